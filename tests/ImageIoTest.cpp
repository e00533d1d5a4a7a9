// ImageIoTest — pattern images in (SPEC §2 value mapping), float maps out, bad files rejected.
// Writes and reads temporary files through OpenImageIO; decoding from memory writes no file.
#include "io/frame_io.hpp"
#include "io/image_io.hpp"
#include "TestFiles.hpp"

#include <gtest/gtest.h>

#include <algorithm>

#include <sys/resource.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>

using namespace dermis;
using namespace dermis::test;
using OIIO::TypeDesc;

TEST(ImageIoTest, SixteenBitMapping) {
    TempDir dir;
    const std::vector<std::uint16_t> px = {0, 1, 32768, 65535, 49151, 16384};
    writeImage(dir / "p16.png", 3, 2, 1, px, TypeDesc::UINT16);
    auto img = readHeightImage(dir / "p16.png");
    ASSERT_TRUE(img.ok()) << img.error().message;
    ASSERT_EQ(img->width, 3);
    ASSERT_EQ(img->height, 2);
    EXPECT_FLOAT_EQ(img->at(0, 0), -1.0f); // (0 − 32768)/32767 clamped
    EXPECT_FLOAT_EQ(img->at(1, 0), -1.0f); // (1 − 32768)/32767 = −1 exactly
    EXPECT_FLOAT_EQ(img->at(2, 0), 0.0f);
    EXPECT_FLOAT_EQ(img->at(0, 1), 1.0f);
    EXPECT_FLOAT_EQ(img->at(1, 1), static_cast<float>((49151 - 32768) / 32767.0));
    EXPECT_FLOAT_EQ(img->at(2, 1), static_cast<float>((16384 - 32768) / 32767.0));
}

TEST(ImageIoTest, EightBitMappingAndFirstChannel) {
    TempDir dir;
    // RGB: only the first (red) channel counts.
    const std::vector<std::uint8_t> px = {0, 200, 200, 128, 0, 0, 255, 9, 9, 191, 255, 255};
    writeImage(dir / "p8.png", 2, 2, 3, px, TypeDesc::UINT8);
    auto img = readHeightImage(dir / "p8.png");
    ASSERT_TRUE(img.ok()) << img.error().message;
    EXPECT_FLOAT_EQ(img->at(0, 0), -1.0f);
    EXPECT_FLOAT_EQ(img->at(1, 0), 0.0f);
    EXPECT_FLOAT_EQ(img->at(0, 1), 1.0f);
    EXPECT_FLOAT_EQ(img->at(1, 1), static_cast<float>((191 - 128) / 127.0));
}

TEST(ImageIoTest, FloatImagesAsTheyAreClamped) {
    TempDir dir;
    const std::vector<float> px = {-0.5f, 0.25f, 2.0f, -3.0f};
    writeImage(dir / "pf.exr", 2, 2, 1, px, TypeDesc::FLOAT);
    writeImage(dir / "pf.tif", 2, 2, 1, px, TypeDesc::FLOAT);
    for (const char* name : {"pf.exr", "pf.tif"}) {
        auto img = readHeightImage(dir / name);
        ASSERT_TRUE(img.ok()) << img.error().message;
        EXPECT_FLOAT_EQ(img->at(0, 0), -0.5f) << name;
        EXPECT_FLOAT_EQ(img->at(1, 0), 0.25f) << name;
        EXPECT_FLOAT_EQ(img->at(0, 1), 1.0f) << name;
        EXPECT_FLOAT_EQ(img->at(1, 1), -1.0f) << name;
    }
}

TEST(ImageIoTest, TiffSixteenBitAndFromMemory) {
    TempDir dir;
    const std::vector<std::uint16_t> px = {32768, 65535};
    writeImage(dir / "p.tif", 2, 1, 1, px, TypeDesc::UINT16);
    writeImage(dir / "p.png", 2, 1, 1, px, TypeDesc::UINT16);
    for (const char* name : {"p.tif", "p.png"}) {
        auto img = readHeightImageFromMemory(readBytes(dir / name));
        ASSERT_TRUE(img.ok()) << name << ": " << img.error().message;
        EXPECT_FLOAT_EQ(img->at(0, 0), 0.0f);
        EXPECT_FLOAT_EQ(img->at(1, 0), 1.0f);
    }
}

