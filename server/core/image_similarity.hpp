// Dermis core — how alike two rendered frames are: the structural similarity index (SSIM, Wang,
// Bovik, Sheikh & Simoncelli 2004) on luma, for measuring an anti-aliasing mode against MSAA 4x
// and against a supersampled frame (tests, `dermis-bench`'s AA figures, docs/benchmarks.md).
//
// Pure. Does not weigh colour or alpha; does not align or scale images.
#pragma once

#include "model.hpp"
#include "result.hpp"

namespace dermis {

/// Mean SSIM of `a` and `b` (RGBA8, the same size): luma Y = 0.299 R + 0.587 G + 0.114 B on the
/// encoded values, 8×8 windows every 4 pixels (uniform weights), constants C1 = (0.01·255)²,
/// C2 = (0.03·255)². 1 for identical images, lower as structure differs; ≥ 0.98 reads as "hard
/// to tell apart". Fails (InvalidArgument, naming `b`) when the sizes differ, an image is
/// smaller than 8×8 or a buffer does not hold width·height·4 bytes.
Result<double> ssim(const Image8& a, const Image8& b);

/// `image` shrunk by `factor` in each direction, each pixel the rounded mean of its factor×factor
/// block (encoded values averaged: near enough for a supersampled reference to compare frames
/// with). Rows and columns past a whole block are dropped. Fails (InvalidArgument) when factor < 1,
/// the image is smaller than one block or its buffer does not hold width·height·4 bytes.
Result<Image8> boxDownsample(const Image8& image, int factor);

} // namespace dermis
