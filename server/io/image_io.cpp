// Pattern images and float height maps: PNG and JPEG directly (image_decode.hpp, libpng for the
// 16-bit PNG writer), everything else through the OpenImageIO module loaded on first use
// (oiio_loader.hpp). See image_io.hpp for the value mapping and failure modes.
#include "image_io.hpp"

#include "io/atomic_file.hpp" // writeFileAtomically
#include "io/image_decode.hpp"
#include "io/oiio_loader.hpp"

#include <png.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <csetjmp>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace dermis {
namespace {

Error moduleError(const char* where, const oiio::OiioFailure& f) {
    return makeError(f.code, where, f.field, f.what);
}

/// Channel 0 of directly decoded pixels with SPEC §2's value mapping.
HeightImage heightOf(const DecodedPixels& px) {
    HeightImage img(px.width, px.height);
    auto clamp1 = [](double v) { return static_cast<float>(std::clamp(v, -1.0, 1.0)); };
    const std::size_t nc = static_cast<std::size_t>(px.channels);
    for (std::size_t k = 0; k < img.data.size(); ++k)
        img.data[k] = px.bits == 16 ? clamp1((px.u16[k * nc] - 32768.0) / 32767.0)
                                    : clamp1((px.u8[k * nc] - 128.0) / 127.0);
    return img;
}

Result<std::vector<std::uint8_t>> readFileBytes(const char* where, const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return makeError(ErrorCode::Io, where, path, "cannot open the file");
    std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)),
                                    std::istreambuf_iterator<char>());
    if (in.bad()) return makeError(ErrorCode::Io, where, path, "cannot read the file");
    return bytes;
}

/// The first bytes of a file, to pick the direct decoder or the module without reading it all.
bool looksLikePngOrJpeg(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    unsigned char m[8] = {};
    in.read(reinterpret_cast<char*>(m), 8);
    if (in.gcount() >= 8 && png_sig_cmp(m, 0, 8) == 0) return true;
    return in.gcount() >= 3 && m[0] == 0xFF && m[1] == 0xD8 && m[2] == 0xFF;
}

/// A pattern read by the OpenImageIO module (loaded on first use) from a file or from bytes.
Result<HeightImage> readHeightThroughModule(const char* where, const std::string* path,
                                            const std::vector<std::uint8_t>* bytes, int maxSide = kMaxPatternSize) {
    auto api = oiio::oiioApi();
    if (!api) return api.error();
    HeightImage img;
    oiio::OiioFailure f;
    if (!(*api)->readHeight(path, bytes, maxSide, img, f)) return moduleError(where, f);
    return img;
}

} // namespace

Result<HeightImage> readHeightImage(const std::string& path) {
    const char* where = "dermis::readHeightImage";
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec))
        return makeError(ErrorCode::NotFound, where, path, "no such file");
    if (looksLikePngOrJpeg(path)) {
        auto bytes = readFileBytes(where, path);
        if (!bytes) return bytes.error();
        auto direct = decodeDirect(bytes->data(), bytes->size(), kMaxPatternSize, where, path);
        // Alpha read from a file goes to OpenImageIO, which associates it there (as before the
        // direct decoders); from memory it stays unassociated.
        if (direct && (!*direct || !(*direct)->alpha)) {
            if (!*direct) return direct->error();
            return heightOf(**direct);
        }
    }
    return readHeightThroughModule(where, &path, nullptr);
}

Result<HeightImage> readHeightImageFromMemory(const std::vector<std::uint8_t>& bytes, int maxSide) {
    const char* where = "dermis::readHeightImageFromMemory";
    maxSide = std::clamp(maxSide, 1, kMaxPatternSize);
    if (bytes.empty()) return makeError(ErrorCode::Parse, where, "", "empty image data");
    if (auto direct = decodeDirect(bytes.data(), bytes.size(), maxSide, where, "")) {
        if (!*direct) return direct->error();
        return heightOf(**direct);
    }
    return readHeightThroughModule(where, nullptr, &bytes, maxSide);
}

