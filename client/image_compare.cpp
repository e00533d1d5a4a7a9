// PNG through libpng's png_image API, JPEG through the TurboJPEG API, and the comparison.
#include "image_compare.hpp"

#include <png.h>
#include <turbojpeg.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>

namespace dermis::cli {

namespace {

bool decodePng(const std::string& bytes, Rgba8& out, std::string& error) {
    png_image image;
    std::memset(&image, 0, sizeof image);
    image.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_memory(&image, bytes.data(), bytes.size())) {
        error = std::string("PNG: ") + image.message;
        return false;
    }
    image.format = PNG_FORMAT_RGBA;
    out.width = static_cast<int>(image.width);
    out.height = static_cast<int>(image.height);
    out.pixels.assign(PNG_IMAGE_SIZE(image), 0);
    if (!png_image_finish_read(&image, nullptr, out.pixels.data(), 0, nullptr)) {
        error = std::string("PNG: ") + image.message;
        png_image_free(&image);
        return false;
    }
    return true;
}

bool decodeJpeg(const std::string& bytes, Rgba8& out, std::string& error) {
    tjhandle tj = tjInitDecompress();
    if (!tj) {
        error = "JPEG: cannot start libjpeg-turbo";
        return false;
    }
    int w = 0, h = 0, subsamp = 0, colorspace = 0;
    auto* src = reinterpret_cast<const unsigned char*>(bytes.data());
    const auto size = static_cast<unsigned long>(bytes.size());
    bool ok = tjDecompressHeader3(tj, src, size, &w, &h, &subsamp, &colorspace) == 0;
    if (ok) {
        out.width = w;
        out.height = h;
        out.pixels.assign(static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 4, 0);
        ok = tjDecompress2(tj, src, size, out.pixels.data(), w, 0, h, TJPF_RGBA, TJFLAG_ACCURATEDCT) == 0;
    }
    if (!ok) error = std::string("JPEG: ") + tjGetErrorStr2(tj);
    tjDestroy(tj);
    return ok;
}

} // namespace

bool decodeImage(const std::string& bytes, Rgba8& out, std::string& error) {
    if (bytes.size() >= 8 && std::memcmp(bytes.data(), "\x89PNG", 4) == 0) return decodePng(bytes, out, error);
    if (bytes.size() >= 3 && static_cast<unsigned char>(bytes[0]) == 0xFF && static_cast<unsigned char>(bytes[1]) == 0xD8)
        return decodeJpeg(bytes, out, error);
    error = "neither PNG nor JPEG";
    return false;
}

bool encodePng(const Rgba8& in, std::string& out, std::string& error) {
    png_image image;
    std::memset(&image, 0, sizeof image);
    image.version = PNG_IMAGE_VERSION;
    image.width = static_cast<png_uint_32>(in.width);
    image.height = static_cast<png_uint_32>(in.height);
    image.format = PNG_FORMAT_RGBA;
    png_alloc_size_t size = 0;
    if (!png_image_write_to_memory(&image, nullptr, &size, 0, in.pixels.data(), 0, nullptr)) {
        error = std::string("PNG: ") + image.message;
        return false;
    }
    out.assign(size, '\0');
    if (!png_image_write_to_memory(&image, out.data(), &size, 0, in.pixels.data(), 0, nullptr)) {
        error = std::string("PNG: ") + image.message;
        return false;
    }
    out.resize(size);
    return true;
}

Comparison compareImages(const Rgba8& actual, const Rgba8& reference, double threshold, double fraction) {
    Comparison c;
    c.sizeMatches = actual.width == reference.width && actual.height == reference.height &&
                    actual.pixels.size() == reference.pixels.size();
    if (!c.sizeMatches) return c;
    const std::size_t n = static_cast<std::size_t>(actual.width) * static_cast<std::size_t>(actual.height);
    c.diff.width = actual.width;
    c.diff.height = actual.height;
    c.diff.pixels.assign(n * 4, 0);
    int maxDiff = 0;
    const int limit = static_cast<int>(threshold * 255.0);
    for (std::size_t i = 0; i < n; ++i) {
        int d = 0;
        for (std::size_t ch = 0; ch < 4; ++ch)
            d = std::max(d, std::abs(int(actual.pixels[i * 4 + ch]) - int(reference.pixels[i * 4 + ch])));
        maxDiff = std::max(maxDiff, d);
        if (d > limit) ++c.differing;
        // Heat map: red rises first, then green, then blue (black → red → yellow → white).
        const int v = std::min(765, d * 3 * 4); // ×4: small differences stay visible
        std::uint8_t* px = &c.diff.pixels[i * 4];
        px[0] = static_cast<std::uint8_t>(std::min(v, 255));
        px[1] = static_cast<std::uint8_t>(std::clamp(v - 255, 0, 255));
        px[2] = static_cast<std::uint8_t>(std::clamp(v - 510, 0, 255));
        px[3] = 255;
    }
    c.maxDifference = maxDiff / 255.0;
    c.fraction = n ? static_cast<double>(c.differing) / static_cast<double>(n) : 0.0;
    c.pass = c.fraction <= fraction;
    return c;
}

} // namespace dermis::cli
