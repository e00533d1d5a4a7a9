// Dermis io shell (internal) — direct decoders for the common formats: PNG with libpng and JPEG
// with libjpeg-turbo, so that pattern images and glTF textures decode without loading the
// OpenImageIO module (oiio_module.hpp). They give the same pixels as OpenImageIO's readers
// (checked by ImageDecodeTest on generated variants, the pattern library and the test models):
//   PNG: palette → RGB, grey of 1/2/4 bits → 8 bits (scaled: 1 → 255), a tRNS chunk → an alpha
//        channel, 16-bit samples kept; interlacing undone; no gamma or colour-profile conversion
//        (chunks are ignored, as OpenImageIO does); alpha as stored (unassociated).
//   JPEG: grey → 1 channel, colour → 3 channels (RGB), accurate integer DCT, smooth upsampling.
// Anything else — other formats, CMYK/YCCK JPEGs, and PNG/JPEG data that is not recognised at
// all — is not decoded here (std::nullopt), and the caller hands it to the module.
//
// Thread-safe; no global state. Failure: corrupt or truncated data of a recognised format →
// ErrorCode::Parse ("libpng: …", "libjpeg-turbo: …"); a side over `maxSide` → InvalidArgument
// with "larger than the limit" (as the module words it), before pixels are allocated.
#pragma once

#include "core/result.hpp"

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace dermis {

/// Interleaved pixels as stored: `channels` samples per pixel (1 grey, 2 grey+alpha, 3 RGB,
/// 4 RGBA), 8 bits in `u8` or 16 bits in `u16` (the other vector is empty), row 0 first.
struct DecodedPixels {
    int width = 0, height = 0, channels = 0, bits = 8;
    bool alpha = false; ///< the last channel is alpha
    std::vector<std::uint8_t> u8;
    std::vector<std::uint16_t> u16;
};

/// Decodes PNG or JPEG bytes directly; std::nullopt when the bytes are another format or a
/// variant left to OpenImageIO (CMYK JPEG). `field` names the source in errors (a path or "").
std::optional<Result<DecodedPixels>> decodeDirect(const std::uint8_t* data, std::size_t size,
                                                  int maxSide, const char* where,
                                                  const std::string& field);

} // namespace dermis
