// dermis-charactergen — writing the character: a binary glTF 2.0 (.glb) through tinygltf and
// the JSON sidecar that lists the UV charts and landmark points.
//
// The .glb holds one scene: the joint hierarchy (root first), a root node "body" with the
// skinned mesh (one primitive: POSITION, NORMAL, TEXCOORD_0, JOINTS_0 as unsigned bytes,
// WEIGHTS_0 as floats, unsigned-short indices), one skin over all joints with inverse bind
// matrices, one material and the clips (LINEAR samplers). Output bytes depend only on the model.
#pragma once

#include "character.hpp"
#include "core/model.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace dermis::chargen {

/// Encodes `model` (one part, node i = joint i, joints = all skin joints, the last node holding
/// the mesh) as GLB bytes. Returns an empty vector when tinygltf fails.
std::vector<std::uint8_t> encodeGlb(const dermis::Model& model);

/// The charts sidecar (format "dermis.charts/1"), pretty-printed with a final newline.
std::string chartsJson(const Character& character, const std::string& modelFile);

} // namespace dermis::chargen
