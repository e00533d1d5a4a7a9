// Frame encoders (ISA-L's igzip for PNG, libjpeg-turbo, the OpenImageIO module for EXR) and file
// writing. See frame_io.hpp for the formats and failure modes.
//
// PNG settings, measured on 1024² RGBA frames on the 2-core development machine (median of 7):
// the fixed SUB filter and a fast deflate. On a rendered-looking frame (smooth gradients, a
// shaded body, ±4 noise, opaque) zlib level 1 with its Z_RLE strategy took 45 ms for 1.87 MB,
// against 60 ms / 2.21 MB at level 1 with the default strategy (UP within 2% of SUB there), 93 ms
// with libpng's adaptive filtering, and 589 ms / 1.95 MB for OpenImageIO's default PNG write
// (level 6, all filters); SUB was as fast as or faster than UP over every frame tried. Since
// 2026-12-03 the deflate is ISA-L's igzip at level 1: on a range frame of the default scene
// (1024², RGB, 3.1 MB of filtered rows) 0.8 ms for 152 KB against zlib's Z_RLE level 1 at
// 6.9–12 ms for 146 KB (libdeflate level 1–2, tried before, was 12–15 ms): the 60-frame range
// used ≈ 1 s less CPU (docs/benchmarks.md).
#include "frame_io.hpp"

#include "io/atomic_file.hpp"
#include "io/oiio_loader.hpp"
#include "io/webp_encode.hpp"

#include <isa-l/igzip_lib.h>
#include <png.h>
#include <turbojpeg.h>
#include <zlib.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <memory>

