// Dermis core — a generated, non-overlapping height-map layout (SPEC §8 `uv_layout: generated`):
// charts split at the model's UV seams and at sharp creases, flattened with low distortion,
// packed into [0,1]² with gutters for bilinear sampling and mip levels at near-uniform texel
// density. Deterministic: the same model data gives a bit-identical layout.
//
// Pure (no GL, no I/O). Fails (Result) only on a model it cannot lay out, naming why.
#pragma once

#include "model.hpp"
#include "result.hpp"
#include "texture_layout.hpp"

namespace dermis {

struct LayoutGenOptions {
    int resolution = 1024;  ///< the map side the gutters are measured at
    int gutterTexels = 4;   ///< free texels around each chart at `resolution` (≥ 2)
    double creaseDegrees = 75.0; ///< dihedral angle above which an edge is a chart boundary
};

/// The generated layout (kind "generated") of every part with triangles. Every layout triangle
/// lies inside [0,1]², no two triangles overlap, charts are ≥ gutterTexels apart at `resolution`.
Result<TextureLayout> generateTextureLayout(const Model& model, const LayoutGenOptions& options = {});

} // namespace dermis
