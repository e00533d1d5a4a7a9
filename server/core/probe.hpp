// Dermis core — why a texel has its height (SPEC §6 Probe): the maps' values at one texel and
// each placement's part in them, computed exactly as the CPU reference computes that texel.
//
// Pure; thread-safe on const inputs.
#pragma once

#include "frame_plan.hpp"

#include <vector>

namespace dermis {

/// One placement's part at the probed texel.
struct ProbeContribution {
    int source = -1;   ///< the scene placement (BakePlacement::source)
    Target target = Target::Bump;
    double t = 0.0;    ///< normalised angle
    float L = 0.0f;    ///< the pattern's value there (bilinear, SPEC §2 mapping)
    float height = 0.0f; ///< L_out added to its target map (paper eq. 1/2)
};

struct ProbeResult {
    int texelX = 0, texelY = 0; ///< the texel whose centre is nearest to (u, v)
    double u = 0.0, v = 0.0;    ///< that texel's centre
    float base = 0.0f;          ///< the static base map there (0 without one)
    float bump = 0.0f, displacement = 0.0f; ///< the maps' values, as bakeHeightMaps gives them
    /// Placements whose footprint covers the texel centre — for a surface placement (SPEC §8):
    /// whose decal reaches the texel's rest-surface point (HeightMapInput::rest) —, in document
    /// order (t = 0 included, with height 0).
    std::vector<ProbeContribution> contributions;
};

/// Probes the texel of `in`'s maps containing (u, v) ∈ [0, 1]² (u = 1 or v = 1 is the last
/// texel). Fails (InvalidArgument, field "u" or "v") outside [0, 1] or when not finite, and like
/// bakeHeightMaps on a bad map size, a placement without a pattern or a surface placement
/// without a rest map of the map's size.
Result<ProbeResult> probeHeights(const HeightMapInput& in, double u, double v);

} // namespace dermis
