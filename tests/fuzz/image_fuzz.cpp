// libFuzzer target: the image decoders from memory (image_io.hpp) and the header sniffer
// (image_header.hpp) on any bytes: readHeightImageFromMemory (pattern uploads: PNG, JPEG, TIFF,
// EXR, BMP, HDR, WebP, GIF, TGA by content), encodedImageSize (the glTF loader's preflight), and
// decodeImage8 (glTF textures) the way the loader calls it: only for PNG/JPEG bytes whose
// declared size passed the preflight (here ≤ 1024² pixels, to stay fast and far below
// -rss_limit_mb; pattern images are bounded by kMaxPatternSize inside the decoder).
//
// What counts as a bug: a crash, a sanitizer report, a hang, or a decoded image whose size does
// not match its pixels (or, for decodeImage8, the size its header declared). An Error return is
// the expected answer to bad bytes. Built only with -DDERMIS_FUZZ=ON; run with `make fuzz`.
#include "io/image_header.hpp"
#include "io/image_io.hpp"

#include <cstddef>
#include <cstdint>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::vector<std::uint8_t> bytes(data, data + size);

    if (auto h = dermis::readHeightImageFromMemory(bytes)) {
        if (h->width <= 0 || h->height <= 0 || h->width > dermis::kMaxPatternSize ||
            h->height > dermis::kMaxPatternSize ||
            h->data.size() != std::size_t(h->width) * std::size_t(h->height))
            __builtin_trap();
        for (float v : h->data)
            if (!(v >= -1.0f && v <= 1.0f)) __builtin_trap(); // SPEC §2: heights in [-1, 1]
    }

    const auto declared = dermis::encodedImageSize(data, size);
    if (declared && std::uint64_t(declared->width) * declared->height <= 1024u * 1024u) {
        if (auto img = dermis::decodeImage8(bytes)) {
            if (img->rgba.size() != std::size_t(img->width) * std::size_t(img->height) * 4)
                __builtin_trap();
            if (std::uint32_t(img->width) != declared->width ||
                std::uint32_t(img->height) != declared->height)
                __builtin_trap(); // the preflight must see the size the decoder allocates
        }
    }
    return 0;
}