namespace dermis {
namespace {

std::string dims(int w, int h) {
    return std::to_string(w) + "x" + std::to_string(h);
}

/// Checks a frame's size and buffer.
Status checkFrame(const char* where, const Image8& img) {
    if (img.width <= 0 || img.height <= 0)
        return makeError(ErrorCode::InvalidArgument, where, "image",
                         "empty image (" + dims(img.width, img.height) + ")");
    if (img.width > kMaxFrameSide || img.height > kMaxFrameSide)
        return makeError(ErrorCode::InvalidArgument, where, "image",
                         "image is " + dims(img.width, img.height) + ", larger than the limit of " +
                             std::to_string(kMaxFrameSide) + " per side");
    const std::size_t expected = static_cast<std::size_t>(img.width) * img.height * 4;
    if (img.rgba.size() != expected)
        return makeError(ErrorCode::InvalidArgument, where, "image.rgba",
                         "has " + std::to_string(img.rgba.size()) +
                             " bytes, expected width*height*4 = " + std::to_string(expected));
    return Ok{};
}

// --- PNG -------------------------------------------------------------------------------------

constexpr int kPngDeflateLevel = 1;       // ISA-L's igzip level 1
constexpr std::uint8_t kPngFilterSub = 1; // PNG filter type 1: each byte minus the one bpp before

void putU32(std::vector<std::uint8_t>& out, std::uint32_t v) {
    for (int shift = 24; shift >= 0; shift -= 8)
        out.push_back(static_cast<std::uint8_t>(v >> shift));
}

void setU32(std::uint8_t* at, std::uint32_t v) {
    for (int k = 0; k < 4; ++k)
        at[k] = static_cast<std::uint8_t>(v >> (24 - 8 * k));
}

/// Appends a PNG chunk: length, type, data, CRC-32 of type and data (zlib's crc32).
void putChunk(std::vector<std::uint8_t>& out, const char type[4], const std::uint8_t* data,
              std::size_t size) {
    putU32(out, static_cast<std::uint32_t>(size));
    const std::size_t typeAt = out.size();
    out.insert(out.end(), type, type + 4);
    if (size) out.insert(out.end(), data, data + size);
    const uLong crc = crc32(0L, out.data() + typeAt, static_cast<uInt>(4 + size));
    putU32(out, static_cast<std::uint32_t>(crc));
}

/// One scanline with PNG filter type 1 (SUB): the filter byte, then each byte minus the one a
/// pixel before (0 before the first pixel), from RGBA8 `src` keeping `channels` (4, or 3: alpha
/// dropped). The RGBA case is a loop the compiler vectorises.
void subFilterRow(const std::uint8_t* __restrict src, std::uint8_t* __restrict line, std::size_t w,
                  int channels) {
    line[0] = kPngFilterSub;
    std::uint8_t* __restrict dst = line + 1;
    if (channels == 4) {
        for (std::size_t i = 0; i < 4; ++i)
            dst[i] = src[i];
        for (std::size_t i = 4; i < 4 * w; ++i)
            dst[i] = static_cast<std::uint8_t>(src[i] - src[i - 4]);
        return;
    }
    // RGB: a pixel's four byte differences at once in a 32-bit word (SWAR: each byte's borrow
    // kept inside it), stored as 4 bytes of which the next pixel overwrites the fourth; the last
    // pixel byte by byte, so that nothing is written past the line. 3–4× the byte loop, which
    // GCC does not vectorise at -O2 (alpha is dropped from every opaque frame: the common case).
    for (std::size_t c = 0; c < 3; ++c)
        dst[c] = src[c];
    constexpr std::uint32_t kHigh = 0x80808080u;
    for (std::size_t x = 1; x + 1 < w; ++x) {
        std::uint32_t a, b;
        std::memcpy(&a, src + 4 * x, 4);
        std::memcpy(&b, src + 4 * (x - 1), 4);
        const std::uint32_t d = ((a | kHigh) - (b & ~kHigh)) ^ ((a ^ ~b) & kHigh);
        std::memcpy(dst + 3 * x, &d, 4);
    }
    if (w > 1)
        for (std::size_t c = 0; c < 3; ++c)
            dst[3 * (w - 1) + c] = static_cast<std::uint8_t>(src[4 * (w - 1) + c] - src[4 * (w - 2) + c]);
}

/// Appends the zlib stream of `img`'s SUB-filtered scanlines to `out` (ISA-L's igzip at
/// kPngDeflateLevel with its zlib wrapper: header, deflate, Adler-32). Rows are filtered and
/// handed over a batch at a time (≈ 64 KB: cache-sized). False when igzip reports an error.
bool deflateScanlines(const Image8& img, int channels, std::vector<std::uint8_t>& out) {
    const std::size_t w = static_cast<std::size_t>(img.width);
    const std::size_t lineBytes = 1 + w * static_cast<std::size_t>(channels);
    const int batchRows = static_cast<int>(std::max<std::size_t>(1, 65536 / lineBytes));
    std::unique_ptr<std::uint8_t[]> batch(new std::uint8_t[lineBytes * static_cast<std::size_t>(batchRows)]);
    // igzip's level-1 hash tables and token buffer (≈ 300 KB), kept per thread.
    thread_local std::unique_ptr<std::uint8_t[]> levelBuf(new std::uint8_t[ISAL_DEF_LVL1_DEFAULT]);
    isal_zstream zs;
    isal_deflate_init(&zs);
    zs.level = kPngDeflateLevel;
    zs.level_buf = levelBuf.get();
    zs.level_buf_size = ISAL_DEF_LVL1_DEFAULT;
    zs.gzip_flag = IGZIP_ZLIB;
    zs.flush = NO_FLUSH;
    // Output grows in steps of an eighth of the filtered size (a rendered frame compresses 15–20×).
    const std::size_t step = std::max<std::size_t>(65536, lineBytes * static_cast<std::size_t>(img.height) / 8);
    // `out` is grown (zero-filled once per step) ahead of igzip; `written` is what it holds.
    std::size_t written = out.size();
    out.resize(std::max(out.capacity(), written + step));
    for (int y = 0; y < img.height; y += batchRows) {
        const int n = std::min(batchRows, img.height - y);
        for (int r = 0; r < n; ++r)
            subFilterRow(img.rgba.data() + static_cast<std::size_t>(y + r) * w * 4,
                         batch.get() + static_cast<std::size_t>(r) * lineBytes, w, channels);
        zs.next_in = batch.get();
        zs.avail_in = static_cast<std::uint32_t>(static_cast<std::size_t>(n) * lineBytes);
        zs.end_of_stream = y + n == img.height ? 1 : 0;
        do { // until igzip has taken the batch and (at the end) written everything
            if (out.size() - written < 4096) out.resize(out.size() + step);
            zs.next_out = out.data() + written;
            zs.avail_out = static_cast<std::uint32_t>(out.size() - written);
            const int rc = isal_deflate(&zs);
            written = out.size() - zs.avail_out;
            if (rc != COMP_OK) {
                out.resize(written);
                return false;
            }
        } while (zs.avail_in > 0 || (zs.end_of_stream && zs.internal_state.state != ZSTATE_END));
    }
    out.resize(written);
    return true;
}

// --- JPEG ------------------------------------------------------------------------------------

struct TjDestroy {
    void operator()(void* h) const { tjDestroy(h); }
};
using TjHandle = std::unique_ptr<void, TjDestroy>;

struct TjFree {
    void operator()(unsigned char* p) const { tjFree(p); }
};

// --- EXR -------------------------------------------------------------------------------------

/// The exact sRGB EOTF of every 8-bit code.
const std::array<float, 256>& srgbToLinearTable() {
    static const std::array<float, 256> table = [] {
        std::array<float, 256> t{};
        for (int c = 0; c < 256; ++c) {
            const double v = c / 255.0;
            t[static_cast<std::size_t>(c)] =
                static_cast<float>(v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4));
        }
        return t;
    }();
    return table;
}

Result<std::vector<std::uint8_t>> encodeExr(const Image8& img) {
    const char* where = "dermis::encodeFrame";
    if (auto s = checkFrame(where, img); !s) return s.error();
    const auto& lut = srgbToLinearTable();
    std::vector<float> px(img.rgba.size());
    for (std::size_t k = 0; k < px.size(); k += 4) {
        px[k + 0] = lut[img.rgba[k + 0]];
        px[k + 1] = lut[img.rgba[k + 1]];
        px[k + 2] = lut[img.rgba[k + 2]];
        px[k + 3] = img.rgba[k + 3] / 255.0f;
    }
    auto api = oiio::oiioApi();
    if (!api) return api.error();
    const char* names[] = {"R", "G", "B", "A"};
    std::vector<std::uint8_t> out;
    oiio::OiioFailure f;
    if (!(*api)->encodeExr(img.width, img.height, 4, names, px.data(), true, out, f))
        return makeError(f.code, where, f.field, f.what);
    return out;
}

} // namespace

