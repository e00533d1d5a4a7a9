// Every change this editor makes to the scene goes through here. Each edit carries If-Match with
// the revision the person saw; the answer's document and revision become the state. A 412 means
// someone else changed the scene first: the editor shows a notice, reads the scene again and
// drops the edit (it never overwrites their change). Undo and redo are server reverts to the
// revisions around this person's own edits.
//
// Drags use a Stream: at most one edit in flight, edits at least `interval` ms apart, the newest
// value wins, and finish() sends the last value so the scene ends where the pointer stopped.

import { store, set, emit } from "./store.js";
import { notify } from "./notice.js";
import { trace } from "./trace.js";

let api = null;
const undoStack = []; // revisions to go back to (the document before one of my edits)
const redoStack = []; // revisions to go forward to
let reloadScene = async () => {};

export function initEdits(theApi, reload) {
  api = theApi;
  reloadScene = reload;
}

export const canUndo = () => undoStack.length > 0;
export const canRedo = () => redoStack.length > 0;
export function clearUndo() { undoStack.length = 0; redoStack.length = 0; emit("undo"); }

/// Applies an edit answer ({id, revision, scene}) to the state.
export function accept(answer, topic = "doc") {
  if (!answer || answer.id !== store.sceneId || answer.revision < store.revision) return;
  const fields = { doc: answer.scene, revision: answer.revision };
  if (store.pinnedRevision !== null) fields.pinnedRevision = null;
  set(fields, topic + " revision");
}

let queue = Promise.resolve(); // this editor's edits, one at a time, in order

/// Sends one edit (method, path under the scene, body) with If-Match. Edits run one at a time in
/// the order asked, each with the revision its predecessor left; `body` may be a function of the
/// current document, called when the edit's turn comes (so quick key repeats add up). Resolves to
/// the answer, or null when the server refused it (the notice is shown) or `body` gave null.
/// `undoable` records it for undo.
export function edit(method, path, body, opts = {}) {
  ++store.busy;
  emit("busy");
  const run = queue.then(() => send(method, path, body, opts)).finally(() => { --store.busy; emit("busy"); });
  queue = run.catch(() => {});
  return run;
}

async function send(method, path, body, { undoable = true, quiet = false } = {}) {
  const before = store.revision;
  const payload = typeof body === "function" ? body(store.doc) : body;
  if (payload === null) return null;
  try {
    const sentAt = performance.now();
    const answer = await api.send(method, `/scenes/${store.sceneId}${path}`, payload, before);
    if (trace.on) trace.acks.push({ sentAt, ackAt: performance.now() });
    accept(answer);
    if (store.saveError !== null) set({ saveError: null });
    if (undoable) {
      undoStack.push(before);
      redoStack.length = 0;
      emit("undo");
    }
    return answer;
  } catch (e) {
    await refused(e, quiet);
    return null;
  }
}

/// Shows why an edit was refused; after a 412, re-reads the scene.
export async function refused(e, quiet = false) {
  set({ saveError: e.message || "refused" }); // the save indicator says so until an edit succeeds
  if (e.code === "stale_revision") {
    notify(`Someone else changed this scene first (now revision ${e.revision}). Your edit was not applied; the scene is up to date again.`, "warn");
    await reloadScene();
  } else if (!quiet) {
    notify(e.field ? `${e.message}` : e.message, "error");
  }
}

export const patchPlacement = (id, fields, opts) => edit("PATCH", `/placements/${encodeURIComponent(id)}`, fields, opts);
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
  notify(`Deleted ${what}.`, "info", { label: "Undo", run: async () => {
    if (await revert(before)) set({ selection: gone.filter((id) => store.doc.placements.some((p) => p.id === id)) });
  } });
}
export const addPlacement = (placement) => edit("POST", "/placements", placement);
export const mirrorPlacement = (id) => edit("POST", `/placements/${encodeURIComponent(id)}/mirror`, {});
export const patchPose = (fields, opts) => edit("PATCH", "/pose", fields, opts);
export const putScene = (doc) => edit("PUT", "", doc);

/// Goes back to `revision` as a new revision (history panel, undo, redo, cancelled drags).
export async function revert(revision, { undoable = true } = {}) {
  return edit("POST", "/revert", { revision }, { undoable });
}

/// Goes back (undo) or forward (redo): a revert to the revision on top of `from`, whose own
/// revision then goes on `to`. A refused revert leaves both stacks as they were. A notice names
/// what was undone (the operation of the revision left) or redone (of the revision returned to),
/// with the way back as its button.
async function travel(from, to, nothing, verb, back) {
  if (!from.length) return notify(nothing, "info");
  const target = from.pop();
  const here = store.revision;
  if (await revert(target, { undoable: false })) {
    to.push(here);
    tellTravel(verb, verb === "Undone" ? here : target, back);
  } else from.push(target);
  emit("undo");
}

async function tellTravel(verb, revision, back) {
  let what = `revision ${revision}`;
  try {
    const r = (await api.get(`/scenes/${store.sceneId}/revisions?limit=50`)).revisions.find((x) => x.revision === revision);
    if (r && r.op) what = r.op;
  } catch { /* the revision number will do */ }
  notify(`${verb}: ${what}.`, "info", back, "undo");
}

export const undo = () => travel(undoStack, redoStack, "Nothing to undo.", "Undone", { label: "Redo", run: () => redo() });
export const redo = () => travel(redoStack, undoStack, "Nothing to redo.", "Redone", { label: "Undo", run: () => undo() });

/// A stream of edits from one gesture (a drag, a slider). send(value) queues the newest value
/// (the first leaves one interval after the stream starts, so a gesture cancelled at once sends
/// nothing);
/// finish() resolves once the last value is on the server. cancel() sends nothing more and, when
/// edits were already sent, reverts to the revision before the gesture.
export class Stream {
  constructor(apply, interval = 70) {
    this.apply = apply;       // async (value) => answer | null
    this.interval = interval;
    this.pending = undefined; // newest value not yet sent
    this.inFlight = null;
    this.lastSent = performance.now(); // the first edit leaves one interval after the gesture starts
    this.sent = 0;
    this.before = store.revision;
    this.timer = null;
    this.done = false;
    ++store.gestures;
  }
  end() {
    if (!this.ended) { this.ended = true; --store.gestures; emit("gestures"); }
  }
  send(value) {
    if (this.done) return;
    this.pending = value;
    this.pump();
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
    this.lastSent = performance.now();
    ++this.sent;
    this.inFlight = this.apply(value).finally(() => { this.inFlight = null; this.pump(); });
  }
  async finish() {
    this.done = true;
    if (this.timer) { clearTimeout(this.timer); this.timer = null; }
    while (this.inFlight || this.pending !== undefined) {
      if (this.inFlight) await this.inFlight;
      if (this.pending !== undefined) {
        const value = this.pending;
        this.pending = undefined;
        ++this.sent;
        this.inFlight = this.apply(value).finally(() => { this.inFlight = null; });
      }
    }
    this.end();
    if (this.sent > 0) {
      undoStack.push(this.before);
      redoStack.length = 0;
      emit("undo");
    }
  }
  async cancel() {
    this.done = true;
    this.pending = undefined;
    if (this.timer) { clearTimeout(this.timer); this.timer = null; }
    if (this.inFlight) await this.inFlight;
    if (this.sent > 0) await revert(this.before, { undoable: false });
    this.end(); // after the revert: a gesture counts until the scene is back
  }
}
