// dermis-charactergen — the whole default character: skeleton, body surface, UV atlas, skin
// weights and clips, assembled into a dermis::Model (one skinned mesh part, node i = joint i for
// the 51 joints, then the mesh node "body").
//
// Fixed parameters (grid, triangle budget) make the output deterministic: the same binary writes
// the same bytes on every run. buildCharacter fails with a message when a check fails (mesh not
// a closed genus-0 manifold, triangle budget missed, atlas invalid, weights not normalised).
#pragma once

#include "body.hpp"
#include "core/model.hpp"
#include "skeleton.hpp"
#include "surface.hpp"
#include "uv_atlas.hpp"
#include "weights.hpp"

#include <string>
#include <vector>

namespace dermis::chargen {

/// Triangle budget of the default character (the paper's test model has about 4,300).
constexpr std::size_t kTriangleBudget = 4300;
/// Marching-tetrahedra cell size in metres.
constexpr float kGridCell = 0.007f;

/// A named surface point useful for placing patterns, with its texture coordinates.
struct Landmark {
    std::string name;
    std::string pattern; ///< built-in pattern that suits the spot (patterns/manifest.json)
    std::string joint;   ///< joint that drives it
    std::string axis;    ///< rotation axis of that joint ("x", "y" or "z")
    glm::vec3 position{0};
    glm::vec2 uv{0};
    std::string chart;
};

struct Character {
    Skeleton skeleton;
    TriMesh mesh;        ///< welded surface (one vertex per position)
    Atlas atlas;         ///< seams split vertices: model vertices = atlas.source.size()
    SkinWeights weights; ///< per welded vertex
    dermis::Model model;
    std::vector<Landmark> landmarks;
};

/// Builds the default character. `log` receives progress lines (may be null).
bool buildCharacter(Character& out, std::string& error, std::FILE* log);

} // namespace dermis::chargen
