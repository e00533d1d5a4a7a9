// Direct PNG (libpng) and JPEG (libjpeg-turbo) decoding. See image_decode.hpp.
#include "io/image_decode.hpp"

#include <png.h>
#include <turbojpeg.h>

#include <csetjmp>
#include <cstring>
#include <memory>

namespace dermis {
namespace {

Error tooLarge(const char* where, const std::string& field, unsigned long w, unsigned long h,
               int maxSide) {
    return makeError(ErrorCode::InvalidArgument, where, field,
                     "image is " + std::to_string(w) + "x" + std::to_string(h) +
                         ", larger than the limit of " + std::to_string(maxSide) + " per side");
}

// --- PNG ---------------------------------------------------------------------------------------

/// Everything the libpng callbacks and the setjmp frame touch, kept out of that frame's locals
/// (locals changed between setjmp and longjmp are indeterminate afterwards).
struct PngJob {
    const std::uint8_t* data = nullptr;
    std::size_t size = 0, pos = 0;
    int maxSide = 0;
    std::string error;
    bool tooLarge = false;
    unsigned long width = 0, height = 0;
    DecodedPixels out;
    std::vector<png_bytep> rows;
};

void pngRead(png_structp png, png_bytep dst, png_size_t n) {
    auto* job = static_cast<PngJob*>(png_get_io_ptr(png));
    if (job->size - job->pos < n) png_error(png, "truncated PNG data");
    std::memcpy(dst, job->data + job->pos, n);
    job->pos += n;
}

[[noreturn]] void pngError(png_structp png, png_const_charp message) {
    auto* job = static_cast<PngJob*>(png_get_error_ptr(png));
    job->error = message ? message : "unknown error";
    png_longjmp(png, 1);
}

void pngWarning(png_structp, png_const_charp) {}

/// The libpng part; returns false after a libpng error (job->error says which) or a size over
/// the limit (job->tooLarge). No C++ object with a destructor lives in this frame.
bool pngDecode(png_structp png, png_infop info, PngJob* job) {
    if (setjmp(png_jmpbuf(png))) return false;
    png_set_read_fn(png, job, pngRead);
    png_read_info(png, info);
    job->width = png_get_image_width(png, info);
    job->height = png_get_image_height(png, info);
    if (job->width > static_cast<unsigned long>(job->maxSide) ||
        job->height > static_cast<unsigned long>(job->maxSide)) {
        job->tooLarge = true;
        return false;
    }
    const int colorType = png_get_color_type(png, info);
    const int depth = png_get_bit_depth(png, info);
    // The transformations of OpenImageIO's PNG reader: values as stored, no gamma.
    if (colorType == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
    if (colorType == PNG_COLOR_TYPE_GRAY && depth < 8) png_set_expand_gray_1_2_4_to_8(png);
    if (png_get_valid(png, info, PNG_INFO_tRNS)) png_set_tRNS_to_alpha(png);
    if (depth == 16) png_set_swap(png); // big-endian samples → host order (x86 and ARM: little)
    png_set_interlace_handling(png);
    png_read_update_info(png, info);
    DecodedPixels& o = job->out;
    o.width = static_cast<int>(job->width);
    o.height = static_cast<int>(job->height);
    o.channels = png_get_channels(png, info);
    o.bits = png_get_bit_depth(png, info);
    o.alpha = (png_get_color_type(png, info) & PNG_COLOR_MASK_ALPHA) != 0;
    const std::size_t samples = static_cast<std::size_t>(o.width) * o.height * o.channels;
    const std::size_t rowSamples = static_cast<std::size_t>(o.width) * o.channels;
    job->rows.resize(static_cast<std::size_t>(o.height));
    if (o.bits == 16) {
        o.u16.resize(samples);
        for (std::size_t y = 0; y < job->rows.size(); ++y)
            job->rows[y] = reinterpret_cast<png_bytep>(o.u16.data() + y * rowSamples);
    } else {
        o.u8.resize(samples);
        for (std::size_t y = 0; y < job->rows.size(); ++y)
            job->rows[y] = o.u8.data() + y * rowSamples;
    }
    png_read_image(png, job->rows.data());
    png_read_end(png, nullptr);
    return true;
}

Result<DecodedPixels> decodePng(const std::uint8_t* data, std::size_t size, int maxSide,
                                const char* where, const std::string& field) {
    PngJob job;
    job.data = data;
    job.size = size;
    job.maxSide = maxSide;
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &job, pngError, pngWarning);
    png_infop info = png ? png_create_info_struct(png) : nullptr;
    if (!info) {
        png_destroy_read_struct(&png, nullptr, nullptr);
        return makeError(ErrorCode::Io, where, field, "libpng: cannot create a decoder");
    }
    const bool ok = pngDecode(png, info, &job);
    png_destroy_read_struct(&png, &info, nullptr);
    if (job.tooLarge) return tooLarge(where, field, job.width, job.height, maxSide);
    if (!ok) return makeError(ErrorCode::Parse, where, field, "libpng: " + job.error);
    if (job.out.width <= 0 || job.out.height <= 0)
        return makeError(ErrorCode::Parse, where, field, "image has no pixels");
    return std::move(job.out);
}

// --- JPEG --------------------------------------------------------------------------------------

struct TjDestroy {
    void operator()(void* h) const { tjDestroy(h); }
};

std::optional<Result<DecodedPixels>> decodeJpeg(const std::uint8_t* data, std::size_t size,
                                                int maxSide, const char* where,
                                                const std::string& field) {
    std::unique_ptr<void, TjDestroy> tj(tjInitDecompress());
    if (!tj)
        return Result<DecodedPixels>(makeError(ErrorCode::Io, where, field,
                                               "libjpeg-turbo: cannot create a decoder"));
    int w = 0, h = 0, subsamp = 0, colorspace = 0;
    // libjpeg-turbo's API takes non-const buffers but does not write to them.
    auto* src = const_cast<unsigned char*>(data);
    if (tjDecompressHeader3(tj.get(), src, static_cast<unsigned long>(size), &w, &h, &subsamp,
                            &colorspace) != 0)
        return Result<DecodedPixels>(makeError(ErrorCode::Parse, where, field,
                                               std::string("libjpeg-turbo: ") +
                                                   tjGetErrorStr2(tj.get())));
    if (colorspace != TJCS_GRAY && colorspace != TJCS_RGB && colorspace != TJCS_YCbCr)
        return std::nullopt; // CMYK / YCCK: OpenImageIO's conversion
    if (w < 1 || h < 1)
        return Result<DecodedPixels>(makeError(ErrorCode::Parse, where, field, "image has no pixels"));
    if (w > maxSide || h > maxSide)
        return Result<DecodedPixels>(tooLarge(where, field, static_cast<unsigned long>(w),
                                              static_cast<unsigned long>(h), maxSide));
    DecodedPixels out;
    out.width = w;
    out.height = h;
    out.channels = colorspace == TJCS_GRAY ? 1 : 3;
    out.u8.resize(static_cast<std::size_t>(w) * h * out.channels);
    if (tjDecompress2(tj.get(), src, static_cast<unsigned long>(size), out.u8.data(), w, 0, h,
                      out.channels == 1 ? TJPF_GRAY : TJPF_RGB, 0) != 0) {
        // A warning (damaged but readable data, extra bytes): leave the decision to OpenImageIO,
        // as before the direct decoder.
        if (tjGetErrorCode(tj.get()) == TJERR_WARNING) return std::nullopt;
        return Result<DecodedPixels>(makeError(ErrorCode::Parse, where, field,
                                               std::string("libjpeg-turbo: ") +
                                                   tjGetErrorStr2(tj.get())));
    }
    return Result<DecodedPixels>(std::move(out));
}

} // namespace

std::optional<Result<DecodedPixels>> decodeDirect(const std::uint8_t* data, std::size_t size,
                                                  int maxSide, const char* where,
                                                  const std::string& field) {
    if (size >= 8 && png_sig_cmp(data, 0, 8) == 0)
        return decodePng(data, size, maxSide, where, field);
    if (size >= 3 && data[0] == 0xFF && data[1] == 0xD8 && data[2] == 0xFF)
        return decodeJpeg(data, size, maxSide, where, field);
    return std::nullopt;
}

} // namespace dermis
