// FrameIoTest — frame encoders (PNG, JPEG, EXR), writing frames by extension, decoding, errors.
// Writes temporary files; reads them back with decodeFrame and, independently, OpenImageIO.
#include "TestFiles.hpp"
#include "io/frame_io.hpp"
#include "io/webp_encode.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <random>

using namespace dermis;
using namespace dermis::test;
using OIIO::TypeDesc;

namespace {

/// Every byte random (alpha included): nothing compresses, every value must survive.
Image8 noiseImage(int w, int h, unsigned seed) {
    std::mt19937 rng(seed);
    Image8 img;
    img.width = w;
    img.height = h;
    img.rgba.resize(static_cast<std::size_t>(w) * h * 4);
    for (auto& b : img.rgba)
        b = static_cast<std::uint8_t>(rng() & 0xFF);
    return img;
}

/// Smooth colour gradients with a varying alpha: what JPEG handles well.
Image8 gradientImage(int w, int h) {
    Image8 img;
    img.width = w;
    img.height = h;
    img.rgba.resize(static_cast<std::size_t>(w) * h * 4);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            std::uint8_t* p = &img.rgba[(static_cast<std::size_t>(y) * w + x) * 4];
            p[0] = static_cast<std::uint8_t>(255 * x / (w - 1));
            p[1] = static_cast<std::uint8_t>(255 * y / (h - 1));
            p[2] = static_cast<std::uint8_t>(128 + 100 * std::sin((x + y) * 0.05));
            p[3] = static_cast<std::uint8_t>((x * 7 + y * 3) & 0xFF);
        }
    return img;
}

double srgbEotf(int c) {
    const double v = c / 255.0;
    return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4);
}

std::vector<std::string> folderEntries(const std::string& dir) {
    std::vector<std::string> names;
    for (const auto& e : std::filesystem::directory_iterator(dir))
        names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

/// Reads an image with OpenImageIO keeping alpha unassociated (PNG values exactly as stored).
std::vector<std::uint8_t> readWithOiio(const std::string& path, int& w, int& h, int& nc) {
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    auto in = OIIO::ImageInput::open(path, &config);
    if (!in) return {};
    w = in->spec().width, h = in->spec().height, nc = in->spec().nchannels;
    std::vector<std::uint8_t> px(static_cast<std::size_t>(w) * h * nc);
    if (!in->read_image(0, 0, 0, nc, TypeDesc::UINT8, px.data())) return {};
    return px;
}

void expectError(const Error& e, ErrorCode code, const std::string& where,
                 const std::string& field) {
    EXPECT_EQ(e.code, code) << e.message;
    EXPECT_EQ(e.field, field) << e.message;
    EXPECT_EQ(e.message.rfind(where + ":", 0), 0u) << e.message;
}

} // namespace

TEST(FrameIoTest, FormatFromExtension) {
    EXPECT_EQ(frameFormatFromPath("out/frame.png"), FrameFormat::Png);
    EXPECT_EQ(frameFormatFromPath("A.PNG"), FrameFormat::Png);
    EXPECT_EQ(frameFormatFromPath("x.jpg"), FrameFormat::Jpeg);
    EXPECT_EQ(frameFormatFromPath("x.JpEg"), FrameFormat::Jpeg);
    EXPECT_EQ(frameFormatFromPath("/a.b/c.exr"), FrameFormat::Exr);
    EXPECT_EQ(frameFormatFromPath("c.EXR"), FrameFormat::Exr);
    EXPECT_EQ(frameFormatFromPath("f.webp"), FrameFormat::Webp);
    EXPECT_EQ(frameFormatFromPath("F.WebP"), FrameFormat::Webp);
    EXPECT_FALSE(frameFormatFromPath("x.tif"));
    EXPECT_FALSE(frameFormatFromPath("png"));
    EXPECT_FALSE(frameFormatFromPath("x.png.bak"));
    EXPECT_FALSE(frameFormatFromPath("dir.png/frame"));
    EXPECT_FALSE(frameFormatFromPath(".png")); // a hidden file without extension
    EXPECT_FALSE(frameFormatFromPath(""));
}

