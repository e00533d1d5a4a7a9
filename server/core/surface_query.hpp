// Dermis core — geometry queries on a model's surface, shared by the mirror, proposals and
// transfer (SPEC §8): the nearest surface point, a ray cast, and the rest skinning at a surface
// point (bind space ↔ rest world space).
//
// Every query walks all triangles (no acceleration structure): O(triangles) per call, a few
// milliseconds for 50k triangles. Pure; never reads out of bounds (corners with an index past
// the positions are skipped).
#pragma once

#include "mirror.hpp"
#include "model.hpp"

#include <glm/glm.hpp>

#include <functional>
#include <optional>
#include <set>
#include <vector>

namespace dermis {

/// A point on a part's triangle: part, first index of the triangle in `indices`, barycentrics.
struct SurfacePoint {
    std::size_t part = 0, base = 0;
    glm::dvec3 bary{1, 0, 0};
    /// The triangle's index within its part (base / 3).
    int triangle() const { return static_cast<int>(base / 3); }
};

/// Closest point on triangle (a, b, c) to p (Ericson, Real-Time Collision Detection §5.1.5: the
/// Voronoi region of p among the corners, edges and face), as barycentric weights; a degenerate
/// triangle gives its first corner. Never divides by zero.
glm::dvec3 closestBary(glm::dvec3 p, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c);

/// The surface point of `m`'s triangles, with positions `positions[part]` (the parts' own, bind
/// space, or a RestSkin's), nearest to q. nullopt without triangles. Parts past
/// `positions.size()` are skipped.
std::optional<SurfacePoint> nearestSurfacePoint(const Model& m,
                                                const std::vector<const std::vector<glm::vec3>*>& positions,
                                                glm::dvec3 q);

/// A ray hit: the surface point and the distance along the (unit) direction.
struct RayHit {
    SurfacePoint point;
    double distance = 0.0;
};

/// The first triangle the ray origin + s·dir (s in (0, maxDistance], dir unit) meets, both
/// faces counted, among the triangles for which `accept(part, triangle)` is true (all when
/// empty). Möller–Trumbore. nullopt when it meets none.
std::optional<RayHit> castRay(const Model& m, const std::vector<const std::vector<glm::vec3>*>& positions,
                              glm::dvec3 origin, glm::dvec3 dir, double maxDistance,
                              const std::function<bool(std::size_t, int)>& accept = {});

/// The rest skinning at surface point `sp` (bind space → rest world): Σ over the triangle's
/// corners and their influences of bary · weight · world(node) · inverseBind, divided by the
/// weights' sum. Identity where nothing weighs. Precondition: `sp` names a triangle of `m`.
glm::dmat4 restSkinningAt(const Model& m, const RestSkin& rest, const SurfacePoint& sp);

/// `sp`'s position and normal in bind space (the part's own positions and normals blended by
/// the barycentrics; the face normal where the part has no normals), normal unit.
glm::dvec3 bindPositionAt(const Model& m, const SurfacePoint& sp);
glm::dvec3 bindNormalAt(const Model& m, const SurfacePoint& sp);
/// The same in rest world space, from `rest`'s skinned parts.
glm::dvec3 restPositionAt(const Model& m, const RestSkin& rest, const SurfacePoint& sp);
glm::dvec3 restNormalAt(const Model& m, const RestSkin& rest, const SurfacePoint& sp);

/// Whether some corner of the triangle at `base` (first index in `p.indices`) has a skin weight
/// ≥ `minWeight` on one of `nodes`.
bool triangleWeighsOn(const MeshPart& p, std::size_t base, const std::set<int>& nodes, float minWeight = 0.1f);

/// Pointers to each part's bind-space positions / `rest`'s rest-world positions, for the
/// queries above.
std::vector<const std::vector<glm::vec3>*> bindPositions(const Model& m);
std::vector<const std::vector<glm::vec3>*> restPositions(const RestSkin& rest);

} // namespace dermis
