// Dermis core — a generated, non-overlapping height-map layout (SPEC §8 `uv_layout: generated`):
// charts split at the model's UV seams and at sharp creases, flattened with low distortion,
// packed into [0,1]² with gutters for bilinear sampling and mip levels at near-uniform texel
// density. Deterministic: the same model data gives a bit-identical layout.
//
// How (docs/benchmarks.md "Generated height-map layout"; layout_gen_internal.hpp has the steps):
//   1. per part, vertices welded by bit-equal position; an edge is a chart boundary where it is a
//      border, non-manifold or inconsistently oriented, where the model's own UVs differ on its
//      two sides (a UV seam; only where both sides have a UV area, not a palette swatch), where the dihedral angle exceeds creaseDegrees, or next to a
//      degenerate triangle (repeated vertex or area ≤ 1e-6 · longest edge²);
//   2. charts grown best-first over the other edges, each triangle within coneDegrees of the
//      chart's seed normal and of its running mean normal (so every chart is a height field
//      over some plane, a projection gives the first guess);
//   3. each chart flattened by least-squares conformal maps (core/uv_flatten.hpp, two pins,
//      conjugate gradients from the projection), then scaled to its surface area; a chart that
//      is not a genus-0 surface with boundary, has a flipped triangle, a boundary that crosses
//      itself, or more than 2 % of its area stretched beyond maxAreaStretch is split in two
//      (two seeds far apart, breadth-first) and each half retried — a single triangle always
//      flattens;
//   4. every chart at one density (texels per metre), turned to its smallest bounding box and
//      packed on the texel grid with gutterTexels free texels between charts and along the
//      border, at the largest density that fits (bisection): as boxes (core/uv_pack.hpp
//      skylinePackGrid), then by their outlines (the rows each touches per column dropped onto a
//      horizon, Lévy et al. 2002 §6) where that fits more; degenerate triangles get one-texel
//      cells of their own in a lattice packed like a chart;
//   5. verified (checkTextureLayout): UVs in [0,1], no flip, no texel of two charts, gutters.
//
// Pure (no GL, no I/O, no threads, no state: safe to call from several threads). Bit-identical
// output for the same model data and the same build (no FMA contraction on x86-64). Does not
// cache (the Service keeps layouts per model) and does not orient charts by body direction (the
// default character's own atlas does). Fails when the charts cannot all get their gutters
// (roughly more than resolution² / (gutterTexels + 1)² charts: a triangle soup).
#pragma once

#include "heightmap.hpp"
#include "model.hpp"
#include "result.hpp"
#include "texture_layout.hpp"

#include <cstdint>
#include <vector>

namespace dermis {

struct LayoutGenOptions {
    int resolution = 1024; ///< the map side the gutters are measured at, [64, kMaxHeightmapSize]
    /// Free texels around each chart at `resolution`, between charts and along the border,
    /// [2, resolution/16] (bilinear sampling needs 1 at the level sampled; halves per mip level:
    /// 4 at 1024² keeps mip levels 0–2 apart).
    int gutterTexels = 4;
    /// Dihedral angle above which an edge is a chart boundary, (0, 180].
    double creaseDegrees = 75.0;
    /// A chart's triangle normals stay within this angle of its seed's and its running mean
    /// normal, (0, 85]: smaller gives more, flatter charts.
    double coneDegrees = 60.0;
    /// A chart is split when more than 2 % of its surface is scaled in area by more than this
    /// factor (either way) against the chart as a whole, [1.5, 100].
    double maxAreaStretch = 3.0;
};

/// What a layout is like: the checks generateTextureLayout makes (all zero for a generated one)
/// and its quality figures. Measured at texel centres of a resolution² map unless said.
struct LayoutCheck {
    std::size_t triangles = 0; ///< layout triangles (all parts)
    std::size_t malformed = 0; ///< triangles whose corners name a layout vertex out of range or
                               ///< a `source` other than the part's corner (or count mismatch)
    std::size_t outside = 0;   ///< triangles with a UV outside [0,1]² (or not finite)
    std::size_t flipped = 0;   ///< triangles whose UV area is not negative in (u, v-down) terms,
                               ///< i.e. mirrored or collapsed seen from outside
    std::size_t charts = 0;    ///< connected pieces (triangles sharing a layout vertex or UV point)
    std::int64_t usedTexels = 0;    ///< texel centres covered by a triangle
    std::int64_t overlapTexels = 0; ///< texel centres covered by triangles of two charts
    /// Fewest free texels between texels touched (conservatively) by two different charts or
    /// between a touched texel and the border, capped at `gutterCap`.
    int minGutterTexels = 0;
    double usedFraction = 0.0; ///< usedTexels / resolution²
    /// Area-weighted mean over triangles of max(r, 1/r), r = local UV area scale / the layout's
    /// (1 = every triangle at the mean density). Zero-area triangles are left out.
    double areaStretch = 0.0;
    double conformal = 0.0; ///< area-weighted mean σ_max/σ_min of the map surface → UV
    /// Smallest and largest chart density (√(UV area / surface area)) over the layout's.
    double chartDensityMin = 0.0, chartDensityMax = 0.0;
};

/// Measures `layout` of `model` (SPEC §8 acceptance of a generated layout). Works on any layout,
/// the model's own included. Memory: 4 bytes a texel. Preconditions: resolution in
/// [1, kMaxHeightmapSize], gutterCap ≥ 0.
LayoutCheck checkTextureLayout(const Model& model, const TextureLayout& layout, int resolution,
                               int gutterCap);

/// The generated layout and how it was made.
struct GeneratedLayout {
    TextureLayout layout;
    LayoutCheck check;      ///< at options.resolution, gutterCap = options.gutterTexels
    std::size_t charts = 0; ///< charts packed (the degenerate grid not counted)
    /// Per part, per triangle: its chart, in [0, charts); `charts` for a degenerate triangle.
    std::vector<std::vector<std::uint32_t>> chartOf;
    std::size_t splits = 0;      ///< charts split because a flattening failed a check
    std::size_t degenerate = 0;  ///< degenerate triangles (one-texel cells)
    double texelsPerMetre = 0.0; ///< density at options.resolution
};

/// The generated layout (kind "generated") of every part with triangles (parts without get an
/// empty PartLayout). Every layout triangle lies inside [0,1]², no two charts share a texel,
/// charts are ≥ gutterTexels apart at `resolution`, and source[indices[3k+c]] equals the part's
/// indices[3k+c] (layout vertices are split where the part's are, and at chart boundaries).
/// Fails (InvalidArgument naming the field) on options out of range, a part whose indices are
/// out of range or not a multiple of 3, or a model without triangles; (Internal) should a check
/// of the result fail, naming it.
Result<GeneratedLayout> generateTextureLayoutWithReport(const Model& model,
                                                        const LayoutGenOptions& options = {});

/// generateTextureLayoutWithReport's layout alone.
Result<TextureLayout> generateTextureLayout(const Model& model,
                                            const LayoutGenOptions& options = {});

/// The layout a scene with `mode` uses on `model`, uncached (the one-shot commands `render` and
/// `bake`; the service caches the same choice per model): the model's own UVs when
/// modelUvsHoldHeightmaps (uv_diagnosis.hpp) says so — "model", or "auto" on usable UVs — else
/// the generated layout. Fails as generateTextureLayout does.
Result<TextureLayout> textureLayoutFor(const Model& model, UvLayoutMode mode);

} // namespace dermis