TEST(FrameIoTest, PngRoundTripIsExactIncludingAlpha) {
    const Image8 img = noiseImage(37, 23, 1);
    auto png = encodePng(img);
    ASSERT_TRUE(png.ok()) << png.error().message;
    ASSERT_GT(png->size(), 8u);
    EXPECT_EQ((*png)[0], 0x89);
    EXPECT_EQ((*png)[1], 'P');
    auto back = decodeFrame(*png);
    ASSERT_TRUE(back.ok()) << back.error().message;
    EXPECT_EQ(back->width, 37);
    EXPECT_EQ(back->height, 23);
    EXPECT_EQ(back->rgba, img.rgba);

    // An independent decoder agrees (OpenImageIO, alpha left unassociated).
    TempDir dir;
    writeBytes(dir / "n.png", *png);
    int w = 0, h = 0, nc = 0;
    EXPECT_EQ(readWithOiio(dir / "n.png", w, h, nc), img.rgba);
    EXPECT_EQ(nc, 4);
}

TEST(FrameIoTest, PngOfATallNoisyFrameIsOneValidStream) {
    // Rows go to igzip in many batches, and noise does not compress: the output buffer grows
    // several times over while the stream is written. libpng and OpenImageIO both read it back
    // exactly, with and without alpha.
    const Image8 img = noiseImage(301, 517, 7);
    for (bool alpha : {true, false}) {
        auto png = encodePng(img, alpha);
        ASSERT_TRUE(png.ok()) << png.error().message;
        auto back = decodeFrame(*png);
        ASSERT_TRUE(back.ok()) << back.error().message;
        std::vector<std::uint8_t> want = img.rgba;
        if (!alpha)
            for (std::size_t p = 3; p < want.size(); p += 4) want[p] = 255;
        EXPECT_EQ(back->rgba, want) << "alpha " << alpha;
        TempDir dir;
        writeBytes(dir / "t.png", *png);
        int w = 0, h = 0, nc = 0;
        auto oiio = readWithOiio(dir / "t.png", w, h, nc);
        EXPECT_EQ(w, 301);
        EXPECT_EQ(h, 517);
        EXPECT_EQ(nc, alpha ? 4 : 3);
        EXPECT_EQ(oiio.size(), 301u * 517u * static_cast<std::size_t>(nc));
        if (alpha) EXPECT_EQ(oiio, img.rgba);
    }
}

TEST(FrameIoTest, PngWithoutAlpha) {
    const Image8 img = noiseImage(16, 9, 2);
    auto png = encodePng(img, false);
    ASSERT_TRUE(png.ok()) << png.error().message;
    auto back = decodeFrame(*png);
    ASSERT_TRUE(back.ok()) << back.error().message;
    ASSERT_EQ(back->rgba.size(), img.rgba.size());
    for (std::size_t k = 0; k < img.rgba.size(); k += 4) {
        ASSERT_EQ(back->rgba[k + 0], img.rgba[k + 0]) << k;
        ASSERT_EQ(back->rgba[k + 1], img.rgba[k + 1]) << k;
        ASSERT_EQ(back->rgba[k + 2], img.rgba[k + 2]) << k;
        ASSERT_EQ(back->rgba[k + 3], 255) << k;
    }
    TempDir dir;
    writeBytes(dir / "rgb.png", *png);
    int w = 0, h = 0, nc = 0;
    ASSERT_FALSE(readWithOiio(dir / "rgb.png", w, h, nc).empty());
    EXPECT_EQ(nc, 3);
    // Without alpha the (incompressible) file is about 3/4 of the RGBA one.
    auto rgba = encodePng(img, true);
    ASSERT_TRUE(rgba.ok());
    EXPECT_LT(png->size() * 5, rgba->size() * 4);
    // Narrow rows: the RGB filter's word-at-a-time middle is empty or one pixel wide.
    for (int width : {1, 2, 3}) {
        const Image8 narrow = noiseImage(width, 5, 3 + width);
        auto bytes = encodePng(narrow, false);
        ASSERT_TRUE(bytes.ok()) << bytes.error().message;
        auto decoded = decodeFrame(*bytes);
        ASSERT_TRUE(decoded.ok()) << decoded.error().message;
        std::vector<std::uint8_t> want = narrow.rgba;
        for (std::size_t p = 3; p < want.size(); p += 4) want[p] = 255;
        EXPECT_EQ(decoded->rgba, want) << "width " << width;
    }
}

