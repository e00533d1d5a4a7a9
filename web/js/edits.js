// Every change this editor makes to the scene goes through here. Each edit carries If-Match with
// the revision the person saw; the answer's document and revision become the state. The server
// rebases an edit of one placement over other people's edits of other placements; a 412 means
// someone else changed the same thing first: the editor shows a notice, reads the scene again and
// drops the edit (it never overwrites their change). Undo and redo are server reverts to the
// revisions around this person's own edits; each step remembers what it did, in words, for the
// notice that says what was undone or redone.
//
// Gestures (a drag in the texture view, a joint slider) use a Stream: the gesture is previewed
// locally (pending.js, the frame route's `preview`) and its last value is sent once when it ends,
// one revision per gesture; a `live` Stream (joint sliders, whose frames need the stored pose)
// also sends values while the gesture runs, at most one in flight, at least `interval` ms apart.

import { store, set, emit, Topic } from "./store.js";
import { scenePath } from "./scene_resource.js";
import { notify } from "./notice.js";
import { trace } from "./trace.js";
import { inWords } from "./messages.js";

let api = null;
const undoStack = []; // {revision, what, scene}: the document before one of my edits, that edit in words, its scene
const redoStack = []; // {revision, what, scene}: revisions to go forward to
let reloadScene = async () => {};

export function initEdits(theApi, reload) {
  api = theApi;
  reloadScene = reload;
}

export const canUndo = () => undoStack.length > 0;
export const canRedo = () => redoStack.length > 0;
export function clearUndo() { undoStack.length = 0; redoStack.length = 0; emit(Topic.UNDO); }

/// Records an undo step of the open scene: going back to `revision` undoes `what` (words, e.g.
/// 'move "elbow L"').
export function pushUndo(revision, what) {
  undoStack.push({ revision, what, scene: store.sceneId });
  redoStack.length = 0;
  emit(Topic.UNDO);
}

let beforeEdit = () => {};
const committing = new Set(); // this person's changes on their way (see committingChange)

/// Runs `work` (an async function) as one of this person's changes on its way — a gesture's
/// commit, a pick and then its edit: undo and redo wait until it is answered and recorded, so
/// that Ctrl+Z right after a change undoes that change, not the one before it (whose revision
/// would take the new change away with it). Resolves to work's result; a rejection is passed on.
export function committingChange(work) {
  const p = work();
  committing.add(p);
  p.finally(() => committing.delete(p)).catch(() => {});
  return p;
}

/// Resolves once every change this editor has made is answered and on the undo stack: a waiting
/// key burst sent, no change committing, no edit queued or in flight. Undo and redo wait for it,
/// and so does opening another scene (the changes go to the scene they were made in).
export async function ownChangesAnswered() {
  for (;;) {
    await beforeEdit();
    await Promise.allSettled([...committing]);
    const q = queue;
    await q;
    if (q === queue && committing.size === 0) return;
  }
}

/// `fn` runs before every edit is queued (pending.js sends a waiting key burst first, so edits
/// stay in the order the person made them); undo and redo wait for the promise it returns.
export function setBeforeEdit(fn) { beforeEdit = fn; }

/// Applies an edit answer ({id, revision, scene}) to the state.
export function accept(answer, topic = Topic.DOC) {
  if (!answer || answer.id !== store.sceneId || answer.revision < store.revision) return;
  const fields = { doc: answer.scene, revision: answer.revision };
  if (store.pinnedRevision !== null) fields.pinnedRevision = null;
  set(fields, [topic, Topic.REVISION]);
}

let queue = Promise.resolve(); // this editor's edits, one at a time, in order

/// Sends one edit (method, path under the scene, body) with If-Match. Edits run one at a time in
/// the order asked, each with the revision its predecessor left; `body` may be a function of the
/// current document, called when the edit's turn comes (so quick key repeats add up). Resolves to
/// the answer, or null when the server refused it (the notice is shown) or `body` gave null.
/// `undoable` records it for undo. An edit belongs to the scene open when it is asked for: one
/// whose turn comes after another scene was opened is dropped (null).
export function edit(method, path, body, opts = {}) {
  beforeEdit();
  set({ busy: store.busy + 1 });
  const scene = store.sceneId;
  const run = queue.then(() => (scene === store.sceneId ? send(method, path, body, opts) : null)).finally(() => set({ busy: store.busy - 1 }));
  queue = run.catch(() => {});
  return run;
}

