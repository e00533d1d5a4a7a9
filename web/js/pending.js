// Placement changes this window shows before they are on the server: a running drag's value, a
// burst of keyboard nudges, and a finished gesture whose one edit is on its way. The texture view
// draws placements with these fields on top and the 3D view previews them (the frame route's
// `preview`: nothing stored), so a gesture makes one revision when it ends instead of one per
// pointer move or key press (three.js's editor merges updatable commands the same way).
//
// Key bursts: nudge() changes the local value at once and commits when no key came for
// BURST_MS, one PATCH per placement (undone as one step); another edit, a selection change or
// leaving the page commits first. Drags: texture_view.js sets the drag's fields with hold() and
// commits through edits.js's Stream.

import { store, on, emit, set, placementById, Topic } from "./store.js";
import { patchPlacement, pushUndo, setBeforeEdit, committingChange } from "./edits.js";

const BURST_MS = 450;
const shownFields = new Map(); // placement id -> fields shown over the document's
let burst = null;              // {before, ids: Set, timer}

/// The placement `p` as this window shows it: the document's fields with pending ones on top.
export function withPending(p) {
  const f = p && shownFields.get(p.id);
  return f ? { ...p, ...f } : p;
}

/// {placementId: fields} of everything pending (the frame route's `preview`), or null.
export function pendingPreview() {
  if (!shownFields.size) return null;
  return Object.fromEntries(shownFields);
}

/// Shows `fields` over placement `id` until release(id) (a drag's value; a commit on its way).
export function hold(id, fields) {
  shownFields.set(id, { ...(shownFields.get(id) || {}), ...fields });
  emit(Topic.DRAG);
}

/// Stops showing placement `id`'s pending fields (its edit is on the server, or was dropped):
/// all of them, or with `sent` only those still as they were sent (a newer change made while
/// that edit was on its way stays shown until its own edit is answered).
export function release(id, sent = null) {
  const cur = shownFields.get(id);
  if (!cur) return;
  if (sent) {
    const rest = Object.fromEntries(Object.entries(cur).filter(([k, v]) => sent[k] !== v));
    if (Object.keys(rest).length) shownFields.set(id, rest);
    else shownFields.delete(id);
  } else shownFields.delete(id);
  emit(Topic.DRAG);
}

/// True while a key burst waits to be committed.
export const bursting = () => burst !== null;

/// Changes each placement of `ids` by `change(placementAsShown) → fields` locally, and commits
/// the burst once the keys pause; `verb` names the change ("move", "rotate", "scale").
export function nudge(ids, change, verb = "adjust") {
  if (!burst) {
    burst = { before: store.revision, ids: new Set(), verbs: new Set(), timer: null };
    set({ gestures: store.gestures + 1 });
  }
  for (const id of ids) {
    const p = placementById(id);
    if (!p) continue;
    hold(id, change(withPending(p)));
    burst.ids.add(id);
  }
  burst.verbs.add(verb);
  clearTimeout(burst.timer);
  burst.timer = setTimeout(commitBurst, BURST_MS);
}

/// Sends the key burst now (one PATCH per placement); resolves when they are answered and the
/// burst is on the undo stack (undo waits for that: committingChange).
export function commitBurst() {
  return burst ? committingChange(sendBurst) : Promise.resolve();
}

async function sendBurst() {
  const b = burst;
  burst = null;
  clearTimeout(b.timer);
  const edits = [...b.ids].map((id) => {
    const fields = shownFields.get(id);
    return fields ? patchPlacement(id, fields, { undoable: false }).finally(() => release(id, fields)) : null;
  }).filter(Boolean);
  set({ gestures: store.gestures - 1 });
  const answers = await Promise.all(edits);
  if (answers.some(Boolean)) pushUndo(b.before, describeBurst(b));
}

function describeBurst({ ids, verbs }) {
  const verb = verbs.size === 1 ? [...verbs][0] : "adjust";
  if (ids.size !== 1) return `${verb} ${ids.size} placements`;
  const id = [...ids][0];
  const p = placementById(id);
  return `${verb} "${(p && p.label) || id}"`;
}

// Another edit, a new selection or leaving the page sends a waiting burst first.
setBeforeEdit(() => (burst ? commitBurst() : Promise.resolve()));
on(Topic.SELECTION, () => { if (burst) commitBurst(); });
window.addEventListener("pagehide", () => { if (burst) commitBurst(); });
