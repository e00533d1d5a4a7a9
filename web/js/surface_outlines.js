// Texture view: surface placements' footprints (SPEC §8) in the layout in use — every piece, also
// where a seam cuts the decal — from GET /scenes/{id}/placements/{pid}/outline, cached per
// placement as stored (one request per placement and change; the view redraws when it lands).
// Also their hit test (a piece's bounds) for selecting and dragging in the texture view.

import { store } from "./store.js";
import { outlinePath } from "./scene_resource.js";

let api = null;
let onLoaded = () => {};
const cache = new Map(); // id → {key, answer | null, loading}

export function initSurfaceOutlines(theApi, loaded) {
  api = theApi;
  onLoaded = loaded;
}

/// The outline answer of stored surface placement `p` ({segments, bounds, anchor_uv, …}), or null
/// while it loads (it is asked for then) or when it could not be had.
export function outlineOf(p) {
  const key = keyOf(p);
  const hit = cache.get(p.id);
  if (hit && hit.key === key) return hit.answer;
  const entry = { key, answer: hit ? hit.answer : null, loading: true }; // the old outline until the new one lands
  cache.set(p.id, entry);
  api.get(outlinePath(store.sceneId, p.id))
    .then((a) => { entry.answer = a; }, () => { entry.answer = null; })
    .finally(() => { entry.loading = false; if (cache.get(p.id) === entry) onLoaded(); });
  return entry.answer;
}

/// Whether the outline held for stored placement `p` is p's as it is now (loaded, not the previous
/// one shown while p's own is on its way).
export function outlineCurrent(p) {
  const hit = cache.get(p.id);
  return !!hit && hit.key === keyOf(p) && !hit.loading;
}

const keyOf = (p) => JSON.stringify([store.sceneId, store.layout ? store.layout.layout : null, p]);

/// The topmost surface placement of `placements` with a piece whose bounds (grown by `margin` UV,
/// shifted by `offsetOf(p)` UV where it is drawn away from where it is stored) hold `uv`; of
/// several, the one with the smallest such piece.
export function hitOutline(placements, uv, margin = 0, offsetOf = () => [0, 0]) {
  let best = null, bestArea = Infinity;
  for (let i = placements.length - 1; i >= 0; --i) {
    const p = placements[i];
    if (p.projection !== "surface") continue;
    const o = outlineOf(p);
    if (!o) continue;
    const [du, dv] = offsetOf(p);
    for (const b0 of o.bounds || []) {
      const b = [b0[0] + du, b0[1] + dv, b0[2] + du, b0[3] + dv];
      if (uv[0] < b[0] - margin || uv[0] > b[2] + margin || uv[1] < b[1] - margin || uv[1] > b[3] + margin) continue;
      const area = (b[2] - b[0]) * (b[3] - b[1]);
      if (area < bestArea) { best = p; bestArea = area; }
    }
  }
  return best;
}

/// Strokes the outline of `p` (its segments, shifted by `offset` UV while it is dragged) with
/// `toScreen` mapping UV → css px.
export function strokeOutline(ctx, p, toScreen, offset = [0, 0]) {
  const o = outlineOf(p);
  if (!o) return null;
  ctx.beginPath();
  for (const s of o.segments) {
    ctx.moveTo(...toScreen([s[0] + offset[0], s[1] + offset[1]]));
    ctx.lineTo(...toScreen([s[2] + offset[0], s[3] + offset[1]]));
  }
  ctx.stroke();
  return o;
}