TEST(FrameIoTest, PngCompressesSmoothImages) {
    const Image8 img = gradientImage(256, 128);
    auto png = encodePng(img);
    ASSERT_TRUE(png.ok()) << png.error().message;
    EXPECT_LT(png->size(), img.rgba.size() / 2);
    auto back = decodeFrame(*png);
    ASSERT_TRUE(back.ok());
    EXPECT_EQ(back->rgba, img.rgba);
}

TEST(FrameIoTest, JpegRoundTripWithinTolerance) {
    const Image8 img = gradientImage(64, 48);
    auto jpg = encodeJpeg(img, 90);
    ASSERT_TRUE(jpg.ok()) << jpg.error().message;
    ASSERT_GE(jpg->size(), 3u);
    EXPECT_EQ((*jpg)[0], 0xFF);
    EXPECT_EQ((*jpg)[1], 0xD8);
    auto back = decodeFrame(*jpg);
    ASSERT_TRUE(back.ok()) << back.error().message;
    ASSERT_EQ(back->width, 64);
    ASSERT_EQ(back->height, 48);
    int maxErr = 0;
    double sumErr = 0;
    for (std::size_t k = 0; k < img.rgba.size(); k += 4) {
        for (int c = 0; c < 3; ++c) {
            const int e = std::abs(int(back->rgba[k + c]) - int(img.rgba[k + c]));
            maxErr = std::max(maxErr, e);
            sumErr += e;
        }
        ASSERT_EQ(back->rgba[k + 3], 255) << "alpha is dropped";
    }
    EXPECT_LE(maxErr, 12);
    EXPECT_LT(sumErr / (64 * 48 * 3), 2.0);

    // 4:2:0 chroma subsampling, as OpenImageIO reports it.
    TempDir dir;
    writeBytes(dir / "f.jpg", *jpg);
    auto in = OIIO::ImageInput::open(dir / "f.jpg");
    ASSERT_TRUE(in);
    EXPECT_EQ(in->spec().get_string_attribute("jpeg:subsampling"), "4:2:0");
    EXPECT_EQ(in->spec().nchannels, 3);
}

TEST(FrameIoTest, JpegQualityMattersAndIsChecked) {
    const Image8 img = noiseImage(64, 64, 3);
    auto low = encodeJpeg(img, 20), high = encodeJpeg(img, 98);
    ASSERT_TRUE(low.ok() && high.ok());
    EXPECT_LT(low->size() * 2, high->size());
    for (int q : {0, 101, -5}) {
        auto r = encodeJpeg(img, q);
        ASSERT_FALSE(r.ok()) << q;
        expectError(r.error(), ErrorCode::InvalidArgument, "dermis::encodeJpeg", "quality");
    }
    EXPECT_TRUE(encodeJpeg(img, 1).ok());
    EXPECT_TRUE(encodeJpeg(img, 100).ok());
}

TEST(FrameIoTest, EncodeFrameDispatches) {
    const Image8 img = gradientImage(20, 10);
    auto png = encodeFrame(img, FrameFormat::Png);
    auto jpg = encodeFrame(img, FrameFormat::Jpeg);
    auto exr = encodeFrame(img, FrameFormat::Exr);
    ASSERT_TRUE(png.ok() && jpg.ok() && exr.ok());
    EXPECT_EQ(*png, *encodePng(img, true)); // alpha varies: RGBA
    // An opaque frame (every rendered one) is written as RGB: smaller, decoded to the same bytes.
    Image8 opaque = img;
    for (std::size_t k = 3; k < opaque.rgba.size(); k += 4) opaque.rgba[k] = 255;
    auto rgb = encodeFrame(opaque, FrameFormat::Png);
    ASSERT_TRUE(rgb.ok());
    EXPECT_EQ(*rgb, *encodePng(opaque, false));
    EXPECT_LT(rgb->size(), encodePng(opaque, true)->size());
    auto back = decodeFrame(*rgb);
    ASSERT_TRUE(back.ok()) << back.error().message;
    EXPECT_EQ(back->rgba, opaque.rgba);
    opaque.rgba[opaque.rgba.size() - 1] = 254; // one pixel not opaque: RGBA again
    EXPECT_EQ(*encodeFrame(opaque, FrameFormat::Png), *encodePng(opaque, true));
    EXPECT_EQ(*jpg, *encodeJpeg(img, 90));
    ASSERT_GE(exr->size(), 4u);
    const std::vector<std::uint8_t> exrMagic = {0x76, 0x2F, 0x31, 0x01};
    EXPECT_TRUE(std::equal(exrMagic.begin(), exrMagic.end(), exr->begin()));
}

