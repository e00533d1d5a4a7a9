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

/// Local TRS of every node (same indexing as Model::nodes), and the morph weights.
struct LocalPose {
    std::vector<glm::vec3> translation;
    std::vector<glm::quat> rotation;
    std::vector<glm::vec3> scale;
    std::vector<float> morphWeights; ///< one per Model::morphWeights
};

/// The model's rest pose (each node's own TRS, each morph weight's rest value).
LocalPose restPose(const Model& model);

/// Samples clip `clip` at `time` seconds (clamped to [0, duration]) over the rest pose: nodes
/// without a channel keep their rest TRS, morph weights without one their rest value. LINEAR (slerp for rotations), STEP and CUBICSPLINE
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

/// A part's bind-space attributes with its morph targets applied (MorphTarget's formula).
struct MorphedPart {
    std::vector<glm::vec3> positions;
    std::vector<glm::vec3> normals;  ///< unit; empty when the part has none
    std::vector<glm::vec4> tangents; ///< unit xyz, the part's w; empty when the part has none
};

/// The weight each morph target of `part` gets: weights[target.weight], or the rest value of
/// that Model::morphWeights entry when `weights` does not have one per entry; 0 for a target
/// naming no entry.
float morphWeightOf(const Model& model, const MorphTarget& target, const std::vector<float>& weights);

/// `part` (of `model`) with its morph targets at `weights` (one per Model::morphWeights; empty:
/// the rest values). Targets whose arrays do not match the vertex count are skipped; a normal or
/// tangent that sums to zero keeps its unmorphed value.
MorphedPart morphPart(const Model& model, const MeshPart& part, const std::vector<float>& weights);

/// CPU linear blend skinning of every part after its morph targets (morphPart with
/// `morphWeights`; empty: the rest values): p' = Σ w_k · world(node_k) · inverseBind_k · p;
/// normals with the inverse-transpose of the blended matrix, renormalised. `world` comes from
/// worldMatrices (one per node). Weights are used as stored (the loader normalises them). A part
/// whose joints/weights arrays do not match its vertex count follows influence 0; a part without
/// normals gets computeNormals of the posed positions. Never reads out of bounds.
std::vector<SkinnedPart> skin(const Model& model, const std::vector<glm::mat4>& world,
                              const std::vector<float>& morphWeights = {});

} // namespace dermis
