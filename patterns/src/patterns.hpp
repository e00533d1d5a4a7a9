// Dermis built-in pattern library — procedural height patterns (SPEC §3, paper §3 and Fig. 2).
//
// Every pattern is a pure function of its pixel size: no clocks, no std::random_device, no
// <random> distributions — noise comes from an integer hash, so the output is bit-identical
// from run to run. Heights L lie in [−1, 1] and fade to 0 at the image border (|L| < 0.01 on the
// outermost texels). Images are square, row 0 first; pattern coordinates are (x, y) ∈ [0,1]²,
// x to the right and y down, texel (i, j) centred at ((i+0.5)/N, (j+0.5)/N) as in SPEC §2.
//
// Kinds and their value conventions:
// * wrinkle (scale model, bump): grooves are negative (the deepest reaches −1), with slight
//   positive ridges of compressed skin between them; grooves taper at their ends and vary in
//   depth, width and spacing.
// * bulge (scale model, displacement): one smooth C² dome, peak 1.0, no flat top, no rings.
// * bone (bias model, bump): non-negative (the bias model's max(L − offset, 0) would make any
//   negative value pop in only at t = 1); the crest reaches 1.0 and falls off smoothly, so that
//   as the offset drops with the angle more and more of the bone's silhouette shows.
#pragma once

#include "core/heightmap.hpp"
#include "core/scene.hpp"

#include <string>
#include <vector>

namespace dermis::patterngen {

/// One generated pattern: its manifest entry (file = "<id>.png") and its height image.
struct GeneratedPattern {
    PatternInfo info;
    HeightImage image;
};

/// The manifest entries of the library, in library order (no images). Same for every size.
std::vector<PatternInfo> libraryInfo();

/// Generates pattern `id` at size×size texels. Precondition: id is one of libraryInfo()'s ids,
/// size ≥ 16.
HeightImage generatePattern(const std::string& id, int size);

/// All patterns of the library, in library order.
std::vector<GeneratedPattern> generateLibrary(int size);

/// An 8-bit RGB image, row 0 first.
struct RgbImage {
    int width = 0, height = 0;
    std::vector<unsigned char> data; ///< width·height·3 bytes
};

/// A contact sheet of the library: one shaded-relief tile per pattern (warm = raised, cool =
/// sunken, lit from the top left) with its id and kind written under it.
RgbImage contactSheet(const std::vector<GeneratedPattern>& patterns);

} // namespace dermis::patterngen
