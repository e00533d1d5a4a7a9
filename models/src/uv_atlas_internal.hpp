// dermis-charactergen — private to models/src/uv_atlas*.cpp: the steps of the UV atlas that
// buildAtlas (uv_atlas.cpp) runs, each in its own file:
//   * uv_atlas_regions.cpp: the body regions (rules on the skeleton), mesh adjacency, and a
//     region's triangles as a local mesh split along its boundary and cut edges (LocalMesh);
//   * uv_atlas_flatten.cpp: flattening a disk-shaped local mesh (Tutte, then ARAP), distortion;
//   * uv_atlas_pack.cpp: skyline packing of chart boxes.
// Not included outside these files. Nothing here reports errors itself: flatten returns an empty
// result with a note, skylinePack a height above 1; buildAtlas turns them into messages.
#pragma once

#include "skeleton.hpp"
#include "surface.hpp"

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

// --- flattening (uv_atlas_flatten.cpp) ----------------------------------------------------------

/// Signed area of the 2-D triangle (a, b, c), positive when counter-clockwise.
double signedArea(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c);

/// σ_max / σ_min of the linear map taking a surface triangle onto its UV triangle.
double conformalDistortion(const glm::vec3& q0, const glm::vec3& q1, const glm::vec3& q2,
                           const glm::dvec2& u0, const glm::dvec2& u1, const glm::dvec2& u2);

/// Flattens a disk-shaped local mesh. Returns UVs in metres (isometric scale), positively
/// oriented triangles. Fails (empty result) when the Tutte embedding already flips (it cannot
/// for a disk with a convex boundary, up to solver accuracy).
std::vector<glm::dvec2> flatten(const LocalMesh& lm, const TriMesh& mesh, std::string& note);

// --- packing (uv_atlas_pack.cpp) ----------------------------------------------------------------

struct PackItem {
    int chart;
    double w, h; // size in UV units, padding included
    double x = 0, y = 0;
};

/// Skyline bottom-left packing into a strip of width 1 (items sorted by height). Returns the
/// height used.
double skylinePack(std::vector<PackItem>& items);

} // namespace dermis::chargen::atlas_detail
