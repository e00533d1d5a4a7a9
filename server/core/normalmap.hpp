// Dermis core — UV-space normal maps of height maps (for shading a bump map as a normal map).
//
// Pure and deterministic; no image library. Conventions (OpenGL-style "Y+" normal maps, as glTF
// expects):
//   * the map lives in texture space, row 0 first (row 0 = v near 0, drawn at the top);
//   * +X points towards +u (increasing column), +Y points "up" in the image, i.e. towards
//     DECREASING row (decreasing v), +Z points out of the surface;
//   * the surface is z = strength·H(column, row) with both axes measured in texels, so
//       n = normalize(−strength·∂H/∂column, +strength·∂H/∂row, 1).
//     The +Y sign comes from Y = −row: ∂z/∂Y = −strength·∂H/∂row and a graph's normal is
//     (−∂z/∂X, −∂z/∂Y, 1). So height rising towards +u tilts the normal towards −u (n.x < 0),
//     and height rising downwards in the image (towards +v) tilts it up in the image (n.y > 0).
//   * derivatives are central differences (H[k+1] − H[k−1])/2 inside, one-sided differences
//     (H[1] − H[0], H[N−1] − H[N−2]) on the first and last column/row, and 0 along an axis that
//     is one texel wide.
#pragma once

#include "heightmap.hpp"
#include "model.hpp"
#include "result.hpp"

#include <glm/glm.hpp>

#include <vector>

namespace dermis {

/// A unit-vector image, row 0 first (same layout as HeightImage).
struct NormalImage {
    int width = 0, height = 0;
    std::vector<glm::vec3> data; ///< width·height unit vectors

    const glm::vec3& at(int i, int j) const {
        return data[static_cast<std::size_t>(j) * width + i];
    }
};

/// The normal map of `bump` (conventions above). `strength` scales heights into texel units
/// (height units per texel); 0 gives (0, 0, 1) everywhere. Normals are computed in double and
/// stay finite and unit length for any finite strength (a slope too steep to represent gives a
/// normal in the surface plane).
/// Fails (InvalidArgument, naming "dermis::normalMapFromBump") on an empty image or one whose
/// data size is not width·height (field "bump"), a non-finite height (field "bump.data[k]"), or
/// a negative or non-finite strength (field "strength").
Result<NormalImage> normalMapFromBump(const HeightImage& bump, double strength);

/// The `strength` of a scene's normal map (the one formula for `bake --normals` and the
/// server's normal-map route): a bump-map unit rises `bumpStrength` % of the map's width, in
/// texels: 0.01 · bumpStrength · mapWidth. bumpStrength is the scene's render.bump_strength
/// (≥ 0, validateRenderSettings).
double normalMapStrength(double bumpStrength, int mapWidth);

/// Encodes a normal map as RGBA8: each component c ∈ [−1, 1] becomes round((c·0.5 + 0.5)·255)
/// (so 0 → 128, 1 → 255, −1 → 0; values outside [−1, 1] are clamped, non-finite ones encode as
/// 0 → 128), alpha 255. Row order is kept (row 0 first). Returns an empty Image8 (0×0) when `n`
/// is empty or its data size is not width·height.
Image8 encodeNormalMap8(const NormalImage& n);

} // namespace dermis
