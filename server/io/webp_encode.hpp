// Dermis io shell — lossless WebP frames (libwebp): an encoder to memory for the server's
// responses and offline renders, and a decoder for tests and tools.
//
// Frames are dermis::Image8 (8-bit RGBA, row 0 = top, sRGB-encoded colour, straight alpha; see
// frame_io.hpp). The encoding is lossless and exact: decoding gives back every byte, colour under
// fully transparent pixels included (libwebp's `exact` flag). Thread-safe: no shared state.
//
// Failure: an empty frame, a side over kMaxFrameSide or over WebP's 16383 limit, or an rgba buffer
// whose size is not width·height·4 → ErrorCode::InvalidArgument naming the function and the field
// ("image", "image.rgba"); libwebp's own failure (out of memory) → ErrorCode::Io with its error
// code; undecodable bytes in decodeWebp → ErrorCode::Parse.
#pragma once

#include "core/model.hpp"
#include "core/result.hpp"

#include <cstdint>
#include <vector>

namespace dermis {

/// WebP's largest picture side.
constexpr int kMaxWebpSide = 16383;

/// Encodes a frame as lossless WebP with the fastest lossless preset (level 0: no backward-
/// reference search beyond the basic one; ≈ PNG's size at a similar speed, see docs/benchmarks.md
/// "Encoders"). keepAlpha = false stores every pixel as opaque (alpha dropped, as encodePng's
/// keepAlpha = false); RGB are stored as is either way.
Result<std::vector<std::uint8_t>> encodeWebpLossless(const Image8& img, bool keepAlpha = true);

/// True when `bytes` start like a WebP file ("RIFF" size "WEBP").
bool looksLikeWebp(const std::vector<std::uint8_t>& bytes);

/// Decodes WebP bytes (lossless or lossy) to RGBA8 with libwebp (missing alpha → 255). Parse
/// error on anything else, corrupt or truncated data. Meant for tests and tools.
Result<Image8> decodeWebp(const std::vector<std::uint8_t>& bytes);

} // namespace dermis
