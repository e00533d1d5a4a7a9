// Lossless WebP encode/decode with libwebp's advanced API. See webp_encode.hpp.
#include "io/webp_encode.hpp"

#include "io/frame_io.hpp"

#include <webp/decode.h>
#include <webp/encode.h>

#include <cstring>
#include <string>

namespace dermis {

namespace {

/// A memory writer's buffer for WebPPicture::custom_ptr.
int appendBytes(const std::uint8_t* data, std::size_t size, const WebPPicture* picture) {
    auto* out = static_cast<std::vector<std::uint8_t>*>(picture->custom_ptr);
    out->insert(out->end(), data, data + size);
    return 1;
}

} // namespace

bool looksLikeWebp(const std::vector<std::uint8_t>& bytes) {
    return bytes.size() >= 12 && std::memcmp(bytes.data(), "RIFF", 4) == 0 &&
           std::memcmp(bytes.data() + 8, "WEBP", 4) == 0;
}

Result<std::vector<std::uint8_t>> encodeWebpLossless(const Image8& img, bool keepAlpha) {
    const char* where = "dermis::encodeWebpLossless";
    if (img.width <= 0 || img.height <= 0 || img.width > kMaxFrameSide ||
        img.height > kMaxFrameSide || img.width > kMaxWebpSide || img.height > kMaxWebpSide)
        return makeError(ErrorCode::InvalidArgument, where, "image",
                         "each side must be in [1, " + std::to_string(kMaxWebpSide) + "], got " +
                             std::to_string(img.width) + "x" + std::to_string(img.height));
    if (img.rgba.size() != static_cast<std::size_t>(img.width) * img.height * 4)
        return makeError(ErrorCode::InvalidArgument, where, "image.rgba",
                         "must hold width*height*4 bytes");
    WebPConfig config;
    if (!WebPConfigInit(&config) || !WebPConfigLosslessPreset(&config, 0))
        return makeError(ErrorCode::Io, where, "", "libwebp: cannot set up the encoder");
    config.exact = 1;        // keep RGB under transparent pixels: decoding gives every byte back
    config.thread_level = 1; // libwebp's own helper thread where it has one
    WebPPicture pic;
    if (!WebPPictureInit(&pic))
        return makeError(ErrorCode::Io, where, "", "libwebp: version mismatch");
    pic.use_argb = 1;
    pic.width = img.width;
    pic.height = img.height;
    const int stride = img.width * 4;
    const int imported = keepAlpha ? WebPPictureImportRGBA(&pic, img.rgba.data(), stride)
                                   : WebPPictureImportRGBX(&pic, img.rgba.data(), stride);
    if (!imported) {
        WebPPictureFree(&pic);
        return makeError(ErrorCode::Io, where, "", "libwebp: out of memory importing the frame");
    }
    std::vector<std::uint8_t> out;
    out.reserve(static_cast<std::size_t>(img.width) * img.height); // a typical frame's size
    pic.writer = appendBytes;
    pic.custom_ptr = &out;
    const bool ok = WebPEncode(&config, &pic) != 0;
    const int code = pic.error_code;
    WebPPictureFree(&pic);
    if (!ok)
        return makeError(ErrorCode::Io, where, "",
                         "libwebp: encoding failed (WebPEncodingError " + std::to_string(code) + ")");
    return out;
}

Result<Image8> decodeWebp(const std::vector<std::uint8_t>& bytes) {
    const char* where = "dermis::decodeWebp";
    int w = 0, h = 0;
    if (!looksLikeWebp(bytes) || !WebPGetInfo(bytes.data(), bytes.size(), &w, &h))
        return makeError(ErrorCode::Parse, where, "", "not a WebP image");
    if (w <= 0 || h <= 0 || w > kMaxFrameSide || h > kMaxFrameSide)
        return makeError(ErrorCode::Parse, where, "",
                         "image is " + std::to_string(w) + "x" + std::to_string(h) +
                             ", not within 1.." + std::to_string(kMaxFrameSide) + " per side");
    Image8 out;
    out.width = w;
    out.height = h;
    out.rgba.resize(static_cast<std::size_t>(w) * h * 4);
    if (!WebPDecodeRGBAInto(bytes.data(), bytes.size(), out.rgba.data(), out.rgba.size(), w * 4))
        return makeError(ErrorCode::Parse, where, "", "libwebp: corrupt or truncated WebP data");
    return out;
}

} // namespace dermis
