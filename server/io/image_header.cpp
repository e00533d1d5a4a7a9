// Declared image sizes from PNG and JPEG headers (image_header.hpp). PNG: 8-byte signature, then
// the IHDR chunk (length, "IHDR", width and height as big-endian 32-bit). JPEG: SOI, then marker
// segments up to the first start-of-frame (SOF0–SOF15 except DHT C4, JPG C8, DAC CC), whose
// payload is precision (1 byte), height, width (big-endian 16-bit).
#include "image_header.hpp"

namespace dermis {
namespace {

std::uint32_t be32(const std::uint8_t* p) {
    return std::uint32_t(p[0]) << 24 | std::uint32_t(p[1]) << 16 | std::uint32_t(p[2]) << 8 |
           std::uint32_t(p[3]);
}

std::uint32_t be16(const std::uint8_t* p) {
    return std::uint32_t(p[0]) << 8 | std::uint32_t(p[1]);
}

std::optional<ImageSize> pngSize(const std::uint8_t* b, std::size_t size) {
    static const std::uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    if (size < 24) return std::nullopt;
    for (int k = 0; k < 8; ++k)
        if (b[k] != kSignature[k]) return std::nullopt;
    if (b[12] != 'I' || b[13] != 'H' || b[14] != 'D' || b[15] != 'R') return std::nullopt;
    return ImageSize{be32(b + 16), be32(b + 20)};
}

std::optional<ImageSize> jpegSize(const std::uint8_t* b, std::size_t size) {
    if (size < 4 || b[0] != 0xFF || b[1] != 0xD8) return std::nullopt;
    std::size_t at = 2;
    while (at + 1 < size) {
        if (b[at] != 0xFF) return std::nullopt; // segments follow each other without gaps
        const std::uint8_t marker = b[at + 1];
        if (marker == 0xFF) { // fill byte
            ++at;
            continue;
        }
        at += 2;
        // Markers without a length: TEM, RSTn; SOI again or EOI end the search.
        if (marker == 0x01 || (marker >= 0xD0 && marker <= 0xD7)) continue;
        if (marker == 0xD8 || marker == 0xD9 || marker == 0xDA) return std::nullopt; // no SOF
        if (at + 2 > size) return std::nullopt;
        const std::size_t length = be16(b + at);
        if (length < 2 || at + length > size) return std::nullopt;
        const bool sof =
            marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
        if (sof) {
            if (length < 7) return std::nullopt;
            return ImageSize{be16(b + at + 5), be16(b + at + 3)};
        }
        at += length;
    }
    return std::nullopt;
}

} // namespace

std::optional<ImageSize> encodedImageSize(const std::uint8_t* bytes, std::size_t size) {
    if (bytes == nullptr) return std::nullopt;
    auto s = pngSize(bytes, size);
    if (!s) s = jpegSize(bytes, size);
    if (!s || s->width == 0 || s->height == 0) return std::nullopt;
    return s;
}

} // namespace dermis