std::optional<FrameFormat> frameFormatFromPath(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (ext == ".png") return FrameFormat::Png;
    if (ext == ".jpg" || ext == ".jpeg") return FrameFormat::Jpeg;
    if (ext == ".exr") return FrameFormat::Exr;
    if (ext == ".webp") return FrameFormat::Webp;
    return std::nullopt;
}

Result<std::vector<std::uint8_t>> encodePng(const Image8& img, bool keepAlpha) {
    const char* where = "dermis::encodePng";
    if (auto s = checkFrame(where, img); !s) return s.error();
    std::vector<std::uint8_t> out = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    out.reserve(64 + static_cast<std::size_t>(img.width) * static_cast<std::size_t>(img.height) / 4);
    std::vector<std::uint8_t> ihdr;
    putU32(ihdr, static_cast<std::uint32_t>(img.width));
    putU32(ihdr, static_cast<std::uint32_t>(img.height));
    // bit depth 8; colour type 6 (RGBA) or 2 (RGB); deflate; adaptive filtering; no interlace
    for (std::uint8_t b : {std::uint8_t{8}, std::uint8_t(keepAlpha ? 6 : 2), std::uint8_t{0},
                           std::uint8_t{0}, std::uint8_t{0}})
        ihdr.push_back(b);
    putChunk(out, "IHDR", ihdr.data(), ihdr.size());
    // IDAT, written in place: its length once the stream is complete, then its CRC.
    const std::size_t idatAt = out.size();
    putU32(out, 0);
    out.insert(out.end(), {'I', 'D', 'A', 'T'});
    try {
        if (!deflateScanlines(img, keepAlpha ? 4 : 3, out))
            return makeError(ErrorCode::Io, where, "", "igzip failed to compress the frame");
    } catch (const std::exception& e) {
        return makeError(ErrorCode::Io, where, "", std::string("cannot compress: ") + e.what());
    }
    const std::size_t dataBytes = out.size() - idatAt - 8;
    setU32(out.data() + idatAt, static_cast<std::uint32_t>(dataBytes));
    putU32(out, static_cast<std::uint32_t>(crc32(0L, out.data() + idatAt + 4, static_cast<uInt>(4 + dataBytes))));
    putChunk(out, "IEND", nullptr, 0);
    return out;
}

Result<std::vector<std::uint8_t>> encodeJpeg(const Image8& img, int quality) {
    const char* where = "dermis::encodeJpeg";
    if (auto s = checkFrame(where, img); !s) return s.error();
    if (quality < 1 || quality > 100)
        return makeError(ErrorCode::InvalidArgument, where, "quality",
                         "must be in [1, 100], got " + std::to_string(quality));
    TjHandle tj(tjInitCompress());
    if (!tj)
        return makeError(ErrorCode::Io, where, "",
                         std::string("cannot create a libjpeg-turbo compressor: ") +
                             tjGetErrorStr2(nullptr));
    unsigned char* raw = nullptr;
    unsigned long size = 0;
    const int rc = tjCompress2(tj.get(), img.rgba.data(), img.width, img.width * 4, img.height,
                               TJPF_RGBA, &raw, &size, TJSAMP_420, quality, 0);
    std::unique_ptr<unsigned char, TjFree> buf(raw);
    if (rc != 0)
        return makeError(ErrorCode::Io, where, "",
                         std::string("libjpeg-turbo: ") + tjGetErrorStr2(tj.get()));
    return std::vector<std::uint8_t>(buf.get(), buf.get() + size);
}