TEST(FrameIoTest, WebpLosslessRoundTripIsExactIncludingAlpha) {
    // Random bytes everywhere, alpha 0 included: lossless WebP with `exact` keeps the colour of
    // fully transparent pixels too, so libwebp's decoder gives back every byte.
    for (auto [w, h] : {std::pair{37, 23}, {1, 1}, {300, 7}}) {
        Image8 img = noiseImage(w, h, 5);
        for (std::size_t k = 3; k < img.rgba.size(); k += 40) img.rgba[k] = 0;
        auto webp = encodeWebpLossless(img);
        ASSERT_TRUE(webp.ok()) << webp.error().message;
        EXPECT_TRUE(looksLikeWebp(*webp));
        auto back = decodeWebp(*webp);
        ASSERT_TRUE(back.ok()) << back.error().message;
        EXPECT_EQ(back->width, w);
        EXPECT_EQ(back->height, h);
        EXPECT_EQ(back->rgba, img.rgba) << w << "x" << h;
    }
    // Without alpha: every pixel opaque, RGB exact.
    const Image8 img = gradientImage(64, 48);
    auto opaque = encodeWebpLossless(img, false);
    ASSERT_TRUE(opaque.ok());
    auto back = decodeWebp(*opaque);
    ASSERT_TRUE(back.ok());
    for (std::size_t k = 0; k < img.rgba.size(); k += 4) {
        ASSERT_EQ(back->rgba[k + 0], img.rgba[k + 0]) << k;
        ASSERT_EQ(back->rgba[k + 1], img.rgba[k + 1]) << k;
        ASSERT_EQ(back->rgba[k + 2], img.rgba[k + 2]) << k;
        ASSERT_EQ(back->rgba[k + 3], 255) << k;
    }
    // Smooth frames compress well below raw RGBA.
    EXPECT_LT(opaque->size(), img.rgba.size() / 3);
    // Dispatch and file writing by extension.
    auto viaFrame = encodeFrame(img, FrameFormat::Webp);
    ASSERT_TRUE(viaFrame.ok());
    EXPECT_EQ(*viaFrame, *encodeWebpLossless(img, true));
    TempDir dir;
    ASSERT_TRUE(writeFrame(dir / "f.webp", img).ok());
    auto file = decodeWebp(readBytes(dir / "f.webp"));
    ASSERT_TRUE(file.ok());
    EXPECT_EQ(file->rgba, img.rgba);
}

TEST(FrameIoTest, WebpRejectsBadInput) {
    Image8 empty;
    auto e = encodeWebpLossless(empty);
    ASSERT_FALSE(e.ok());
    expectError(e.error(), ErrorCode::InvalidArgument, "dermis::encodeWebpLossless", "image");
    Image8 wrong = gradientImage(8, 8);
    wrong.rgba.pop_back();
    auto w = encodeWebpLossless(wrong);
    ASSERT_FALSE(w.ok());
    expectError(w.error(), ErrorCode::InvalidArgument, "dermis::encodeWebpLossless", "image.rgba");
    Image8 huge;
    huge.width = kMaxWebpSide + 1;
    huge.height = 1;
    huge.rgba.resize(static_cast<std::size_t>(huge.width) * 4);
    EXPECT_FALSE(encodeWebpLossless(huge).ok());
    auto good = encodeWebpLossless(gradientImage(16, 16));
    ASSERT_TRUE(good.ok());
    for (std::vector<std::uint8_t> bad :
         {std::vector<std::uint8_t>{}, *encodePng(gradientImage(4, 4)),
          std::vector<std::uint8_t>(good->begin(), good->begin() + 20)}) {
        auto d = decodeWebp(bad);
        ASSERT_FALSE(d.ok()) << bad.size();
        EXPECT_EQ(d.error().code, ErrorCode::Parse);
    }
}

