// Dermis core — what a model's own UVs are good for (SPEC §8 "UV diagnosis"): used and overlapping
// texel fractions with the regions / joints that share texels, mirrored island pairs, missing or
// out-of-range UVs, texel density per driving joint. `uv_layout: auto` chooses the model's UVs
// when `usable()`.
//
// Pure (no GL, no I/O); deterministic.
#pragma once

#include "model.hpp"

#include <string>
#include <vector>

namespace dermis {

struct UvDiagnosis {
    bool hasUVs = false;          ///< every part has TEXCOORD_0 (Model::hasUVs)
    double usedFraction = 0.0;    ///< texels of [0,1]² covered by at least one triangle
    double overlapFraction = 0.0; ///< of used texels, those claimed by more than one surface region
    // (the rest is filled in by the diagnosis itself: regions, mirrored pairs, density, …)

    /// The model's UVs can hold height maps: present and overlap below 0.5 % of used texels.
    bool usable() const { return hasUVs && overlapFraction < 0.005; }
};

} // namespace dermis
