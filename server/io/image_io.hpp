// Dermis io shell — pattern images in, float height maps out, through OpenImageIO.
//
// Value mapping of SPEC §2: 16-bit unsigned L = clamp((v − 32768)/32767, −1, 1); 8-bit unsigned
// L = clamp((v − 128)/127, −1, 1); half/float/double images as they are, clamped to [−1, 1]; any
// other integer type is read as normalised [0, 1] float and mapped as 2·v − 1. Multi-channel
// images use their FIRST channel (red, or grey of grey+alpha) — not luminance.
// Failure: missing, truncated or undecodable files, zero or huge (> limits) sizes → Error.
#pragma once

#include "core/heightmap.hpp"
#include "core/model.hpp"
#include "core/result.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace dermis {

/// Largest pattern or base-map side accepted, in pixels.
constexpr int kMaxPatternSize = 8192;

/// Reads a pattern (or static height map) file.
Result<HeightImage> readHeightImage(const std::string& path);
/// Same, from encoded bytes in memory (PNG, TIFF, EXR, … by content).
Result<HeightImage> readHeightImageFromMemory(const std::vector<std::uint8_t>& bytes);

/// Writes a single-channel 32-bit float image (EXR by extension, row 0 first).
Status writeFloatImage(const std::string& path, const HeightImage& image);
/// Writes a 16-bit grey PNG with the inverse of the 16-bit mapping (L = 0 → 32768).
Status writeHeight16Png(const std::string& path, const HeightImage& image);

/// Decodes an encoded image (PNG, JPEG, …) to RGBA8 (grey → RGB, missing alpha → 255).
Result<Image8> decodeImage8(const std::vector<std::uint8_t>& bytes);

} // namespace dermis