Result<Image8> decodeImage8(const std::vector<std::uint8_t>& bytes) {
    const char* where = "dermis::decodeImage8";
    constexpr int kMaxSide = 16384;
    if (bytes.empty()) return makeError(ErrorCode::Parse, where, "", "empty image data");
    if (auto direct = decodeDirect(bytes.data(), bytes.size(), kMaxSide, where, "")) {
        if (!*direct) return direct->error();
        const DecodedPixels& px = **direct;
        Image8 out;
        out.width = px.width;
        out.height = px.height;
        out.rgba.resize(static_cast<std::size_t>(px.width) * px.height * 4);
        const std::size_t nc = static_cast<std::size_t>(px.channels);
        // 16 → 8 bits as OpenImageIO converts: round(v · 255 / 65535).
        auto at = [&](std::size_t i) -> std::uint8_t {
            return px.bits == 16 ? static_cast<std::uint8_t>((px.u16[i] * 255u + 32767u) / 65535u)
                                 : px.u8[i];
        };
        for (std::size_t k = 0, n = out.rgba.size() / 4; k < n; ++k) {
            std::uint8_t* d = &out.rgba[k * 4];
            const std::size_t s = k * nc;
            if (nc >= 3) {
                d[0] = at(s), d[1] = at(s + 1), d[2] = at(s + 2);
                d[3] = nc == 4 ? at(s + 3) : 255;
            } else {
                d[0] = d[1] = d[2] = at(s);
                d[3] = nc == 2 ? at(s + 1) : 255;
            }
        }
        return out;
    }
    auto api = oiio::oiioApi();
    if (!api) return api.error();
    Image8 img;
    oiio::OiioFailure f;
    if (!(*api)->decodeRgba8(bytes, kMaxSide, img, f)) return moduleError(where, f);
    return img;
}

Result<EnvironmentImage> readEnvironmentImage(const std::string& path, int maxSide) {
    const char* where = "dermis::readEnvironmentImage";
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec))
        return makeError(ErrorCode::NotFound, where, path, "no such file");
    auto api = oiio::oiioApi();
    if (!api) return api.error();
    EnvironmentImage env;
    std::vector<float> rgb;
    oiio::OiioFailure f;
    if (!(*api)->readRgbFloat(path, std::min(std::max(maxSide, 2), kMaxEnvironmentSide), env.width, env.height, rgb, f))
        return moduleError(where, f);
    env.texels.resize(rgb.size() / 3);
    for (std::size_t k = 0; k < env.texels.size(); ++k)
        env.texels[k] = glm::vec3(rgb[3 * k], rgb[3 * k + 1], rgb[3 * k + 2]);
    if (auto s = validateEnvironment(env); !s)
        return makeError(ErrorCode::InvalidArgument, where, path, s.error().message);
    return env;
}

