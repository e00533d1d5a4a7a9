// Joint angles in the page (SPEC §2). A placement's axis is "x", "y", "z" or a vector in the
// joint's rest frame (proposals, transfers and mirror twins write vectors); its θ is the twist of
// q_rel = q_rest⁻¹ · q_pose about that axis, 2·atan2(q_rel.xyz · a, q_rel.w). A pose override of
// a letter axis is `axis_angles` (q_rest · Rx · Ry · Rz; the other letters kept); of a vector axis
// it is `rotation` = q_rest · R(a, θ), the override that gives exactly θ about a vector (it
// replaces the joint's whole rotation). Quaternions are [x, y, z, w], as in glTF.

import { store } from "./store.js";

const UNIT = { x: [1, 0, 0], y: [0, 1, 0], z: [0, 0, 1] };
const r6 = (x) => Math.round(x * 1e6) / 1e6;

/// The axis as a unit vector.
export function axisVector(axis) {
  const a = Array.isArray(axis) ? axis : UNIT[axis] || UNIT.x;
  const n = Math.hypot(...a) || 1;
  return a.map((x) => x / n);
}

/// A short name of an axis: "x", or "(0.12, 0.51, −0.85)" for a vector.
export const axisLabel = (axis) => (Array.isArray(axis) ? `(${axis.map((x) => (Math.round(x * 100) / 100).toFixed(2)).join(", ")})` : String(axis));

/// Quaternion of `deg` degrees about `axis` ("x" or a vector).
export function axisAngle(axis, deg) {
  const a = axisVector(axis), h = (deg * Math.PI) / 360, s = Math.sin(h);
  return [a[0] * s, a[1] * s, a[2] * s, Math.cos(h)];
}

/// Hamilton product a·b.
export function mul(a, b) {
  const [ax, ay, az, aw] = a, [bx, by, bz, bw] = b;
  return [aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
          aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz];
}

const conj = (q) => [-q[0], -q[1], -q[2], q[3]];
const unit = (q) => { const n = Math.hypot(...q) || 1; return q.map((x) => x / n); };

/// The rest rotation of `joint` (GET /models/{id}: joints[].rest_rotation), identity if unknown.
export function restRotation(joint) {
  const j = store.model && store.model.joints.find((k) => k.name === joint);
  return j && j.rest_rotation ? j.rest_rotation : [0, 0, 0, 1];
}

/// θ in degrees, in (−180, 180], of the rest-relative rotation `rel` about `axis`.
export function twist(rel, axis) {
  const a = axisVector(axis);
  let t = (2 * Math.atan2(rel[0] * a[0] + rel[1] * a[1] + rel[2] * a[2], rel[3]) * 180) / Math.PI;
  while (t > 180) t -= 360;
  while (t <= -180) t += 360;
  return t;
}

/// The angle about `axis` that `joint`'s pose override gives, or undefined where the override
/// does not set it (no override, or `axis_angles` without that letter: the clip's angle shows).
export function overrideAngle(override, joint, axis) {
  if (!override) return undefined;
  if (override.rotation) return twist(mul(conj(restRotation(joint)), unit(override.rotation)), axis);
  const aa = override.axis_angles;
  if (!aa) return undefined;
  if (!Array.isArray(axis)) return aa[axis];
  return twist(mul(mul(axisAngle("x", aa.x || 0), axisAngle("y", aa.y || 0)), axisAngle("z", aa.z || 0)), axis);
}

/// The pose override of `joint` with θ = `theta` about `axis`, from its current override `cur`.
export function overrideAt(joint, axis, theta, cur) {
  if (!Array.isArray(axis)) {
    const angles = cur && cur.axis_angles ? { ...cur.axis_angles } : {};
    angles[axis] = theta;
    return { axis_angles: angles };
  }
  return { rotation: mul(restRotation(joint), axisAngle(axis, theta)).map(r6) };
}
