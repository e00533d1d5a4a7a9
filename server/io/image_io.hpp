// Dermis io shell — pattern images in, float height maps out (to memory or to a file). PNG and
// JPEG are decoded directly (libpng, libjpeg-turbo: image_decode.hpp) and 16-bit PNGs written
// with libpng; every other format (EXR in and out, TIFF, BMP, HDR, WebP, GIF, TGA, PSD, CMYK
// JPEG, and PNGs with alpha read from a file) goes through OpenImageIO in the module
// libdermis_oiio.so, loaded on first use (oiio_loader.hpp): when it cannot be loaded those
// formats fail with ErrorCode::Unavailable naming the module. Encoded bytes are decoded from
// memory only (an IOProxy for OpenImageIO), never through a file; a format whose plugin cannot
// read from memory is Unsupported.
//
// Value mapping of SPEC §2: 16-bit unsigned L = clamp((v − 32768)/32767, −1, 1); 8-bit unsigned
// L = clamp((v − 128)/127, −1, 1); half/float/double images as they are, clamped to [−1, 1]; any
// other integer type is read as normalised [0, 1] float and mapped as 2·v − 1. Multi-channel
// images use their FIRST channel (red, or grey of grey+alpha) — not luminance.
// Failure: missing, truncated or undecodable files, zero or huge (> limits) sizes → Error.
#pragma once

#include "core/environment.hpp"
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
/// Same, from encoded bytes in memory (PNG, JPEG, TIFF, EXR, BMP, HDR, WebP, GIF, TGA, by
/// content), decoded in memory: no file is written, not even a temporary one. Parse for empty,
/// unrecognised or corrupt data; Unsupported for a format that cannot be read from memory.
/// Sides over `maxSide` are refused (TooLarge) from the header or the decoder's spec, before any
/// pixel is decoded, whatever the format.
Result<HeightImage> readHeightImageFromMemory(const std::vector<std::uint8_t>& bytes, int maxSide = kMaxPatternSize);

/// Encodes a height map in memory as a single-channel ("Y") 32-bit float OpenEXR, row 0 first,
/// values as they are, through the OpenImageIO module with its default compression.
/// InvalidArgument for an empty or inconsistent image; Unsupported when OpenImageIO cannot write
/// EXR to memory; Unavailable when the module cannot be loaded.
Result<std::vector<std::uint8_t>> encodeFloatExr(const HeightImage& image);
/// Encodes a height map in memory as a 16-bit grey PNG with the inverse of the 16-bit mapping:
/// v = round(32768 + 32767·clamp(L, −1, 1)) (L = 0 → 32768; NaN → 32768), with libpng's
/// default compression. InvalidArgument for an empty or inconsistent image.
Result<std::vector<std::uint8_t>> encodeHeight16Png(const HeightImage& image);
/// The raw map: width·height little-endian IEEE-754 float32 values, row 0 first, no header
/// (the server's `f32` format). InvalidArgument for an empty or inconsistent image.
Result<std::vector<std::uint8_t>> encodeF32(const HeightImage& image);

/// encodeFloatExr to a file, replaced whole (writeFileAtomically, atomic_file.hpp).
Status writeFloatImage(const std::string& path, const HeightImage& image);
/// encodeHeight16Png to a file, replaced whole.
Status writeHeight16Png(const std::string& path, const HeightImage& image);

/// Largest side of an environment image (`--environment`).
constexpr int kMaxEnvironmentSide = 8192;

/// Reads an environment for image-based light (core/environment.hpp: equirectangular, linear RGB
/// radiance, row 0 at the top): a Radiance .hdr or OpenEXR file as stored, any other format
/// OpenImageIO reads (8-bit ones as their values / 255, not decoded from sRGB), through the
/// module. NotFound for a missing file; TooLarge past kMaxEnvironmentSide; Parse for unreadable
/// data; InvalidArgument (validateEnvironment's field) for a size under 2 or negative or
/// non-finite values; Unavailable without the module. `maxSide` (≤ kMaxEnvironmentSide) lowers
/// the side limit (a server's maxImageSide for uploads).
Result<EnvironmentImage> readEnvironmentImage(const std::string& path, int maxSide = kMaxEnvironmentSide);

/// Decodes an encoded image (PNG, JPEG, …) to RGBA8 (grey → RGB, missing alpha → 255, alpha
/// unassociated, 16-bit samples rounded to 8 bits), PNG and JPEG without the module.
Result<Image8> decodeImage8(const std::vector<std::uint8_t>& bytes);

} // namespace dermis