TEST(ImageIoTest, WritesSingleChannelFloatExrRowZeroFirst) {
    TempDir dir;
    HeightImage img(3, 2);
    img.at(0, 0) = 0.125f;
    img.at(2, 1) = -0.75f;
    ASSERT_TRUE(writeFloatImage(dir / "m.exr", img).ok());
    auto in = OIIO::ImageInput::open(dir / "m.exr");
    ASSERT_TRUE(in);
    const OIIO::ImageSpec& spec = in->spec();
    EXPECT_EQ(spec.nchannels, 1);
    EXPECT_EQ(spec.format, TypeDesc::FLOAT);
    std::vector<float> px(6);
    ASSERT_TRUE(in->read_image(0, 0, 0, 1, TypeDesc::FLOAT, px.data()));
    EXPECT_EQ(px[0], 0.125f);
    EXPECT_EQ(px[5], -0.75f);
    // And back through the pattern reader.
    auto back = readHeightImage(dir / "m.exr");
    ASSERT_TRUE(back.ok());
    EXPECT_EQ(back->data, img.data);
}

TEST(ImageIoTest, Height16PngRoundTrip) {
    TempDir dir;
    HeightImage img(2, 1);
    img.at(0, 0) = 0.0f;
    img.at(1, 0) = -0.5f;
    ASSERT_TRUE(writeHeight16Png(dir / "h.png", img).ok());
    auto back = readHeightImage(dir / "h.png");
    ASSERT_TRUE(back.ok());
    EXPECT_FLOAT_EQ(back->at(0, 0), 0.0f);
    EXPECT_NEAR(back->at(1, 0), -0.5f, 1.0 / 32767);
}

/// EXR bytes with the value of the capDate attribute ("capDate\0string\0", a 4-byte length, the
/// text) zeroed: two encodes of one image differ only there when a second passed between them.
static std::vector<std::uint8_t> withoutCapDate(std::vector<std::uint8_t> bytes) {
    static const std::string kHead("capDate\0string\0", 15);
    const auto at = std::search(bytes.begin(), bytes.end(), kHead.begin(), kHead.end());
    if (at == bytes.end()) return bytes;
    const std::size_t lenAt = static_cast<std::size_t>(at - bytes.begin()) + kHead.size();
    if (lenAt + 4 > bytes.size()) return bytes;
    const std::size_t len = bytes[lenAt] | bytes[lenAt + 1] << 8 | bytes[lenAt + 2] << 16 |
                            static_cast<std::size_t>(bytes[lenAt + 3]) << 24;
    for (std::size_t k = lenAt + 4; k < lenAt + 4 + len && k < bytes.size(); ++k) bytes[k] = 0;
    return bytes;
}

TEST(ImageIoTest, InMemoryEncodersMatchTheFilesAndReadBack) {
    TempDir dir;
    HeightImage img(5, 3);
    for (std::size_t k = 0; k < img.data.size(); ++k)
        img.data[k] = -1.0f + 2.0f * static_cast<float>(k) / 14.0f;
    img.at(4, 2) = 3.0f; // clamped by the 16-bit mapping, kept by EXR and f32

    auto exr = encodeFloatExr(img);
    ASSERT_TRUE(exr) << exr.error().message;
    ASSERT_TRUE(writeFloatImage(dir / "m.exr", img));
    // The file is exactly the in-memory encoding, but for the capDate OpenEXR stamps (the two
    // encodes may fall in different seconds).
    EXPECT_EQ(withoutCapDate(*exr), withoutCapDate(readBytes(dir / "m.exr")));
    auto in = OIIO::ImageInput::open(dir / "m.exr");
    ASSERT_TRUE(in);
    std::vector<float> px(img.data.size());
    ASSERT_TRUE(in->read_image(0, 0, 0, 1, TypeDesc::FLOAT, px.data()));
    EXPECT_EQ(px, img.data);

    auto png = encodeHeight16Png(img);
    ASSERT_TRUE(png) << png.error().message;
    ASSERT_TRUE(writeHeight16Png(dir / "h.png", img));
    EXPECT_EQ(*png, readBytes(dir / "h.png"));
    auto back = readHeightImageFromMemory(*png);
    ASSERT_TRUE(back) << back.error().message;
    ASSERT_EQ(back->width, 5);
    ASSERT_EQ(back->height, 3);
    for (std::size_t k = 0; k + 1 < img.data.size(); ++k)
        EXPECT_NEAR(back->data[k], img.data[k], 1.0 / 32767) << k;
    EXPECT_FLOAT_EQ(back->at(4, 2), 1.0f);

    auto raw = encodeF32(img);
    ASSERT_TRUE(raw);
    ASSERT_EQ(raw->size(), img.data.size() * 4);
    for (std::size_t k = 0; k < img.data.size(); ++k) {
        std::uint32_t bits = 0;
        for (int b = 0; b < 4; ++b)
            bits |= std::uint32_t((*raw)[k * 4 + static_cast<std::size_t>(b)]) << (8 * b);
        float v = 0;
        std::memcpy(&v, &bits, 4);
        EXPECT_EQ(v, img.data[k]) << k;
    }
}