async function send(method, path, body, { undoable = true, quiet = false, what = null, onRefused = null } = {}) {
  const before = store.revision, scene = store.sceneId;
  const payload = typeof body === "function" ? body(store.doc) : body;
  if (payload === null) return null;
  const words = undoable ? what || describeEdit(method, path, payload) : null; // before the answer changes the document
  try {
    const sentAt = performance.now();
    const answer = await api.send(method, scenePath(scene, path), payload, before);
    if (trace.on) trace.acks.push({ sentAt, ackAt: performance.now() });
    if (scene !== store.sceneId) return answer; // another scene is open now: nothing of this one to show or undo
    accept(answer);
    if (store.saveError !== null) set({ saveError: null });
    if (undoable) pushUndo(before, words);
    return answer;
  } catch (e) {
    if (onRefused && onRefused(e)) { emit(Topic.REFUSED); return null; } // the caller says what now
    await refused(e, quiet);
    return null;
  }
}

/// Shows why an edit was refused (in words, see messages.js); after a 412, re-reads the scene.
/// Tells "refused" so that fields showing the refused value show the document's again.
export async function refused(e, quiet = false) {
  set({ saveError: inWords(e, store.doc) }); // the save indicator says so until an edit succeeds
  if (e.code === "stale_revision") {
    notify(`Someone else changed this placement first (the scene is now at revision ${e.revision}). Your edit was not applied; the scene is up to date again.`, "warn");
    await reloadScene();
  } else if (!quiet) {
    notify(inWords(e, store.doc), "error");
  }
  emit(Topic.REFUSED);
}

/// An edit in words, for undo and redo notices: 'move "elbow L"', 'change h of "elbow L"',
/// 'add "brow"', 'pose'.
export function describeEdit(method, path, payload) {
  const m = /^\/placements\/([^/]+)(\/mirror)?$/.exec(path);
  const name = (id) => { const p = store.doc && store.doc.placements.find((q) => q.id === id); return `"${(p && p.label) || id}"`; };
  if (m) {
    const id = decodeURIComponent(m[1]);
    if (m[2]) return `mirror ${name(id)}`;
    if (method === "DELETE") return `delete ${name(id)}`;
    const keys = payload && typeof payload === "object" ? Object.keys(payload) : [];
    const verbs = { center: "move", scale: "scale", rotation: "rotate", enabled: payload && payload.enabled ? "show" : "hide" };
    if (keys.length === 1 && verbs[keys[0]]) return `${verbs[keys[0]]} ${name(id)}`;
    return `change ${keys.map((k) => k.replace("theta_", "θ")).join(", ") || "fields"} of ${name(id)}`;
  }
  if (path === "/placements") return `add "${(payload && (payload.label || payload.pattern)) || "placement"}"`;
  if (path === "/pose") return "pose";
  if (path === "/revert") return `revert to revision ${payload && payload.revision}`;
  if (path === "") return "replace the scene";
  return `${method} ${path}`;
}

export const patchPlacement = (id, fields, opts) => edit("PATCH", `/placements/${encodeURIComponent(id)}`, fields, opts);
/// Puts placements in a new order (a structural edit: the whole document).
export const putOrder = (doc) => edit("PUT", "", doc, { what: "reorder placements" });
export const deletePlacement = (id) => edit("DELETE", `/placements/${encodeURIComponent(id)}`);

/// Deletes placements `ids` and says so in a notice with an Undo button (a revert to the revision
/// before the first of these deletions, which then selects them again).
export async function removePlacements(ids) {
  const names = new Map(ids.map((id) => { const p = store.doc.placements.find((q) => q.id === id); return [id, (p && p.label) || id]; }));
  const answers = await Promise.all(ids.map((id) => deletePlacement(id)));
  const gone = ids.filter((_, i) => answers[i]);
  if (!gone.length) return;
  const before = Math.min(...answers.filter(Boolean).map((a) => a.revision)) - 1;
  const what = gone.length === 1 ? `"${names.get(gone[0])}"` : `${gone.length} placements`;
  const scene = store.sceneId;
  notify(`Deleted ${what}.`, "info", { label: "Undo", run: async () => {
    if (scene !== store.sceneId) return notify(`That deletion was in another scene: open it again to bring ${what} back (History).`, "warn");
    if (await revert(before, { what: `bring back ${what}` })) set({ selection: gone.filter((id) => store.doc.placements.some((p) => p.id === id)) });
  } });
}
export const addPlacement = (placement) => edit("POST", "/placements", placement);
/// Adds the mirror twin of placement `id`. Where the twin is in the scene already (409) the
/// notice asks whether to bring that twin up to date instead (SPEC §8: ?update=true replaces it in
/// place, its id kept) rather than stacking a second one.
export function mirrorPlacement(id) {
  const path = `/placements/${encodeURIComponent(id)}/mirror`;
  return edit("POST", path, {}, { onRefused: (e) => {
    if (e.code !== "conflict" || /its own mirror twin/.test(e.message || "")) return false;
    const p = store.doc.placements.find((q) => q.id === id);
    const twin = /placement "([^"]+)" already is/.exec(e.message || "");
    notify(`${twin ? `"${twin[1]}"` : "Its twin"} is the mirror twin of "${(p && p.label) || id}" already. Bring it up to date with this side?`, "warn",
      { label: "Update twin", run: () => edit("POST", `${path}?update=true`, {}, { what: `update the mirror twin of "${(p && p.label) || id}"` }) });
    return true;
  } });
}
export const patchPose = (fields, opts) => edit("PATCH", "/pose", fields, opts);
export const putScene = (doc) => edit("PUT", "", doc);

