// dermis-charactergen — the default character's UV atlas (TEXCOORD_0).
//
// 1. Regions: every triangle gets a body region by rules on the skeleton (torso with neck, face,
//    back of the head, arm, hand back, palm, leg, foot top, sole — per side), each region made
//    one connected piece.
// 2. Cuts: a region with several boundary loops (a tube, the torso) is cut along shortest edge
//    paths between its loops, weighted to run on hidden sides (the back of the torso, the inner
//    back of the arms, the inner legs, the back of the heel), until it is a topological disk.
// 3. Flattening: Tutte embedding on a circle (bijective), then as-rigid-as-possible local/global
//    iterations (Liu et al. 2008). Each step goes as far toward the global solution as no
//    triangle flips (backtracking; when even a small global step flips, vertices move one by
//    one as far as their own triangles allow), and the last iterate whose boundary does not
//    cross itself is kept. A part the embedding left crushed (σ_max/σ_min ≥ 6, e.g. a
//    fingertip) gets a cut from the boundary to it and the chart is flattened again (≤ 6 times).
// 4. Orientation and packing: each chart turned so that "up" on the body is up in the texture
//    (v decreasing) and never mirrored, scaled to a common texel density (hands and feet a bit
//    less), packed without overlap into [0,1]² with padding.
// buildAtlas verifies the result (no flipped triangle, no overlap within or between charts,
// every UV in [0,1]) and fails with a message otherwise.
#pragma once

#include "body.hpp"
#include "skeleton.hpp"
#include "surface.hpp"

#include <glm/glm.hpp>

#include <cstdio>
#include <string>
#include <vector>

namespace dermis::chargen {

struct ChartInfo {
    std::string name;
    glm::vec2 lo{0}, hi{0}; ///< UV bounding box
    int triangles = 0;
    float surfaceArea = 0.0f; ///< m²
    float uvArea = 0.0f;
    float conformal = 0.0f;  ///< area-weighted mean of σ_max/σ_min of the UV map (1 = conformal)
    float areaSpread = 0.0f; ///< area-weighted mean |log(local area scale / chart area scale)|
};

struct Atlas {
    std::vector<std::uint32_t> source; ///< output vertex → mesh vertex (seams duplicate)
    std::vector<glm::vec2> uvs;        ///< per output vertex, glTF convention (v down)
    std::vector<glm::uvec3> tris;      ///< per mesh triangle, indices of output vertices
    std::vector<int> triChart;         ///< chart of each triangle
    std::vector<ChartInfo> charts;
};

/// Builds and verifies the atlas. Returns false with `error` set when a step fails (a region
/// that cannot be cut into a disk, a chart that flips or overlaps, a packing that does not fit).
bool buildAtlas(const TriMesh& mesh, const Body& body, const Skeleton& skeleton, Atlas& atlas,
                std::string& error, std::FILE* log = nullptr);

/// UV of the surface point nearest to `p` (by triangle centroid search and barycentric
/// projection), with the chart it lies in.
glm::vec2 uvAt(const TriMesh& mesh, const Atlas& atlas, const glm::vec3& p, int* chart);

} // namespace dermis::chargen
