// Dermis core — what may be wrong with a scene that still validates (SPEC §6 Lint): footprints
// hanging off the UV charts (the pattern is lost there) or across a chart seam, footprints
// overlapping on one target, θ ranges no clip reaches (a joint no clip turns is not judged), driver joints with no skin influence under
// their footprint, mirror pairs that are not symmetric; and, from the model's UV diagnosis (SPEC
// §8, lint_uv.hpp), footprints on texels other regions of the body share (uv_overlap, naming
// where the pattern also shows) and UV placements on a model without UVs (no_uvs).
//
// Placements with projection "surface" get only unreachable_range here (their footprint is on
// the body, not in the model's UVs); so do UV placements on a model without UVs. Where the atlas
// overlaps itself a footprint sample is held by several triangles: the placement's is the one its
// driver joint (or that joint's parent) weighs most — its chart for across_seam, its weight for
// no_influence (a region of the diagnosis driven by one of them also counts: palette atlases
// collapse triangles below a texel, which the UV index cannot find).
//
// Mirror pairs: two enabled placements with the same pattern whose joints are mirror twins by
// name (mirrorJointName: elbow.l / elbow.r; an intentionally different pattern is no pair), each
// placement paired once, with the candidate nearest to where it mirrors. The first of the pair
// (document order) is mirrored by mirrorPlacement (core/mirror.hpp) and compared with the
// second: centre (kMirrorCenterTexels of the scene's height map), scale (kMirrorScaleFraction
// per axis), rotation (kMirrorRotationDegrees, modulo 180°: a reflection is no rotation, so the
// twin may have the mirrored rotation or that turned by a half turn, which is the reflection of a
// pattern symmetric about its v axis), axis (kMirrorAxisDegrees; an axis and its opposite with
// the negated θ range count as the same driver), θ range (kMirrorThetaDegrees), and h / model /
// target / response (equal). Unpaired placements are no finding.
//
// Surface placements (SPEC §8) are seamless and need no UVs: instead of off_chart / across_seam
// they may get off_surface (no vertex of the rest mesh within the decal's depth of the anchor);
// no_influence reads the skin weights of the mesh vertices the decal reaches (the anchor's
// nearest vertex when it reaches none); overlaps with any placement are counted on those
// vertices (a UV placement's samples are put on the surface through the UV index); mirror pairs
// compare anchors (kMirrorAnchorFraction of the size), size and rotation. On a model without
// UVs only UV placements are reported (no_uvs, once).
//
// Each placement's footprint is sampled on a 12×12 grid of pattern coordinates; only samples
// where its pattern is not flat (|L| > 0.02, when the image is given) count, so a transparent
// border hanging off a chart is no finding. Clips are sampled at 30 fps. Disabled placements are
// skipped. Pure; reads the model through `lookup` (which must index the same model). The
// overload taking a ModelDerived reads the model's UV index, rest skin, symmetry plane and UV
// diagnosis from it (built once per model) instead of computing them per call.
#pragma once

#include "bake.hpp"
#include "mirror.hpp" // kMirrorCenterTexels: centre distance, height-map texels
#include "model_derived.hpp"
#include "uv_lookup.hpp"

#include <string>
#include <vector>

namespace dermis {

enum class LintSeverity { Info, Warning };
std::string_view toString(LintSeverity s);

/// Tolerances of a mirror pair (see above).
inline constexpr double kMirrorScaleFraction = 0.15;   ///< |scale / mirrored scale − 1| per axis
inline constexpr double kMirrorRotationDegrees = 10.0; ///< footprint rotation, modulo 180°
inline constexpr double kMirrorAxisDegrees = 5.0;      ///< angle between the axes
inline constexpr double kMirrorThetaDegrees = 0.5;     ///< θmin and θmax each

struct LintFinding {
    /// off_chart, across_seam, off_surface, overlap, unreachable_range, no_influence,
    /// mirror_asymmetric, no_uvs, uv_overlap
    std::string code;
    LintSeverity severity = LintSeverity::Warning;
    int placement = -1;   ///< index in Scene::placements (−1: the scene as a whole)
    std::string message;  ///< for people: what and why, with the numbers
};

/// The findings of `scene` on `model`, by placement in document order (a mirror pair's finding
/// under its first placement, naming both). `images` may lack a
/// pattern (then every sample counts). Never fails: unknown joints or clips are what
/// validation reports, not lint.
std::vector<LintFinding> lintScene(const Scene& scene, const Model& model, const UvLookup& lookup,
                                   const PatternImages& images);
/// The same findings, identical, on derived.model() with its cached UV index, rest skin,
/// symmetry plane and UV diagnosis (built if not yet: the diagnosis — and with it the rest skin
/// and plane — for a scene with an enabled UV placement on a model with UVs, the rest skin and
/// plane on the first mirror pair). Never fails either; the caller keeps `derived` alive for the
/// call.
std::vector<LintFinding> lintScene(const Scene& scene, const ModelDerived& derived,
                                   const PatternImages& images);

} // namespace dermis
