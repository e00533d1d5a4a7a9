// New placements: a library pattern's defaults (model, target, axis, θ range) at a UV point, or on
// the body (a surface placement, SPEC §8: the 3D view's place tool), with a driver suggested by the
// server for the skin there (pick) when it can, and then a label from that joint's side and role
// ("left elbow crease").

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

/// Takes the driver the server suggests for the skin under a pick (`suggested`: {joint, axis,
/// theta_min, theta_max, role?}) into placement `body` of `pattern`; where the suggestion names the
/// joint's role ("left elbow"), the placement is labelled by it and the pattern ("left elbow crease",
/// "left elbow round bulge"). Without a suggestion the body is left as it is.
export function applySuggested(body, suggested, pattern) {
  if (!suggested) return body;
  Object.assign(body, { joint: suggested.joint, axis: suggested.axis, theta_min: suggested.theta_min, theta_max: suggested.theta_max });
  const label = labelFor(suggested.role, pattern);
  if (label) body.label = label;
  return body;
}

/// "left elbow crease": a joint's role and the pattern's name (underscores as spaces), at most 120
/// bytes (the scene's limit on labels); null without a role.
export function labelFor(role, pattern) {
  if (typeof role !== "string" || !role.trim()) return null;
  const name = pattern ? String(pattern.name || pattern.id || "").replace(/_/g, " ").trim() : "";
  let label = name ? `${role.trim()} ${name}` : role.trim();
  while (new TextEncoder().encode(label).length > 120) label = label.slice(0, -1);
  return label;
}