namespace {

Status checkHeightImage(const char* where, const HeightImage& image) {
    if (image.width <= 0 || image.height <= 0 ||
        image.data.size() != static_cast<std::size_t>(image.width) * image.height)
        return makeError(ErrorCode::InvalidArgument, where, "image", "empty or inconsistent image");
    return Ok{};
}

/// State of the libpng writer, kept out of the setjmp frame's locals.
struct PngWriteJob {
    std::vector<std::uint8_t> out;
    std::vector<png_bytep> rows;
    std::string error;
};

void pngWrite(png_structp png, png_bytep data, png_size_t n) {
    auto* job = static_cast<PngWriteJob*>(png_get_io_ptr(png));
    job->out.insert(job->out.end(), data, data + n);
}

void pngFlush(png_structp) {}

[[noreturn]] void pngWriteError(png_structp png, png_const_charp message) {
    static_cast<PngWriteJob*>(png_get_error_ptr(png))->error = message ? message : "unknown error";
    png_longjmp(png, 1);
}

void pngWriteWarning(png_structp, png_const_charp) {}

bool writeGrey16(png_structp png, png_infop info, PngWriteJob* job, int w, int h) {
    if (setjmp(png_jmpbuf(png))) return false;
    png_set_write_fn(png, job, pngWrite, pngFlush);
    png_set_IHDR(png, info, static_cast<png_uint_32>(w), static_cast<png_uint_32>(h), 16,
                 PNG_COLOR_TYPE_GRAY, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    // As OpenImageIO's PNG writer wrote these files before (the committed pattern library is
    // reproduced byte for byte): an oFFs chunk of (0, 0) pixels, zlib level 6, libpng's
    // adaptive filtering, zlib's default strategy (libpng's own default for filtered rows is
    // Z_FILTERED).
    png_set_oFFs(png, info, 0, 0, PNG_OFFSET_PIXEL);
    png_set_compression_level(png, 6);
    png_set_compression_strategy(png, Z_DEFAULT_STRATEGY);
    png_write_info(png, info);
    png_set_swap(png); // host-order samples → big-endian
    png_write_image(png, job->rows.data());
    png_write_end(png, nullptr);
    return true;
}

} // namespace

Result<std::vector<std::uint8_t>> encodeFloatExr(const HeightImage& image) {
    const char* where = "dermis::encodeFloatExr";
    if (auto s = checkHeightImage(where, image); !s) return s.error();
    auto api = oiio::oiioApi();
    if (!api) return api.error();
    const char* names[] = {"Y"};
    std::vector<std::uint8_t> out;
    oiio::OiioFailure f;
    if (!(*api)->encodeExr(image.width, image.height, 1, names, image.data.data(), false, out, f))
        return moduleError(where, f);
    return out;
}

Result<std::vector<std::uint8_t>> encodeHeight16Png(const HeightImage& image) {
    const char* where = "dermis::encodeHeight16Png";
    if (auto s = checkHeightImage(where, image); !s) return s.error();
    std::vector<std::uint16_t> px(image.data.size());
    for (std::size_t k = 0; k < px.size(); ++k) {
        double v = std::clamp(static_cast<double>(image.data[k]), -1.0, 1.0);
        if (!std::isfinite(v)) v = 0.0;
        px[k] = static_cast<std::uint16_t>(std::lround(32768.0 + 32767.0 * v));
    }
    PngWriteJob job;
    job.rows.resize(static_cast<std::size_t>(image.height));
    for (std::size_t y = 0; y < job.rows.size(); ++y)
        job.rows[y] = reinterpret_cast<png_bytep>(px.data() + y * static_cast<std::size_t>(image.width));
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &job, pngWriteError,
                                              pngWriteWarning);
    png_infop info = png ? png_create_info_struct(png) : nullptr;
    if (!info) {
        png_destroy_write_struct(&png, nullptr);
        return makeError(ErrorCode::Io, where, "", "libpng: cannot create an encoder");
    }
    const bool ok = writeGrey16(png, info, &job, image.width, image.height);
    png_destroy_write_struct(&png, &info);
    if (!ok) return makeError(ErrorCode::Io, where, "", "cannot encode: libpng: " + job.error);
    return std::move(job.out);
}

Result<std::vector<std::uint8_t>> encodeF32(const HeightImage& image) {
    if (auto s = checkHeightImage("dermis::encodeF32", image); !s) return s.error();
    std::vector<std::uint8_t> out(image.data.size() * sizeof(float));
    for (std::size_t k = 0; k < image.data.size(); ++k) {
        std::uint32_t bits = 0;
        std::memcpy(&bits, &image.data[k], sizeof bits);
        for (int b = 0; b < 4; ++b) // little-endian whatever the host's order
            out[k * 4 + static_cast<std::size_t>(b)] = static_cast<std::uint8_t>(bits >> (8 * b));
    }
    return out;
}

Status writeFloatImage(const std::string& path, const HeightImage& image) {
    auto bytes = encodeFloatExr(image);
    if (!bytes) return bytes.error();
    return writeFileAtomically(path, *bytes, Durability::Atomic, "dermis::writeFloatImage");
}

Status writeHeight16Png(const std::string& path, const HeightImage& image) {
    auto bytes = encodeHeight16Png(image);
    if (!bytes) return bytes.error();
    return writeFileAtomically(path, *bytes, Durability::Atomic, "dermis::writeHeight16Png");
}

} // namespace dermis
