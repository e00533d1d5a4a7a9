// Dermis core — a height image as a picture for people (pattern thumbnails in the editor).
//
// Pure. Not a height-map export (see io/image_io for 16-bit PNG and EXR): 8 bits, clamped.
#pragma once

#include "heightmap.hpp"
#include "model.hpp"

namespace dermis {

/// A `width`-wide RGBA8 grey picture of `src` (height keeps the aspect ratio, at least 1), sampled
/// bilinearly at pixel centres: grey = (L + 1) / 2 clamped to [0, 1], so L = −1 is black, 0 mid
/// grey, +1 white; alpha 255. Preconditions: `src` non-empty, width ≥ 1.
Image8 heightPreview(const HeightImage& src, int width);

} // namespace dermis
