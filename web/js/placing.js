// New placements: a library pattern's defaults (model, target, axis, θ range) at a UV point, or on
// the body (a surface placement, SPEC §8: the 3D view's place tool), with a driver suggested by the
// server for the skin there (pick) when it can.

import { store } from "./store.js";
import { round4 } from "./geometry.js";

/// The placement body (POST /placements) of `pattern` centred at `uv`, before a driver is known.
export function placementFromPattern(pattern, uv) {
  const body = { pattern: pattern.id, center: uv.map(round4), scale: [0.08, 0.08] };
  for (const k of ["model", "target", "axis", "theta_min", "theta_max"]) if (pattern[k] !== undefined) body[k] = pattern[k];
  if (typeof body.axis !== "string" || !["x", "y", "z"].includes(body.axis)) body.axis = "x";
  // A joint: the pattern's own when the model has it, else the first placement's, else the root's child.
  const names = store.model ? store.model.joints.map((j) => j.name) : [];
  if (pattern.joint && names.includes(pattern.joint)) body.joint = pattern.joint;
  else if (store.doc && store.doc.placements.length) body.joint = store.doc.placements[0].joint;
  else body.joint = names[1] || names[0];
  return body;
}

/// The surface placement body (SPEC §8) of `pattern` at a pick's anchor (the hit's rest position,
/// normal and a tangent across the suggested joint's bone) with a square decal `diameter` model
/// units wide — the 3D view's brush.
export function surfacePlacementFromPattern(pattern, anchor, diameter) {
  const body = placementFromPattern(pattern, [0.5, 0.5]);
  delete body.center;
  delete body.scale;
  const r6 = (x) => Math.round(x * 1e6) / 1e6;
  return { ...body, projection: "surface", anchor: { position: anchor.position.map(r6), normal: anchor.normal.map(r6), tangent: anchor.tangent.map(r6) },
           size: [r6(diameter), r6(diameter)] };
}
