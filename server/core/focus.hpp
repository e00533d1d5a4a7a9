// Dermis core — where a placement's footprint lies on the posed body (the editor's "frame
// selection", F): the surface point under the footprint's UV centre and the radius of the posed
// skin inside the footprint, from which a camera target and distance follow.
//
//   target: the posed position (skinned, not displaced) at the footprint's centre, from the
//           rest-mesh triangle a UvLookup finds there, blended with its barycentric weights; when
//           no triangle lies under the centre (a footprint straddling charts), the mean of the
//           posed vertices inside the footprint;
//   radius: the largest distance from the target of a posed vertex whose UV lies inside the
//           footprint (SPEC §2: s = R(−rotation)·(uv − centre)/scale + ½ ∈ [0, 1]²), of the
//           centre's part when there is a centre triangle, but at most 3 × the estimate from the
//           centre triangle's size in UV and in space (so a footprint that also covers a far
//           chart of the atlas does not frame the whole body); at least that estimate / 2.
//
// Pure; O(vertices). Preconditions: `posed` is skin(model, world) of `model` (one SkinnedPart
// per part, as many positions as the part has). Fails: nullopt when no skin lies inside the
// footprint (or the model has no UVs).
#pragma once

#include "model.hpp"
#include "rig.hpp"
#include "uv_lookup.hpp"

#include <glm/glm.hpp>

#include <optional>
#include <vector>

namespace dermis {

struct FootprintRegion {
    glm::vec3 target{0.0f}; ///< world point: the posed skin at the footprint's centre
    double radius = 0.0;    ///< world units
    bool hit = false;       ///< a triangle lies under the centre
};

/// The posed region of footprint (centre, scale, rotation in degrees) — see the header comment.
std::optional<FootprintRegion> footprintRegion(const Model& model, const UvLookup& lookup,
                                               const std::vector<SkinnedPart>& posed,
                                               glm::dvec2 center, glm::dvec2 scale,
                                               double rotationDegrees);

/// The camera distance that fits a sphere of `radius` in a 30° field of view (core/camera's
/// lens) with `margin` (1.5: the region fills two thirds of the frame), at least 1e-3.
double focusDistance(double radius, double margin = 1.5);

} // namespace dermis
