// dermis-charactergen — private to models/src/uv_atlas*.cpp: the steps of the UV atlas that
// buildAtlas (uv_atlas.cpp) runs:
//   * uv_atlas_regions.cpp: the body regions (rules on the skeleton), mesh adjacency, and a
//     region's triangles as a local mesh split along its boundary and cut edges (LocalMesh);
//   * the core's general pieces (one implementation with the generated height-map layout):
//     flattening a disk-shaped chart (Tutte, then ARAP) and distortion (core/uv_flatten.hpp),
//     skyline packing of chart boxes (core/uv_pack.hpp).
// Not included outside these files. Nothing here reports errors itself: flattenDisk returns an
// empty result with a note, skylinePack a height above 1; buildAtlas turns them into messages.
#pragma once

#include "skeleton.hpp"
#include "surface.hpp"

#include "core/uv_flatten.hpp"
#include "core/uv_pack.hpp"

#include <glm/glm.hpp>

#include <array>
#include <cstdint>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace dermis::chargen::atlas_detail {

// --- regions (uv_atlas_regions.cpp) -------------------------------------------------------------

struct RegionSpec {
    std::string name;
    glm::vec3 seamSide{0, 0, -1}; ///< world direction the cut seams prefer to face
    glm::vec3 up{0, 1, 0};        ///< world direction shown as "up" in the texture
    float scale = 1.0f;           ///< texel density relative to the body
};

enum Region : int {
    kTorso,
    kHeadFront,
    kHeadBack,
    kArmL,
    kArmR,
    kHandBackL,
    kHandBackR,
    kPalmL,
    kPalmR,
    kLegL,
    kLegR,
    kFootTopL,
    kFootTopR,
    kSoleL,
    kSoleR,
    kRegionCount
};

/// The rules that sort triangles into regions, measured on the skeleton (left side; the right
/// side mirrors x), and each region's chart settings (`specs`, indexed by Region).
struct Rules {
    glm::vec3 shoulder, d, palmN, wrist, ankle;
    glm::vec3 thumbA, thumbB, thumbSide; ///< left thumb segment and its palm-facing side
    std::vector<RegionSpec> specs;

    explicit Rules(const Skeleton& sk);

    /// Region of a triangle with centroid c and unit normal n.
    int classify(const glm::vec3& c, const glm::vec3& n) const;
};

/// adj[t][c] = triangle across edge (t[c], t[c+1]) (−1 where there is none).
std::vector<std::array<int, 3>> adjacency(const TriMesh& mesh);

using EdgeKey = std::pair<std::uint32_t, std::uint32_t>;
/// The undirected edge {a, b}, smaller index first.
EdgeKey edgeKey(std::uint32_t a, std::uint32_t b);

// --- chart-local meshes (uv_atlas_regions.cpp) --------------------------------------------------

/// A region's triangles with vertices split along the region boundary and the cut edges, so
/// that it is a manifold surface with boundary.
struct LocalMesh {
    std::vector<int> tris;                         ///< global triangle ids
    std::vector<std::uint32_t> source;             ///< local vertex → global vertex
    std::vector<glm::uvec3> local;                 ///< local triangles
    std::vector<std::vector<std::uint32_t>> loops; ///< boundary loops (local vertices, in order)
    std::vector<int> loopOf; ///< local vertex → loop index, −1 when interior
};

/// The local mesh of region `r`'s triangles `tris` (region[t] = region of each mesh triangle),
/// with vertices split where the region ends and along `cuts`, and its boundary loops.
LocalMesh buildLocal(const TriMesh& mesh, const std::vector<std::array<int, 3>>& adj,
                     const std::vector<int>& tris, const std::vector<int>& region, int r,
                     const std::set<EdgeKey>& cuts);

// --- flattening and packing (server/core/uv_flatten.hpp, uv_pack.hpp) ----------------------------

using dermis::ChartMesh;
using dermis::conformalDistortion;
using dermis::flattenDisk;
using dermis::PackItem;
using dermis::signedArea;
using dermis::skylinePack;

} // namespace dermis::chargen::atlas_detail
