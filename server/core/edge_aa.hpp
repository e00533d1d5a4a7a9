// Dermis core — post-process anti-aliasing of a rendered frame (`render.aa: "post"`, SPEC §2b
// "render"): an edge pass after FXAA 3.11's quality preset (T. Lottes, NVIDIA, 2011) over an
// 8-bit sRGB frame drawn with one sample per pixel.
//
// Why on the CPU, over the read-back frame: on Mesa's llvmpipe (where `aa: auto` chooses this
// pass) a fragment shader runs every branch for every pixel of its SIMD block, so the same
// algorithm as a GL full-screen pass cost ≈ 140 ms per 1024² frame there; here a pixel whose
// four neighbours are flat costs a few compares and only edge pixels (a few percent) run the
// search. A GPU keeps MSAA as its default.
//
// Pure: no GL, no image library. Does not resample, blur flat areas or touch alpha (the frame's
// alpha is 255 and stays so).
#pragma once

#include "model.hpp"

namespace dermis {

/// Anti-aliases `image` (RGBA8, sRGB-encoded, row 0 first) in place, in one pass that reads the
/// input only: a pixel whose luma contrast with its 4 neighbours is below max(1/32, 1/8 of the
/// local maximum) is left as it is; on an edge, the edge's direction comes from the 3×3 luma
/// gradients, the search walks along it both ways (up to 10 steps of 1–8 pixels) to its ends, and
/// the pixel becomes a linear blend of itself and its neighbour across the edge, weighted by how
/// near the nearer end is, or by the sub-pixel term (how much it stands out of its 3×3 average,
/// at half FXAA's default strength, so texture detail stays) where that is larger. Luma is
/// computed on the encoded values, as FXAA does.
///
/// Only the span of each row whose luma differs from pixel (0, 0)'s — the background of a
/// rendered frame — and of the rows beside it, widened by a pixel, is tested: outside it a pixel
/// and its neighbours have one luma (no edge), so the result is the one of testing every pixel
/// (the 60-frame 1024² range's edge pass took 7.5 % of its CPU before, 3.4 % after).
/// `threads`: rows are split over that many threads (0: up to 2, and 1 below 256×256 pixels).
/// An image with a side under 3 pixels, or whose buffer does not hold width·height·4 bytes, is
/// left unchanged. Deterministic: the result does not depend on `threads`.
void antiAliasEdges(Image8& image, int threads = 0);

} // namespace dermis
