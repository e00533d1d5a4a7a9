// Editor state: what is loaded (scene document and revision, model, pattern library, lint) and
// what this person is doing (selection, solo, view, camera, time, compare). One object, written
// only through set() (every field is declared below), which tells listeners by topic; views and
// panels render from it. Topics are the declared constants of `Topic`: on(), emit() and set()
// throw on any other, so a typo fails loudly. It does not talk to the server (edits.js and
// main.js do) and keeps nothing across page loads (the URL does, see permalink.js).

/// The topics of on(), emit() and set(): one per state field (named as the field: set() tells the
/// names of the fields it sets unless told otherwise) and the events that are no field.
export const Topic = Object.freeze({
  SCENE_ID: "sceneId",
  REVISION: "revision",
  DOC: "doc",
  MODEL: "model",
  PATTERNS: "patterns",
  LAYOUT: "layout",
  LINT: "lint",
  SELECTION: "selection",
  SOLO: "solo",
  PRESENCE: "presence",
  LAYOUT_MODE: "layoutMode",
  VIEW: "view",
  CAMERA: "camera",
  TIME: "time",
  PINNED_REVISION: "pinnedRevision",
  COMPARE: "compare",
  OVERLAY: "overlay",                // also told when the overlay's revision moves (overlayRevision)
  OVERLAY_REVISION: "overlayRevision",
  CURSOR_UV: "cursorUV",
  LIVE_CAMERA: "liveCamera",
  ONLINE: "online",
  BUSY: "busy",
  SAVE_ERROR: "saveError",
  GESTURES: "gestures",
  // Events, no field of their own:
  SCENE: "scene",                    // another scene was opened (with its document, model, layout…)
  UNDO: "undo",                      // the undo or redo stack changed (edits.js)
  REFUSED: "refused",                // an edit was refused: fields show the document's values again
  DRAG: "drag",                      // the changes shown over the document changed (pending.js)
  GHOST: "ghost",                    // the Propose… panel's ghosts changed (propose.js)
  CURRENT_PATTERN: "currentPattern", // the library's chosen pattern
  DRIVERS: "drivers",                // each placement's θ and t at the shown time
  EVENT: "event",                    // a change event arrived on the scene's stream (live.js)
  PLACE_AT: "place-at",              // the place tool hit the body (frame_view.js)
});

export const store = {
  sceneId: null,
  revision: 0,          // the document's current revision on the server
  doc: null,            // dermis.scene/1 document of that revision
  model: null,          // GET /models/{id}
  patterns: [],         // GET /patterns
  layout: null,         // GET /models/{id}/uv-layout (null without UVs)
  lint: [],             // GET /scenes/{id}/lint
  selection: [],        // placement ids, the first is the primary
  solo: [],             // placement ids shown alone in the 3D view (frame only=…)
  presence: new Map(),  // client -> {selection, color, until}; replaced, never changed in place
  layoutMode: "both",   // texture | 3d | both
  view: "shaded",       // shaded (the scene's shading) | pbr | skin | pbr-key | skin-key | legacy | bump | displacement | normal
  camera: { yaw: 0, pitch: 10, distance: null },
  time: null,           // null: the scene's pose time; else the shown time (playback, scrub)
  pinnedRevision: null, // a permalink's revision, shown until the person edits or leaves it
  compare: { mode: "off", against: "off", split: 0.5 },
  overlay: "none",      // texture view: none | bump | displacement
  overlayRevision: null, // the revision the texture view's overlay shows (follows once things are quiet)
  cursorUV: [0.5, 0.5], // last pointer position in the texture view
  liveCamera: null,     // the camera the server used (GET drivers: "auto" distance resolved)
  online: true,
  busy: 0,              // edits queued or in flight
  saveError: null,      // why this window's last edit was refused (null: its edits are on the server)
  gestures: 0,          // drags and slider gestures running
};

const declared = new Set(Object.values(Topic));
for (const field of Object.keys(store))
  if (!declared.has(field)) throw new Error(`store.js: the field ${field} has no topic`);

/// `topics` (one Topic or an array of them) as an array; throws on an undeclared one.
function topicList(topics, caller) {
  const list = Array.isArray(topics) ? topics : [topics];
  for (const t of list) if (!declared.has(t)) throw new Error(`store.${caller}: undeclared topic ${JSON.stringify(t)}`);
  return list;
}

const listeners = new Map();

/// Calls fn(store) whenever one of `topics` (a Topic or an array of them) changes.
export function on(topics, fn) {
  for (const t of topicList(topics, "on")) {
    if (!listeners.has(t)) listeners.set(t, new Set());
    listeners.get(t).add(fn);
  }
}

/// Tells the listeners of `topics` (a Topic or an array of them); each listener runs once per call
/// even when it listens to several.
export function emit(topics) {
  const called = new Set();
  for (const t of topicList(topics, "emit"))
    for (const fn of listeners.get(t) || []) {
      if (called.has(fn)) continue;
      called.add(fn);
      try { fn(store); } catch (e) { console.error(e); }
    }
}

/// Sets fields (each one declared above) and tells `topics` (default: the fields' names; []
/// tells no one, for a change that the next told topic shows). Throws on an undeclared field or
/// topic before changing anything.
export function set(fields, topics) {
  for (const k of Object.keys(fields))
    if (!Object.hasOwn(store, k)) throw new Error(`store.set: undeclared field ${JSON.stringify(k)}`);
  const list = topicList(topics === undefined ? Object.keys(fields) : topics, "set");
  Object.assign(store, fields);
  emit(list);
}

export const placementById = (id) => (store.doc ? store.doc.placements.find((p) => p.id === id) : undefined);
export const primary = () => placementById(store.selection[0]);
export const patternById = (id) => store.patterns.find((p) => p.id === id);
export const heightmapSize = () => (store.doc && store.doc.heightmap && store.doc.heightmap.size) || [1024, 1024];
export const clipByName = (name) => (store.model ? store.model.clips.find((c) => c.name === name) : undefined);
/// The time the 3D view shows.
export const shownTime = () => (store.time !== null ? store.time : (store.doc ? store.doc.pose.time || 0 : 0));

const idleTimers = new Map();

/// Runs fn once things are quiet: no gesture running, no edit in flight, and `delay` ms after
/// the last call with the same `key` — what the side panels (history, lint, activation, the
/// dial) fetch after a change, so that while dragging the frames have the server to themselves.
export function whenIdle(key, fn, delay = 200) {
  clearTimeout(idleTimers.get(key));
  const attempt = () => {
    if (store.gestures > 0 || store.busy > 0) { idleTimers.set(key, setTimeout(attempt, delay)); return; }
    idleTimers.delete(key);
    fn();
  };
  idleTimers.set(key, setTimeout(attempt, delay));
}
