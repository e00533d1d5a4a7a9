// Footprint geometry of the texture view, pure (no DOM): the same mapping as the server's
// core/heightmap Footprint — s = R(−rotation)·(uv − center)/scale + 0.5, inside iff s ∈ [0,1]²,
// with u right and v down — plus the handle positions and what dragging each handle does.

const rad = (deg) => (deg * Math.PI) / 180;

/// Pattern coordinates s of a UV point for footprint p ({center, scale, rotation}).
export function toPattern(p, uv) {
  const a = rad(p.rotation), c = Math.cos(a), s = Math.sin(a);
  const dx = uv[0] - p.center[0], dy = uv[1] - p.center[1];
  return [(c * dx + s * dy) / p.scale[0] + 0.5, (-s * dx + c * dy) / p.scale[1] + 0.5];
}

/// UV of pattern coordinates s (inverse of toPattern).
export function toUV(p, st) {
  const a = rad(p.rotation), c = Math.cos(a), s = Math.sin(a);
  const dx = (st[0] - 0.5) * p.scale[0], dy = (st[1] - 0.5) * p.scale[1];
  return [p.center[0] + c * dx - s * dy, p.center[1] + s * dx + c * dy];
}

/// True when `uv` lies in the footprint, grown by `margin` pattern units on each side.
export function inside(p, uv, margin = 0) {
  const s = toPattern(p, uv);
  return s[0] >= -margin && s[0] <= 1 + margin && s[1] >= -margin && s[1] <= 1 + margin;
}

/// Corners in UV: top-left, top-right, bottom-right, bottom-left (pattern s order).
export const corners = (p) => [[0, 0], [1, 0], [1, 1], [0, 1]].map((s) => toUV(p, s));

/// The rotation handle: above the top edge's middle, `offset` UV units out.
export function rotationHandle(p, offset) {
  const a = rad(p.rotation);
  const top = toUV(p, [0.5, 0]);
  return [top[0] + Math.sin(a) * offset, top[1] - Math.cos(a) * offset];
}

/// Wraps degrees into (−180, 180].
export function wrapDegrees(d) {
  let x = ((d + 180) % 360 + 360) % 360 - 180;
  if (x === -180) x = 180;
  return x;
}

/// Rounds to 4 decimals (the document's precision for UVs and scales; the server keeps doubles).
export const round4 = (x) => Math.round(x * 1e4) / 1e4;

/// The placement after a move drag from `start` (UV) to `now` (UV).
export function moved(p, start, now) {
  return { center: [round4(p.center[0] + now[0] - start[0]), round4(p.center[1] + now[1] - start[1])] };
}

/// The rotation after a rotate drag: the angle of the pointer about the centre; `snap` rounds to
/// 15° steps.
export function rotated(p, now, snap) {
  const dx = now[0] - p.center[0], dy = now[1] - p.center[1];
  let deg = (Math.atan2(dx, -dy) * 180) / Math.PI; // 0 when the pointer is straight above
  if (snap) deg = Math.round(deg / 15) * 15;
  return { rotation: round4(wrapDegrees(deg)) };
}

/// The scale after dragging corner `k` (0..3, see corners) to `now`, the opposite corner fixed;
/// `keepAspect` keeps the start aspect ratio. The smallest footprint is `minScale` UV units.
export function scaled(p, k, now, keepAspect, minScale = 0.005) {
  const opposite = toUV(p, [[1, 1], [0, 1], [0, 0], [1, 0]][k]);
  const a = rad(p.rotation), c = Math.cos(a), s = Math.sin(a);
  // The diagonal from the fixed corner to the pointer, in the footprint's own axes.
  const dx = now[0] - opposite[0], dy = now[1] - opposite[1];
  let w = Math.abs(c * dx + s * dy), h = Math.abs(-s * dx + c * dy);
  if (keepAspect) {
    const f = Math.max(w / p.scale[0], h / p.scale[1]);
    w = p.scale[0] * f;
    h = p.scale[1] * f;
  }
  w = Math.max(w, minScale);
  h = Math.max(h, minScale);
  // The new centre is halfway along the diagonal of the new rectangle from the fixed corner.
  const sx = [-1, 1, 1, -1][k], sy = [-1, -1, 1, 1][k]; // from the fixed corner to corner k, own axes
  const lx = (sx * w) / 2, ly = (sy * h) / 2;
  const center = [opposite[0] + c * lx - s * ly, opposite[1] + s * lx + c * ly];
  return { center: center.map(round4), scale: [round4(w), round4(h)] };
}

