// Editor state: what is loaded (scene document and revision, model, pattern library, lint) and
// what this person is doing (selection, solo, view, camera, time, compare). One object, changed
// through set()/update(), which tell listeners by topic; views and panels render from it. It does
// not talk to the server (edits.js and main.js do) and keeps nothing across page loads (the URL
// does, see permalink.js).

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
  presence: new Map(),  // client -> {selection, color, until}
  layoutMode: "both",   // texture | 3d | both
  view: "shaded",       // shaded | bump | displacement | normal
  camera: { yaw: 0, pitch: 10, distance: null },
  time: null,           // null: the scene's pose time; else the shown time (playback, scrub)
  pinnedRevision: null, // a permalink's revision, shown until the person edits or leaves it
  compare: { mode: "off", against: "off", split: 0.5 },
  overlay: "none",      // texture view: none | bump | displacement
  cursorUV: [0.5, 0.5], // last pointer position in the texture view
  liveCamera: null,     // the camera the server used (GET drivers: "auto" distance resolved)
  online: true,
  busy: 0,              // edits queued or in flight (topic "busy")
  saveError: null,      // why this window's last edit was refused (null: its edits are on the server)
  gestures: 0,          // drags and slider gestures running
};

const listeners = new Map();

/// Calls fn(store) whenever one of `topics` (space separated) changes.
export function on(topics, fn) {
  for (const t of topics.split(/\s+/)) {
    if (!listeners.has(t)) listeners.set(t, new Set());
    listeners.get(t).add(fn);
  }
}

/// Tells the listeners of `topics`; each listener runs once per call even when it listens to several.
export function emit(topics) {
  const called = new Set();
  for (const t of topics.split(/\s+/))
    for (const fn of listeners.get(t) || []) {
      if (called.has(fn)) continue;
      called.add(fn);
      try { fn(store); } catch (e) { console.error(e); }
    }
}

/// Sets fields and tells `topic` (default: the field names).
export function set(fields, topic) {
  Object.assign(store, fields);
  emit(topic || Object.keys(fields).join(" "));
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