TEST(FrameIoTest, WritesPngAndJpegByExtension) {
    TempDir dir;
    const Image8 img = gradientImage(40, 30);
    ASSERT_TRUE(writeFrame(dir / "a.png", img).ok());
    ASSERT_TRUE(writeFrame(dir / "b.JPG", img).ok());
    ASSERT_TRUE(writeFrame(dir / "c.jpeg", img).ok());
    auto a = decodeFrame(readBytes(dir / "a.png"));
    ASSERT_TRUE(a.ok()) << a.error().message;
    EXPECT_EQ(a->rgba, img.rgba);
    for (const char* name : {"b.JPG", "c.jpeg"}) {
        const auto bytes = readBytes(dir / name);
        EXPECT_EQ(bytes, *encodeJpeg(img, 90)) << name;
        auto b = decodeFrame(bytes);
        ASSERT_TRUE(b.ok()) << name;
        EXPECT_EQ(b->width, 40);
        EXPECT_EQ(b->height, 30);
    }
    // No temporary file is left behind.
    EXPECT_EQ(folderEntries(dir.str()), (std::vector<std::string>{"a.png", "b.JPG", "c.jpeg"}));
}

TEST(FrameIoTest, OverwritesAnExistingFrame) {
    TempDir dir;
    writeText(dir / "f.png", "old contents");
    const Image8 img = noiseImage(5, 4, 4);
    ASSERT_TRUE(writeFrame(dir / "f.png", img).ok());
    auto back = decodeFrame(readBytes(dir / "f.png"));
    ASSERT_TRUE(back.ok()) << back.error().message;
    EXPECT_EQ(back->rgba, img.rgba);
    EXPECT_EQ(folderEntries(dir.str()), std::vector<std::string>{"f.png"});
}

TEST(FrameIoTest, ExrIsHalfRgbaInLinearLight) {
    TempDir dir;
    // Codes on both branches of the sRGB EOTF (≤ 10 is on the linear segment) and both ends.
    Image8 img;
    img.width = 4;
    img.height = 2;
    img.rgba = {0,   10,  128, 255, //
                255, 188, 1,   0,   //
                11,  64,  200, 128, //
                5,   250, 100, 7,   //
                30,  60,  90,  120, //
                150, 180, 210, 240, //
                2,   4,   8,   16,  //
                32,  127, 129, 254};
    ASSERT_TRUE(writeFrame(dir / "f.exr", img).ok());
    auto in = OIIO::ImageInput::open(dir / "f.exr");
    ASSERT_TRUE(in) << OIIO::geterror();
    const OIIO::ImageSpec& spec = in->spec();
    ASSERT_EQ(spec.width, 4);
    ASSERT_EQ(spec.height, 2);
    ASSERT_EQ(spec.nchannels, 4);
    EXPECT_EQ(spec.format, TypeDesc::HALF);
    EXPECT_EQ(spec.channelnames, (std::vector<std::string>{"R", "G", "B", "A"}));
    EXPECT_EQ(spec.alpha_channel, 3);
    std::vector<float> px(32);
    ASSERT_TRUE(in->read_image(0, 0, 0, 4, TypeDesc::FLOAT, px.data()));
    for (std::size_t k = 0; k < 32; ++k) {
        const int code = img.rgba[k];
        const double want = k % 4 == 3 ? code / 255.0 : srgbEotf(code);
        // Half floats: 11 significant bits.
        EXPECT_NEAR(px[k], want, want * 1e-3 + 1e-7) << "value " << k << " code " << code;
    }
    // Spot values: 128 → 0.2158605, 10 → 10/255/12.92 (linear segment), 255 → 1.
    EXPECT_NEAR(px[2], 0.2158605, 2e-4);
    EXPECT_NEAR(px[1], 0.0030353, 3e-6);
    EXPECT_EQ(px[3], 1.0f);
    EXPECT_EQ(px[4], 1.0f);
    EXPECT_EQ(px[7], 0.0f);
    // Alpha is linear (128/255), not EOTF-decoded (0.2158…).
    EXPECT_NEAR(px[11], 128 / 255.0, 1e-3);
    EXPECT_EQ(folderEntries(dir.str()), std::vector<std::string>{"f.exr"});
}

TEST(FrameIoTest, WriteFrameRejectsUnknownExtensions) {
    TempDir dir;
    const Image8 img = gradientImage(8, 8);
    for (const char* name : {"f.tif", "f", "f.png.tmp"}) {
        auto s = writeFrame(dir / name, img);
        ASSERT_FALSE(s.ok()) << name;
        expectError(s.error(), ErrorCode::InvalidArgument, "dermis::writeFrame", dir / name);
    }
    EXPECT_TRUE(folderEntries(dir.str()).empty());
}

