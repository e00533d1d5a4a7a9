// dermis-charactergen — skin weights of the default character.
//
// Each vertex is shared between the body's skinning chains (body.hpp) by OWNERSHIP: a soft-min
// of the distances to each chain's groups, so ownership changes smoothly where groups blend
// (armpits, groin, neck base). Within a chain, weights follow the bones by AXIAL position: at
// every junction the next bone's share rises along a smoothstep across a zone of ±halfWidth
// around the junction plane (bisector of the two bones), which keeps bends smooth and the twist
// joints sharing the twist of their segment. A few rounds of one-ring smoothing, then the four
// largest influences, renormalised so that they sum to 1.
#pragma once

#include "body.hpp"
#include "skeleton.hpp"
#include "surface.hpp"

#include <glm/glm.hpp>

#include <vector>

namespace dermis::chargen {

struct SkinWeights {
    std::vector<glm::u16vec4> joints; ///< skeleton joint indices, one per vertex
    std::vector<glm::vec4> weights;   ///< sum to 1, sorted by decreasing weight; unused = 0
};

/// Weights for every vertex of `mesh`. Deterministic.
SkinWeights computeWeights(const TriMesh& mesh, const Body& body, const Skeleton& skeleton);

/// The chain's bone weights at p (one per bone of the chain, summing to 1).
std::vector<float> chainWeights(const Chain& chain, const glm::vec3& p);

} // namespace dermis::chargen
