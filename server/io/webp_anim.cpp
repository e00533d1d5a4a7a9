#include "io/webp_anim.hpp"

#include "io/webp_encode.hpp"

#include <webp/demux.h>
#include <webp/encode.h>
#include <webp/mux.h>

#include <cstring>
#include <memory>
#include <string>

namespace dermis {

namespace {

constexpr const char* kWhere = "dermis::encodeAnimatedWebp";

struct EncoderDeleter {
    void operator()(WebPAnimEncoder* e) const { WebPAnimEncoderDelete(e); }
};
struct DecoderDeleter {
    void operator()(WebPAnimDecoder* d) const { WebPAnimDecoderDelete(d); }
};

} // namespace

Result<std::vector<std::uint8_t>> encodeAnimatedWebp(const std::vector<Image8>& frames, int delayMs,
                                                     float quality) {
    if (frames.empty()) return makeError(ErrorCode::InvalidArgument, kWhere, "frames", "no frames");
    const int W = frames[0].width, H = frames[0].height;
    for (const Image8& f : frames)
        if (f.width != W || f.height != H || W < 1 || H < 1 || W > kMaxWebpSide || H > kMaxWebpSide ||
            f.rgba.size() != static_cast<std::size_t>(W) * H * 4)
            return makeError(ErrorCode::InvalidArgument, kWhere, "frames",
                             "frames must share one size within 1.." + std::to_string(kMaxWebpSide) +
                                 " with width·height·4 bytes each");
    if (!(quality >= 0.0f && quality <= 100.0f))
        return makeError(ErrorCode::InvalidArgument, kWhere, "quality", "must be in [0, 100]");
    if (delayMs < 1 || delayMs > 65535)
        return makeError(ErrorCode::InvalidArgument, kWhere, "delay", "must be in [1, 65535] ms");
    WebPAnimEncoderOptions options;
    if (!WebPAnimEncoderOptionsInit(&options))
        return makeError(ErrorCode::Io, kWhere, "", "libwebp version mismatch");
    options.anim_params.loop_count = 0;
    options.allow_mixed = 0;
    std::unique_ptr<WebPAnimEncoder, EncoderDeleter> enc(WebPAnimEncoderNew(W, H, &options));
    if (!enc) return makeError(ErrorCode::Io, kWhere, "", "WebPAnimEncoderNew failed");
    WebPConfig config;
    if (!WebPConfigInit(&config)) return makeError(ErrorCode::Io, kWhere, "", "libwebp version mismatch");
    config.quality = quality;
    config.method = 2; // fast; turntables are previews
    config.lossless = 0;
    int timestamp = 0;
    std::vector<std::uint8_t> opaque;
    for (const Image8& f : frames) {
        WebPPicture pic;
        if (!WebPPictureInit(&pic)) return makeError(ErrorCode::Io, kWhere, "", "libwebp version mismatch");
        pic.use_argb = 1;
        pic.width = W;
        pic.height = H;
        opaque = f.rgba;
        for (std::size_t k = 3; k < opaque.size(); k += 4)
            opaque[k] = 255;
        const bool imported = WebPPictureImportRGBA(&pic, opaque.data(), W * 4) != 0;
        const bool added = imported && WebPAnimEncoderAdd(enc.get(), &pic, timestamp, &config) != 0;
        const std::string why = imported ? WebPAnimEncoderGetError(enc.get()) : "out of memory";
        WebPPictureFree(&pic);
        if (!added) return makeError(ErrorCode::Io, kWhere, "frames", "libwebp: " + why);
        timestamp += delayMs;
    }
    if (!WebPAnimEncoderAdd(enc.get(), nullptr, timestamp, nullptr))
        return makeError(ErrorCode::Io, kWhere, "", std::string("libwebp: ") + WebPAnimEncoderGetError(enc.get()));
    WebPData data;
    WebPDataInit(&data);
    if (!WebPAnimEncoderAssemble(enc.get(), &data))
        return makeError(ErrorCode::Io, kWhere, "", std::string("libwebp: ") + WebPAnimEncoderGetError(enc.get()));
    std::vector<std::uint8_t> out(data.bytes, data.bytes + data.size);
    WebPDataClear(&data);
    return out;
}

Result<DecodedAnimation> decodeAnimatedWebp(const std::vector<std::uint8_t>& bytes) {
    const char* where = "dermis::decodeAnimatedWebp";
    WebPAnimDecoderOptions options;
    if (!WebPAnimDecoderOptionsInit(&options)) return makeError(ErrorCode::Io, where, "", "libwebp version mismatch");
    options.color_mode = MODE_RGBA;
    options.use_threads = 0;
    WebPData data{bytes.data(), bytes.size()};
    std::unique_ptr<WebPAnimDecoder, DecoderDeleter> dec(WebPAnimDecoderNew(&data, &options));
    if (!dec) return makeError(ErrorCode::Parse, where, "", "not an animated WebP (or corrupt)");
    WebPAnimInfo info;
    if (!WebPAnimDecoderGetInfo(dec.get(), &info)) return makeError(ErrorCode::Parse, where, "", "no animation info");
    DecodedAnimation out;
    out.loopCount = static_cast<int>(info.loop_count);
    while (WebPAnimDecoderHasMoreFrames(dec.get())) {
        std::uint8_t* buf = nullptr;
        int ts = 0;
        if (!WebPAnimDecoderGetNext(dec.get(), &buf, &ts)) return makeError(ErrorCode::Parse, where, "", "corrupt frame");
        Image8 img;
        img.width = static_cast<int>(info.canvas_width);
        img.height = static_cast<int>(info.canvas_height);
        img.rgba.assign(buf, buf + static_cast<std::size_t>(img.width) * img.height * 4);
        out.frames.push_back(std::move(img));
        out.timestamps.push_back(ts);
    }
    return out;
}

} // namespace dermis
