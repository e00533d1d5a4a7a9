// Dermis core — pictures for people: a height image as grey (pattern thumbnails in the editor),
// and a smaller copy of an RGBA8 picture (a model's texture under the editor's UV layout).
//
// Pure. Not a height-map export (see io/image_io for 16-bit PNG and EXR): 8 bits, clamped.
#pragma once

#include "heightmap.hpp"
#include "model.hpp"

namespace dermis {

/// An RGBA8 grey picture of `src` whose longer side is `maxSide` pixels (the other keeps the aspect
/// ratio, at least 1, so at most maxSide² pixels), sampled bilinearly at pixel centres:
/// grey = (L + 1) / 2 clamped to [0, 1], so L = −1 is black, 0 mid grey, +1 white; alpha 255.
/// Preconditions: `src` non-empty, maxSide ≥ 1.
Image8 heightPreview(const HeightImage& src, int maxSide);

/// `src` made to fit in maxSide × maxSide, its aspect ratio kept: when its longer side is larger
/// than maxSide, that side becomes maxSide and the other round(side · maxSide / longer) (at least
/// 1), each output pixel the plain average (box filter, on the stored bytes: no linearisation,
/// alpha straight) of the source pixels whose centres fall in its footprint; otherwise an
/// unchanged copy (never enlarged). Preconditions: `src` non-empty with width·height·4 bytes,
/// maxSide ≥ 1.
Image8 downsizeImage(const Image8& src, int maxSide);

} // namespace dermis
