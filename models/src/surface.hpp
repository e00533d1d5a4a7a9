// dermis-charactergen — turning the implicit body into a closed triangle mesh of a given budget.
//
//   polygonize  — marching tetrahedra (Kuhn split of each grid cube) on a sparse grid: a closed,
//                 consistently oriented 2-manifold for any field (the tetrahedral split is
//                 consistent between neighbouring cubes and each edge vertex is shared).
//   decimate    — shortest-relative-edge-first collapses (edge length / local sizing) to a
//                 triangle budget, alternating with flips and relaxation; then a few rounds of
//                 isotropic balancing (split the longest, collapse the shortest relative edges)
//                 that end exactly on the budget. New vertices are projected onto the implicit
//                 surface. Collapses that break the link condition (manifoldness), fold or flip
//                 a triangle, or create very poor triangles are refused.
//   optimize    — edge flips toward valence 6 and tangential smoothing with re-projection.
// All steps are deterministic (fixed iteration orders, no hashing of pointers).
#pragma once

#include "body.hpp"

#include <glm/glm.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace dermis::chargen {

struct TriMesh {
    std::vector<glm::vec3> positions;
    std::vector<glm::uvec3> tris; ///< counter-clockwise seen from outside
};

/// Marching tetrahedra of `body` on a grid of `cell` metres covering the body's bounds; keeps
/// the largest connected component.
TriMesh polygonize(const Body& body, float cell);

/// Collapses edges until at most `targetTris` triangles remain (or no legal collapse is left).
/// Precondition: `mesh` is a closed 2-manifold.
void decimate(TriMesh& mesh, const Body& body, std::size_t targetTris);

/// Improves triangle shapes without changing the triangle count: `iterations` rounds of
/// valence-improving edge flips and tangential relaxation, vertices re-projected on the body.
void optimize(TriMesh& mesh, const Body& body, int iterations);

struct TopologyReport {
    bool closedManifold = false; ///< every edge in exactly two triangles with opposite direction,
                                 ///< every vertex link a single cycle
    int euler = 0;               ///< V − E + F (2 for a sphere)
    std::string problem;         ///< first problem found, empty when none
    float minAngleDeg = 0.0f;    ///< smallest triangle angle
};

TopologyReport checkTopology(const TriMesh& mesh);

} // namespace dermis::chargen
