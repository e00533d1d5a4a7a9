// Joint angles of SPEC §2: the twist part of a swing–twist decomposition.
#include "angles.hpp"

#include <cmath>

namespace dermis {

double wrapDegrees(double deg) {
    double r = std::fmod(deg, 360.0); // (−360, 360)
    if (r <= -180.0) r += 360.0;
    else if (r > 180.0) r -= 360.0;
    return r;
}

double jointAngle(const glm::quat& restLocal, const glm::quat& poseLocal, const glm::vec3& axis) {
    // q_rel = q_rest⁻¹ · q_pose, in double to keep small angles exact.
    const glm::dquat rest(restLocal), pose(poseLocal);
    const glm::dquat rel = glm::inverse(rest) * pose;
    const glm::dvec3 a(axis);
    const double twist = 2.0 * std::atan2(rel.x * a.x + rel.y * a.y + rel.z * a.z, rel.w);
    // q and −q: atan2 of the negated pair differs by ±π, i.e. ±360° after doubling → same wrap.
    return wrapDegrees(glm::degrees(twist));
}

glm::quat axisAnglesRotation(const glm::quat& restLocal, double xDeg, double yDeg, double zDeg) {
    const glm::dquat rx = glm::angleAxis(glm::radians(xDeg), glm::dvec3(1, 0, 0));
    const glm::dquat ry = glm::angleAxis(glm::radians(yDeg), glm::dvec3(0, 1, 0));
    const glm::dquat rz = glm::angleAxis(glm::radians(zDeg), glm::dvec3(0, 0, 1));
    return glm::quat(glm::normalize(glm::dquat(restLocal) * rx * ry * rz));
}

} // namespace dermis