TEST(ImageIoTest, InMemoryEncodersRefuseEmptyOrInconsistentImages) {
    HeightImage empty;
    HeightImage wrong(4, 4);
    wrong.data.resize(3);
    for (const HeightImage* img : {&empty, &wrong}) {
        auto exr = encodeFloatExr(*img);
        auto png = encodeHeight16Png(*img);
        auto raw = encodeF32(*img);
        ASSERT_FALSE(exr);
        ASSERT_FALSE(png);
        ASSERT_FALSE(raw);
        EXPECT_EQ(exr.error().field, "image");
        EXPECT_NE(png.error().message.find("dermis::encodeHeight16Png"), std::string::npos);
        EXPECT_EQ(raw.error().code, ErrorCode::InvalidArgument);
    }
}

TEST(ImageIoTest, DecodeImage8ExpandsGrey) {
    TempDir dir;
    const std::vector<std::uint8_t> px = {10, 250};
    writeImage(dir / "g.png", 2, 1, 1, px, TypeDesc::UINT8);
    auto img = decodeImage8(readBytes(dir / "g.png"));
    ASSERT_TRUE(img.ok()) << img.error().message;
    ASSERT_EQ(img->rgba.size(), 8u);
    EXPECT_EQ(img->rgba[0], 10);
    EXPECT_EQ(img->rgba[2], 10);
    EXPECT_EQ(img->rgba[3], 255);
    EXPECT_EQ(img->rgba[5], 250);
}

TEST(ImageIoTest, DecodeImage8KeepsUnassociatedAlpha) {
    // glTF base-colour textures store colour and alpha independently: a half-transparent pixel
    // must come back as stored, not premultiplied (OpenImageIO's default for PNG).
    TempDir dir;
    const std::vector<std::uint8_t> px = {200, 100, 50, 128, 10, 20, 30, 255};
    Image8 src;
    src.width = 2;
    src.height = 1;
    src.rgba = px;
    auto png = encodePng(src); // libpng directly: stores the values as given
    ASSERT_TRUE(png.ok()) << png.error().message;
    writeBytes(dir / "a.png", *png);
    auto img = decodeImage8(readBytes(dir / "a.png"));
    ASSERT_TRUE(img.ok()) << img.error().message;
    EXPECT_EQ(img->rgba, px);
}

TEST(ImageIoTest, BadFilesGiveErrorsNotCrashes) {
    TempDir dir;
    EXPECT_EQ(readHeightImage(dir / "missing.png").error().code, ErrorCode::NotFound);
    EXPECT_FALSE(readHeightImageFromMemory({}).ok());
    EXPECT_FALSE(decodeImage8({}).ok());
    std::vector<std::uint8_t> garbage(300);
    std::mt19937 rng(5);
    for (auto& b : garbage) b = static_cast<std::uint8_t>(rng());
    EXPECT_FALSE(readHeightImageFromMemory(garbage).ok());
    writeBytes(dir / "garbage.png", garbage);
    EXPECT_FALSE(readHeightImage(dir / "garbage.png").ok());

    std::vector<std::uint16_t> px(64 * 64);
    for (auto& v : px) v = static_cast<std::uint16_t>(rng());
    writeImage(dir / "ok.png", 64, 64, 1, px, TypeDesc::UINT16);
    const auto bytes = readBytes(dir / "ok.png");
    for (std::size_t cut : {std::size_t(8), std::size_t(30), bytes.size() / 2, bytes.size() - 40}) {
        std::vector<std::uint8_t> truncated(bytes.begin(), bytes.begin() + cut);
        EXPECT_FALSE(readHeightImageFromMemory(truncated).ok()) << cut;
        writeBytes(dir / "t.png", truncated);
        EXPECT_FALSE(readHeightImage(dir / "t.png").ok()) << cut;
    }
}

// Issue #12.8: uploads are decoded from memory; nothing goes to the temp folder, whatever the
// format and whether the bytes decode or not.
TEST(ImageIoTest, DecodingFromMemoryWritesNoFile) {
    TempDir dir, tmp;
    std::vector<std::uint8_t> px8(3 * 2 * 3); // RGB: HDR, WebP and GIF write no grey
    for (std::size_t k = 0; k < px8.size(); ++k) px8[k] = static_cast<std::uint8_t>(k * 13);
    std::vector<std::string> names;
    for (const char* ext : {"png", "jpg", "tif", "exr", "bmp", "hdr", "webp", "gif", "tga"}) {
        const std::string name = std::string("p.") + ext;
        writeImage(dir / name, 3, 2, 3, px8, TypeDesc::UINT8);
        names.push_back(name);
    }
    const char* old = std::getenv("TMPDIR");
    const std::string saved = old ? old : "";
    ::setenv("TMPDIR", tmp.str().c_str(), 1);
    for (const std::string& name : names) {
        const auto bytes = readBytes(dir / name);
        auto img = readHeightImageFromMemory(bytes);
        EXPECT_TRUE(img.ok()) << name << ": " << img.error().message;
        if (img) EXPECT_EQ(img->width, 3) << name;
        auto rgba = decodeImage8(bytes);
        EXPECT_TRUE(rgba.ok()) << name << ": " << rgba.error().message;
        std::vector<std::uint8_t> corrupt(bytes.begin(), bytes.begin() + static_cast<long>(bytes.size() / 2));
        (void)readHeightImageFromMemory(corrupt); // fails or not: in memory either way
    }
    if (old) ::setenv("TMPDIR", saved.c_str(), 1);
    else ::unsetenv("TMPDIR");
    EXPECT_TRUE(std::filesystem::is_empty(tmp.str())) << "files left in " << tmp.str();
}