/// Goes back to `revision` as a new revision (history panel, undo, redo, cancelled drags).
export async function revert(revision, { undoable = true, what = null } = {}) {
  return edit("POST", "/revert", { revision }, { undoable, what });
}

/// Goes back (undo) or forward (redo): a revert to the revision on top of `from`, whose own
/// revision then goes on `to` with the same words. A refused revert leaves both stacks as they
/// were. A notice names what was undone or redone (the words kept with the step), with the way
/// back as its button.
async function travel(from, to, nothing, verb, back) {
  await ownChangesAnswered(); // a key burst still waiting, an edit on its way: each becomes the step undone first
  while (from.length && from[from.length - 1].scene !== store.sceneId) from.pop(); // steps of a scene left
  if (!from.length) return notify(nothing, "info");
  const step = from.pop();
  const here = store.revision;
  if (await revert(step.revision, { undoable: false })) {
    to.push({ revision: here, what: step.what, scene: step.scene });
    notify(`${verb}: ${step.what || `revision ${step.revision}`}.`, "info", back, "undo");
  } else from.push(step);
  emit(Topic.UNDO);
}

export const undo = () => travel(undoStack, redoStack, "Nothing to undo.", "Undone", { label: "Redo", run: () => redo() });
export const redo = () => travel(redoStack, undoStack, "Nothing to redo.", "Redone", { label: "Undo", run: () => undo() });

/// The edits of one gesture (a drag, a slider). send(value) keeps the newest value; finish()
/// sends it (one edit, one revision) and records one undo step named `what`; cancel() drops it.
/// With `live` (joint sliders: the frame shows the stored pose), values also leave while the
/// gesture runs — the first one interval after it starts, at most one in flight, at least
/// `interval` ms apart — and cancel() reverts to the revision before the gesture.
export class Stream {
  constructor(apply, { live = false, interval = 70, what = null } = {}) {
    this.apply = apply;       // async (value) => answer | null
    this.live = live;
    this.interval = interval;
    this.what = what;         // the gesture in words (undo notices), or a function of the last value
    this.pending = undefined; // newest value not yet sent
    this.last = undefined;    // newest value seen
    this.inFlight = null;
    this.lastSent = performance.now(); // the first edit leaves one interval after the gesture starts
    this.sent = 0;
    this.ok = 0;
    this.before = store.revision;
    this.scene = store.sceneId;
    this.timer = null;
    this.done = false;
    set({ gestures: store.gestures + 1 }, []); // not told: nothing shows otherwise until the gesture changes something
  }
  end() {
    if (!this.ended) { this.ended = true; set({ gestures: store.gestures - 1 }); }
  }
  send(value) {
    if (this.done) return;
    this.pending = value;
    this.last = value;
    if (this.live) this.pump();
  }
  go(value) {
    ++this.sent;
    this.lastSent = performance.now();
    this.inFlight = this.apply(value).then((a) => { if (a) ++this.ok; return a; }).finally(() => { this.inFlight = null; if (this.live && !this.done) this.pump(); });
    return this.inFlight;
  }
  pump() {
    if (this.inFlight || this.pending === undefined || this.timer) return;
    const wait = this.lastSent + this.interval - performance.now();
    if (wait > 0) {
      this.timer = setTimeout(() => { this.timer = null; this.pump(); }, wait);
      return;
    }
    const value = this.pending;
    this.pending = undefined;
    this.go(value);
  }
  /// Sends the last value (when it was not sent yet); resolves once it is answered (undo waits
  /// for it: committingChange).
  finish() { return committingChange(() => this.finishNow()); }
  async finishNow() {
    this.done = true;
    if (this.timer) { clearTimeout(this.timer); this.timer = null; }
    if (this.inFlight) await this.inFlight;
    if (this.pending !== undefined) {
      const value = this.pending;
      this.pending = undefined;
      await this.go(value);
    }
    this.end();
    if (this.ok > 0 && this.scene === store.sceneId) {
      const what = typeof this.what === "function" ? this.what(this.last) : this.what;
      pushUndo(this.before, what);
    }
  }
  async cancel() {
    this.done = true;
    this.pending = undefined;
    if (this.timer) { clearTimeout(this.timer); this.timer = null; }
    if (this.inFlight) await this.inFlight;
    if (this.ok > 0) await revert(this.before, { undoable: false });
    this.end(); // after the revert: a gesture counts until the scene is back
  }
}