TEST(FrameIoTest, UnwritablePathsAreIoErrorsNamingThePath) {
    TempDir dir;
    const Image8 img = gradientImage(8, 8);
    for (const char* name : {"missing/f.png", "missing/f.jpg", "missing/f.exr"}) {
        auto s = writeFrame(dir / name, img);
        ASSERT_FALSE(s.ok()) << name;
        expectError(s.error(), ErrorCode::Io, "dermis::writeFrame", dir / name);
    }
    // A folder in the way: rename fails, the folder stays, no temporary file is left.
    std::filesystem::create_directories(dir / "taken.png");
    auto s = writeFrame(dir / "taken.png", img);
    ASSERT_FALSE(s.ok());
    expectError(s.error(), ErrorCode::Io, "dermis::writeFrame", dir / "taken.png");
    EXPECT_TRUE(std::filesystem::is_directory(dir / "taken.png"));
    EXPECT_EQ(folderEntries(dir.str()), std::vector<std::string>{"taken.png"});
}

TEST(FrameIoTest, RejectsEmptyAndInconsistentImages) {
    Image8 empty;
    Image8 zeroHigh;
    zeroHigh.width = 4;
    Image8 shortBuffer = gradientImage(8, 8);
    shortBuffer.rgba.pop_back();
    Image8 huge;
    huge.width = kMaxFrameSide + 1;
    huge.height = 1;
    huge.rgba.resize(static_cast<std::size_t>(huge.width) * 4);
    struct Case {
        const Image8* img;
        const char* field;
    };
    const Case cases[] = {
        {&empty, "image"}, {&zeroHigh, "image"}, {&shortBuffer, "image.rgba"}, {&huge, "image"}};
    TempDir dir;
    for (const Case& c : cases) {
        SCOPED_TRACE(c.field);
        auto png = encodePng(*c.img);
        ASSERT_FALSE(png.ok());
        expectError(png.error(), ErrorCode::InvalidArgument, "dermis::encodePng", c.field);
        auto jpg = encodeJpeg(*c.img);
        ASSERT_FALSE(jpg.ok());
        expectError(jpg.error(), ErrorCode::InvalidArgument, "dermis::encodeJpeg", c.field);
        auto exr = encodeFrame(*c.img, FrameFormat::Exr);
        ASSERT_FALSE(exr.ok());
        expectError(exr.error(), ErrorCode::InvalidArgument, "dermis::encodeFrame", c.field);
        for (const char* name : {"e.png", "e.jpg", "e.exr"}) {
            auto s = writeFrame(dir / name, *c.img);
            ASSERT_FALSE(s.ok());
            expectError(s.error(), ErrorCode::InvalidArgument, "dermis::writeFrame", c.field);
        }
    }
    EXPECT_TRUE(folderEntries(dir.str()).empty());
}

TEST(FrameIoTest, DecodeFrameRejectsBadBytes) {
    const Image8 img = gradientImage(32, 32);
    auto png = *encodePng(img);
    auto jpg = *encodeJpeg(img);
    const std::vector<std::vector<std::uint8_t>> bad = {
        {},
        {1, 2, 3, 4, 5, 6, 7, 8, 9, 10},
        std::vector<std::uint8_t>(png.begin(), png.begin() + static_cast<long>(png.size() / 2)),
        std::vector<std::uint8_t>(jpg.begin(), jpg.begin() + static_cast<long>(jpg.size() / 2)),
        std::vector<std::uint8_t>(png.begin(), png.begin() + 8), // signature only
        *encodeFrame(img, FrameFormat::Exr),                     // not PNG or JPEG
    };
    for (std::size_t k = 0; k < bad.size(); ++k) {
        auto r = decodeFrame(bad[k]);
        ASSERT_FALSE(r.ok()) << "case " << k;
        expectError(r.error(), ErrorCode::Parse, "dermis::decodeFrame", "");
    }
    // A flipped byte inside the PNG's pixel data breaks its CRC.
    png[png.size() / 2] ^= 0x55;
    EXPECT_FALSE(decodeFrame(png).ok());
}
