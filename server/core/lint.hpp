// Dermis core — what may be wrong with a scene that still validates (SPEC §6 Lint): footprints
// hanging off the UV charts (the pattern is lost there) or across a chart seam, footprints
// overlapping on one target, θ ranges no clip reaches, driver joints with no skin influence under
// their footprint.
//
// Each placement's footprint is sampled on a 12×12 grid of pattern coordinates; only samples
// where its pattern is not flat (|L| > 0.02, when the image is given) count, so a transparent
// border hanging off a chart is no finding. Clips are sampled at 30 fps. Disabled placements are
// skipped. Pure; reads the model through `lookup` (which must index the same model).
#pragma once

#include "bake.hpp"
#include "uv_lookup.hpp"

#include <string>
#include <vector>

namespace dermis {

enum class LintSeverity { Info, Warning };
std::string_view toString(LintSeverity s);

struct LintFinding {
    std::string code;     ///< off_chart, across_seam, overlap, unreachable_range, no_influence, no_uvs
    LintSeverity severity = LintSeverity::Warning;
    int placement = -1;   ///< index in Scene::placements (−1: the scene as a whole)
    std::string message;  ///< for people: what and why, with the numbers
};

/// The findings of `scene` on `model`, by placement in document order. `images` may lack a
/// pattern (then every sample counts). Never fails: unknown joints or clips are what
/// validation reports, not lint.
std::vector<LintFinding> lintScene(const Scene& scene, const Model& model, const UvLookup& lookup,
                                   const PatternImages& images);

} // namespace dermis