namespace {

/// Whether every pixel's alpha is 255.
bool opaque(const Image8& img) {
    std::uint8_t all = 255;
    for (std::size_t k = 3; k < img.rgba.size(); k += 4) all &= img.rgba[k];
    return all == 255;
}

} // namespace

Result<std::vector<std::uint8_t>> encodeFrame(const Image8& img, FrameFormat f) {
    switch (f) {
    case FrameFormat::Png:
        return encodePng(img, !opaque(img));
    case FrameFormat::Jpeg:
        return encodeJpeg(img, 90);
    case FrameFormat::Exr:
        return encodeExr(img);
    case FrameFormat::Webp:
        return encodeWebpLossless(img, true);
    }
    return makeError(ErrorCode::InvalidArgument, "dermis::encodeFrame", "format",
                     "unknown frame format");
}

Status writeFrame(const std::string& path, const Image8& img) {
    const char* where = "dermis::writeFrame";
    const auto format = frameFormatFromPath(path);
    if (!format)
        return makeError(ErrorCode::InvalidArgument, where, path,
                         "unknown frame format: the extension must be .png, .jpg, .jpeg, .exr or .webp");
    if (auto s = checkFrame(where, img); !s) return s.error();
    auto bytes = encodeFrame(img, *format);
    if (!bytes) return bytes.error();
    return writeFileAtomically(path, *bytes, Durability::Atomic, where);
}

Result<Image8> decodeFrame(const std::vector<std::uint8_t>& bytes) {
    const char* where = "dermis::decodeFrame";
    auto tooLarge = [&](unsigned long w, unsigned long h) -> Error {
        return makeError(ErrorCode::Parse, where, "",
                         "image is " + std::to_string(w) + "x" + std::to_string(h) +
                             ", not within 1.." + std::to_string(kMaxFrameSide) + " per side");
    };
    const bool png = bytes.size() >= 8 && png_sig_cmp(bytes.data(), 0, 8) == 0;
    const bool jpeg = bytes.size() >= 3 && bytes[0] == 0xFF && bytes[1] == 0xD8 && bytes[2] == 0xFF;
    if (png) {
        png_image image;
        std::memset(&image, 0, sizeof image);
        image.version = PNG_IMAGE_VERSION;
        if (!png_image_begin_read_from_memory(&image, bytes.data(), bytes.size()))
            return makeError(ErrorCode::Parse, where, "", std::string("libpng: ") + image.message);
        if (image.width < 1 || image.height < 1 || image.width > kMaxFrameSide ||
            image.height > kMaxFrameSide) {
            png_image_free(&image);
            return tooLarge(image.width, image.height);
        }
        image.format = PNG_FORMAT_RGBA;
        Image8 out;
        out.width = static_cast<int>(image.width);
        out.height = static_cast<int>(image.height);
        out.rgba.resize(PNG_IMAGE_SIZE(image));
        if (!png_image_finish_read(&image, nullptr, out.rgba.data(), 0, nullptr))
            return makeError(ErrorCode::Parse, where, "", std::string("libpng: ") + image.message);
        return out;
    }
    if (jpeg) {
        TjHandle tj(tjInitDecompress());
        if (!tj)
            return makeError(ErrorCode::Io, where, "",
                             std::string("cannot create a libjpeg-turbo decompressor: ") +
                                 tjGetErrorStr2(nullptr));
        int w = 0, h = 0, subsamp = 0, colorspace = 0;
        // libjpeg-turbo's API takes non-const buffers but does not write to them.
        auto* src = const_cast<unsigned char*>(bytes.data());
        if (tjDecompressHeader3(tj.get(), src, bytes.size(), &w, &h, &subsamp, &colorspace) != 0)
            return makeError(ErrorCode::Parse, where, "",
                             std::string("libjpeg-turbo: ") + tjGetErrorStr2(tj.get()));
        if (w < 1 || h < 1 || w > kMaxFrameSide || h > kMaxFrameSide)
            return tooLarge(static_cast<unsigned long>(w), static_cast<unsigned long>(h));
        Image8 out;
        out.width = w;
        out.height = h;
        out.rgba.resize(static_cast<std::size_t>(w) * h * 4);
        if (tjDecompress2(tj.get(), src, bytes.size(), out.rgba.data(), w, 0, h, TJPF_RGBA,
                          TJFLAG_STOPONWARNING) != 0)
            return makeError(ErrorCode::Parse, where, "",
                             std::string("libjpeg-turbo: ") + tjGetErrorStr2(tj.get()));
        return out;
    }
    return makeError(ErrorCode::Parse, where, "", "not a PNG or JPEG image");
}

} // namespace dermis