TEST(ImageIoTest, OversizedPatternsAreRejected) {
    TempDir dir;
    std::vector<std::uint8_t> px(kMaxPatternSize + 1, 128);
    writeImage(dir / "wide.png", kMaxPatternSize + 1, 1, 1, px, TypeDesc::UINT8);
    auto img = readHeightImage(dir / "wide.png");
    ASSERT_FALSE(img.ok());
    EXPECT_EQ(img.error().code, ErrorCode::InvalidArgument);
    EXPECT_NE(img.error().message.find("larger than the limit"), std::string::npos);
}

// Found by tests/fuzz/image_fuzz (kept in tests/fuzz/regressions/image_fuzz): a 58-byte GIF
// whose screen is 65535² made OpenImageIO's GIF reader throw std::length_error out of
// ImageInput::create, through readHeightImageFromMemory (a 500 for a pattern upload, a crash
// for any caller without a handler). Bad bytes are an error, never an exception.
TEST(ImageIoTest, CorruptGifIsAnErrorNotAnException) {
    const std::vector<std::uint8_t> gif = {
        0x47, 0x49, 0x46, 0x7e, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xe8, 0x32, 0x00, 0x00, 0x00,
        0x3d, 0x28, 0x00, 0x00, 0x74, 0x67, 0x61, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00, 0x01, 0x00,
        0x18, 0x00, 0x00, 0x00, 0x00, 0x00, 0x10, 0x00, 0x00, 0x00, 0x13, 0x0b, 0x00, 0x00, 0xed,
        0xf4, 0x00, 0x00, 0x00, 0x00, 0x00, 0x80, 0xff, 0x00, 0x80, 0xff, 0x00, 0x00};
    Result<HeightImage> img = makeError(ErrorCode::Internal, "", "", "not run");
    EXPECT_NO_THROW(img = readHeightImageFromMemory(gif));
    ASSERT_FALSE(img.ok());
    EXPECT_NE(img.error().code, ErrorCode::Internal);
    Result<Image8> rgba = makeError(ErrorCode::Internal, "", "", "not run");
    EXPECT_NO_THROW(rgba = decodeImage8(gif));
    EXPECT_FALSE(rgba.ok());
}

// Also from image_fuzz: OpenImageIO decodes a GIF's whole screen in open(), so a 35-byte GIF
// declaring a 16000² screen cost 1.3 GB and 2 s before the side limit refused it (20000²
// here: past decodeImage8's limit too). The screen
// size is now checked from the header first: refused, nothing allocated.
TEST(ImageIoTest, GifScreenPastTheLimitIsRefusedFromItsHeader) {
    std::vector<std::uint8_t> gif = {0x47, 0x49, 0x46, 0x38, 0x39, 0x61, 0x01, 0x00, 0x01,
                                     0x00, 0x80, 0x00, 0x00, 0x00, 0x00, 0x00, 0xff, 0xff,
                                     0xff, 0x2c, 0x00, 0x00, 0x00, 0x00, 0x01, 0x00, 0x01,
                                     0x00, 0x00, 0x02, 0x02, 0x44, 0x01, 0x00, 0x3b};
    auto small = readHeightImageFromMemory(gif); // as made: 1×1, decodes
    ASSERT_TRUE(small.ok()) << small.error().message;
    EXPECT_EQ(small->width, 1);
    gif[6] = gif[8] = 0x20, gif[7] = gif[9] = 0x4e; // 20000 × 20000
    rusage before{}, after{};
    ::getrusage(RUSAGE_SELF, &before);
    auto big = readHeightImageFromMemory(gif);
    auto bigRgba = decodeImage8(gif);
    ::getrusage(RUSAGE_SELF, &after);
    ASSERT_FALSE(big.ok());
    EXPECT_EQ(big.error().code, ErrorCode::InvalidArgument);
    EXPECT_NE(big.error().message.find("20000x20000"), std::string::npos) << big.error().message;
    EXPECT_FALSE(bigRgba.ok());
    const long grewMb = (after.ru_maxrss - before.ru_maxrss) / 1024;
    EXPECT_LT(grewMb, 256) << "peak memory grew by " << grewMb << " MB for a 35-byte file";
}
