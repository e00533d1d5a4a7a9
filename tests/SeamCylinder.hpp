// A hand-built cylinder with a UV seam, shared by the pure tests of surface placements
// (SurfacePlacementTest, SurfaceOutlineTest): radius kRadius, height kHeight along y, one skinned
// joint "root"; u = angle/2π with a seam at angle 0 (the vertices of u = 0 and u = 1 are
// separate), v = 1 − y/kHeight (v down); normals point outwards.
#pragma once
#include "core/model.hpp"

#include <cmath>
#include <cstdint>

namespace dermis::test::seam_cylinder {

constexpr double kPi = 3.14159265358979323846;
constexpr int kSegments = 96, kRings = 24;
constexpr double kRadius = 0.5, kHeight = 2.0;

inline Model cylinder() {
    Model m;
    m.nodes.push_back({"root", -1, glm::vec3(0.0f), glm::quat(1, 0, 0, 0), glm::vec3(1.0f)});
    m.joints = {0};
    MeshPart p;
    for (int r = 0; r <= kRings; ++r)
        for (int s = 0; s <= kSegments; ++s) {
            const double a = 2.0 * kPi * s / kSegments, y = kHeight * r / kRings;
            p.positions.emplace_back(kRadius * std::cos(a), y, kRadius * std::sin(a));
            p.normals.emplace_back(std::cos(a), 0.0, std::sin(a));
            p.uvs.emplace_back(static_cast<float>(s) / kSegments, 1.0f - static_cast<float>(r) / kRings);
            p.joints.emplace_back(0);
            p.weights.emplace_back(1, 0, 0, 0);
        }
    for (int r = 0; r < kRings; ++r)
        for (int s = 0; s < kSegments; ++s) {
            const std::uint32_t a = r * (kSegments + 1) + s, b = a + 1, c = a + kSegments + 1, d = c + 1;
            p.indices.insert(p.indices.end(), {a, c, b, b, c, d});
        }
    p.influences = {{0, glm::mat4(1.0f)}};
    m.parts.push_back(p);
    return m;
}

} // namespace dermis::test::seam_cylinder