/// Whether a placement has a footprint in texture space: a surface placement (SPEC §8,
/// `projection: "surface"`) is a decal on the body, drawn by the server into whichever layout is in
/// use; its center/scale mean nothing, so the texture view neither draws nor hits it.
export const inTexture = (p) => p.projection !== "surface";

/// The topmost placement (last drawn) under `uv`, or undefined. Disabled placements count;
/// surface placements have no footprint there (inTexture).
export function hit(placements, uv, margin = 0) {
  for (let i = placements.length - 1; i >= 0; --i) if (inTexture(placements[i]) && inside(placements[i], uv, margin)) return placements[i];
  return undefined;
}

// --- surface placements (SPEC §8) ------------------------------------------------------------

const v3dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const v3cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const v3unit = (a) => { const l = Math.hypot(...a); return l > 0 ? a.map((x) => x / l) : null; };

/// The decal frame of surface placement `p` as core surfaceFrameOf makes it (bake.hpp): unit
/// normal n, tangent made orthogonal to n and turned by `rotation` about it, b = n × t, size and
/// depth (default max(size)/2). Null for a degenerate anchor.
export function surfaceFrame(p) {
  const n = v3unit(p.anchor.normal);
  if (!n) return null;
  const t0 = p.anchor.tangent, k = v3dot(t0, n);
  const t1 = v3unit([t0[0] - k * n[0], t0[1] - k * n[1], t0[2] - k * n[2]]);
  if (!t1) return null;
  const bt = v3cross(n, t1), a = (p.rotation * Math.PI) / 180;
  const t = v3unit(t1.map((x, i) => Math.cos(a) * x + Math.sin(a) * bt[i]));
  const depth = typeof p.depth === "number" ? p.depth : Math.max(p.size[0], p.size[1]) / 2;
  return { c: p.anchor.position, n, t, b: v3cross(n, t), w: p.size[0], h: p.size[1], depth };
}

/// Whether rest-surface point `position` with normal `normal` (a pick's anchor) lies in surface
/// placement `p`'s decal (core SurfaceFrame::toPattern), shrunk by `margin` of its size.
export function insideSurface(p, position, normal, margin = 0) {
  const f = surfaceFrame(p);
  if (!f || !(v3dot(normal, f.n) > 0)) return false;
  const d = [0, 1, 2].map((i) => position[i] - f.c[i]);
  if (Math.abs(v3dot(d, f.n)) > f.depth) return false;
  const s = [v3dot(d, f.t) / f.w + 0.5, v3dot(d, f.b) / f.h + 0.5];
  return s.every((x) => x >= margin && x <= 1 - margin);
}

/// The topmost placement under a pick answer (GET pick with hit: true): a UV placement whose
/// footprint holds the pick's UV, or a surface placement whose decal holds its anchor point.
export function hitPick(placements, pick) {
  for (let i = placements.length - 1; i >= 0; --i) {
    const p = placements[i];
    if (inTexture(p) ? inside(p, pick.uv) : pick.anchor && insideSurface(p, pick.anchor.position, pick.anchor.normal)) return p;
  }
  return undefined;
}

/// A pick's anchor `a` for surface placement `p`: its rest position and normal, `p`'s tangent kept
/// where it is not (nearly) along the new normal, else the pick's (across the driver's bone).
export function anchorNear(p, a) {
  const t = p.anchor.tangent, n = a.normal;
  const along = Math.abs(v3dot(t, n)) / (Math.hypot(...t) || 1);
  return { position: a.position, normal: n, tangent: along < 0.95 ? t : a.tangent };
}
