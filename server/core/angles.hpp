// Dermis core — joint angles of SPEC §2 (the twist of a swing–twist decomposition) and the
// scene document's axis-angle rotations. Pure functions in double precision; no state.
#pragma once

#include <glm/gtc/quaternion.hpp>

namespace dermis {

/// A joint's rotation axis in its rest frame; normalised by the caller (see jointAngle).
/// Returns theta in degrees in (−180, 180]: the twist angle of q_rel = q_rest⁻¹ · q_pose about
/// `axis` (SPEC §2): theta = 2·atan2(dot(q_rel.xyz, a), q_rel.w), wrapped. q and −q give the same
/// angle. Precondition: |axis| = 1.
double jointAngle(const glm::quat& restLocal, const glm::quat& poseLocal, const glm::vec3& axis);

/// q_rest · R_x(x) · R_y(y) · R_z(z), angles in degrees (the scene document's `axis_angles`).
glm::quat axisAnglesRotation(const glm::quat& restLocal, double xDeg, double yDeg, double zDeg);

/// Wraps degrees into (−180, 180].
double wrapDegrees(double deg);

} // namespace dermis
