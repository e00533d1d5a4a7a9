// Dermis io shell — the pixel size an encoded PNG or JPEG declares in its header (PNG IHDR, JPEG
// SOFn), read from the bytes without decoding anything: how the glTF loader checks a texture
// against its limits before the decoder allocates width × height pixels.
//
// Reads only the bytes given (never past `size`); allocates nothing. Does not check that the rest
// of the file is valid: the decoder does that later. Failure: nullopt for anything that is not a
// PNG or JPEG, or whose header is truncated or declares a zero side.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>

namespace dermis {

/// Width and height in pixels, as a header declares them.
struct ImageSize {
    std::uint32_t width = 0, height = 0;
};

/// The size a PNG (IHDR, the first chunk) or a baseline/progressive JPEG (the first SOFn
/// segment) declares; nullopt for other formats, truncated headers and zero sides.
std::optional<ImageSize> encodedImageSize(const std::uint8_t* bytes, std::size_t size);

} // namespace dermis
