// Dermis io shell — animated WebP (libwebpmux's WebPAnimEncoder): the turntable route's range-of-
// motion previews, and a decoder (libwebpdemux's WebPAnimDecoder) for tests and tools.
//
// Frames are dermis::Image8 (8-bit RGBA, row 0 = top, sRGB, straight alpha), all of one size.
// Lossy (quality 0–100) with alpha dropped, looping forever, each frame shown `delayMs`.
// Thread-safe: no shared state.
//
// Failure: no frames, frames of different sizes, a side over kMaxWebpSide, an rgba buffer whose
// size is not width·height·4, quality outside [0, 100], delay outside [1, 65535] →
// ErrorCode::InvalidArgument naming the field ("frames", "quality", "delay"); libwebp's own
// failure → ErrorCode::Io; undecodable bytes in decodeAnimatedWebp → ErrorCode::Parse.
#pragma once

#include "core/model.hpp"
#include "core/result.hpp"

#include <cstdint>
#include <vector>

namespace dermis {

/// Encodes `frames` as a looping animated WebP, `delayMs` per frame.
Result<std::vector<std::uint8_t>> encodeAnimatedWebp(const std::vector<Image8>& frames, int delayMs,
                                                     float quality = 80.0f);

/// An animated WebP decoded: every frame composed (RGBA8) and its timestamp (ms, end of frame).
struct DecodedAnimation {
    std::vector<Image8> frames;
    std::vector<int> timestamps;
    int loopCount = -1; ///< 0 = forever
};
Result<DecodedAnimation> decodeAnimatedWebp(const std::vector<std::uint8_t>& bytes);

} // namespace dermis
