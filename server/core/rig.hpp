// Dermis core — pose math: clip sampling, pose overrides, world matrices, CPU linear blend
// skinning (the paper's SSD). Joint angles are in angles.hpp (included here for convenience).
//
// Pure functions over a Model; no I/O. Thread-safe for concurrent calls on a const Model.
#pragma once

#include "angles.hpp"
#include "model.hpp"
#include "result.hpp"

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace dermis {

/// Local TRS of every node (same indexing as Model::nodes).
struct LocalPose {
    std::vector<glm::vec3> translation;
    std::vector<glm::quat> rotation;
    std::vector<glm::vec3> scale;
};

/// The model's rest pose (each node's own TRS).
LocalPose restPose(const Model& model);

/// Samples clip `clip` at `time` seconds (clamped to [0, duration]) over the rest pose: nodes
/// without a channel keep their rest TRS. LINEAR (slerp for rotations), STEP and CUBICSPLINE
/// (Hermite, rotations renormalised) as in glTF 2.0 Appendix C. Precondition: clip is a valid index.
LocalPose sampleClip(const Model& model, int clip, float time);

/// World matrix of every node for a local pose: world(n) = world(parent) · T · R · S (parents
/// before children not required). Precondition: `pose` has one entry per node (else identity).
std::vector<glm::mat4> worldMatrices(const Model& model, const LocalPose& pose);

/// Posed vertices of one part.
struct SkinnedPart {
    std::vector<glm::vec3> positions;
    std::vector<glm::vec3> normals; ///< unit length
};

/// CPU linear blend skinning of every part: p' = Σ w_k · world(node_k) · inverseBind_k · p;
/// normals with the inverse-transpose of the blended matrix, renormalised. `world` comes from
/// worldMatrices (one per node). Weights are used as stored (the loader normalises them). A part
/// whose joints/weights arrays do not match its vertex count follows influence 0; a part without
/// normals gets computeNormals of the posed positions. Never reads out of bounds.
std::vector<SkinnedPart> skin(const Model& model, const std::vector<glm::mat4>& world);

} // namespace dermis
