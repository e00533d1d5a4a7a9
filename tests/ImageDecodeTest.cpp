// ImageDecodeTest — the direct PNG (libpng) and JPEG (libjpeg-turbo) decoders give exactly the
// pixels of OpenImageIO's readers (the module libdermis_oiio.so, called directly) on every PNG
// variant (bit depths 1–16, grey, grey+alpha, RGB, RGBA, palette with and without tRNS,
// interlaced), grey and colour JPEGs, the pattern library and the test models' image files; CMYK
// JPEGs go to the module; a missing or wrong module is a clear Unavailable error.
// Needs the module built (it is a dependency of dermis_io).
#include "BuildPaths.hpp"
#include "TestFiles.hpp"
#include "io/image_decode.hpp"
#include "io/image_io.hpp"
#include "io/oiio_loader.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <png.h>
#include <turbojpeg.h>

#include <filesystem>
#include <random>

using namespace dermis;
using namespace dermis::test;

namespace {

const oiio::OiioApi& module() {
    auto api = oiio::oiioApi();
    EXPECT_TRUE(api) << api.error().message;
    if (!api) std::abort();
    return **api;
}

/// Encodes random samples as a PNG of the given colour type and bit depth with libpng.
std::vector<std::uint8_t> makePng(int w, int h, int colorType, int depth, bool trns,
                                  bool interlaced, unsigned seed) {
    std::vector<std::uint8_t> out;
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
    png_infop info = png_create_info_struct(png);
    png_set_write_fn(
        png, &out,
        [](png_structp p, png_bytep d, png_size_t n) {
            auto* v = static_cast<std::vector<std::uint8_t>*>(png_get_io_ptr(p));
            v->insert(v->end(), d, d + n);
        },
        nullptr);
    png_set_IHDR(png, info, static_cast<png_uint_32>(w), static_cast<png_uint_32>(h), depth,
                 colorType, interlaced ? PNG_INTERLACE_ADAM7 : PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    std::mt19937 rng(seed);
    if (colorType == PNG_COLOR_TYPE_PALETTE) {
        std::vector<png_color> palette(static_cast<std::size_t>(1 << depth));
        for (auto& c : palette)
            c = {static_cast<png_byte>(rng()), static_cast<png_byte>(rng()), static_cast<png_byte>(rng())};
        png_set_PLTE(png, info, palette.data(), static_cast<int>(palette.size()));
        if (trns) {
            std::vector<png_byte> alpha(palette.size() / 2 + 1);
            for (auto& a : alpha) a = static_cast<png_byte>(rng());
            png_set_tRNS(png, info, alpha.data(), static_cast<int>(alpha.size()), nullptr);
        }
    } else if (trns) {
        png_color_16 key{};
        key.gray = key.red = 1;
        key.green = key.blue = 0;
        png_set_tRNS(png, info, nullptr, 0, &key);
    }
    png_write_info(png, info);
    const int channels = png_get_channels(png, info);
    const std::size_t rowBytes = (static_cast<std::size_t>(w) * channels * depth + 7) / 8;
    std::vector<std::vector<png_byte>> rows(static_cast<std::size_t>(h), std::vector<png_byte>(rowBytes));
    std::vector<png_bytep> ptrs;
    for (auto& r : rows) {
        for (auto& b : r) b = static_cast<png_byte>(rng() % 4 == 0 ? 1 : rng()); // hit the key
        ptrs.push_back(r.data());
    }
    png_write_image(png, ptrs.data());
    png_write_end(png, nullptr);
    png_destroy_write_struct(&png, &info);
    return out;
}

std::vector<std::uint8_t> makeJpeg(int w, int h, int pixelFormat, int subsamp) {
    const int nc = tjPixelSize[pixelFormat];
    std::vector<std::uint8_t> px(static_cast<std::size_t>(w) * h * nc);
    for (std::size_t k = 0; k < px.size(); ++k)
        px[k] = static_cast<std::uint8_t>((k * 7 + (k / 97) * 13) & 0xFF);
    tjhandle tj = tjInitCompress();
    unsigned char* buf = nullptr;
    unsigned long size = 0;
    EXPECT_EQ(tjCompress2(tj, px.data(), w, 0, h, pixelFormat, &buf, &size, subsamp, 85, 0), 0)
        << tjGetErrorStr2(tj);
    std::vector<std::uint8_t> out(buf, buf + size);
    tjFree(buf);
    tjDestroy(tj);
    return out;
}

/// The direct decoders and the module agree exactly on `bytes` (decodeImage8 and the height
/// mapping), and the direct path handled them.
void expectSameAsModule(const std::vector<std::uint8_t>& bytes, const std::string& what) {
    auto direct = decodeDirect(bytes.data(), bytes.size(), 16384, "test", "");
    ASSERT_TRUE(direct.has_value()) << what << ": not handled directly";
    ASSERT_TRUE(*direct) << what << ": " << direct->error().message;

    auto mine = decodeImage8(bytes);
    ASSERT_TRUE(mine) << what << ": " << mine.error().message;
    Image8 theirs;
    oiio::OiioFailure f;
    ASSERT_TRUE(module().decodeRgba8(bytes, 16384, theirs, f)) << what << ": " << f.what;
    ASSERT_EQ(mine->width, theirs.width) << what;
    ASSERT_EQ(mine->height, theirs.height) << what;
    std::size_t differ = 0;
    for (std::size_t k = 0; k < theirs.rgba.size(); ++k)
        differ += mine->rgba[k] != theirs.rgba[k];
    EXPECT_EQ(differ, 0u) << what << ": RGBA8 bytes that differ from OpenImageIO's";

    auto heights = readHeightImageFromMemory(bytes);
    ASSERT_TRUE(heights) << what << ": " << heights.error().message;
    HeightImage theirHeights;
    ASSERT_TRUE(module().readHeight(nullptr, &bytes, kMaxPatternSize, theirHeights, f)) << what;
    EXPECT_EQ(heights->data, theirHeights.data) << what << ": heights differ from OpenImageIO's";
}

} // namespace

TEST(ImageDecodeTest, EveryPngVariantDecodesAsOpenImageIoDoes) {
    struct Variant {
        int type, depth;
        bool trns;
        const char* name;
    };
    const Variant variants[] = {
        {PNG_COLOR_TYPE_GRAY, 1, false, "grey 1-bit"},     {PNG_COLOR_TYPE_GRAY, 2, false, "grey 2-bit"},
        {PNG_COLOR_TYPE_GRAY, 4, false, "grey 4-bit"},     {PNG_COLOR_TYPE_GRAY, 8, false, "grey 8-bit"},
        {PNG_COLOR_TYPE_GRAY, 16, false, "grey 16-bit"},   {PNG_COLOR_TYPE_GRAY, 8, true, "grey + tRNS"},
        {PNG_COLOR_TYPE_GRAY_ALPHA, 8, false, "grey+alpha"}, {PNG_COLOR_TYPE_GRAY_ALPHA, 16, false, "grey+alpha 16"},
        {PNG_COLOR_TYPE_RGB, 8, false, "RGB"},             {PNG_COLOR_TYPE_RGB, 16, false, "RGB 16"},
        {PNG_COLOR_TYPE_RGB, 8, true, "RGB + tRNS"},       {PNG_COLOR_TYPE_RGBA, 8, false, "RGBA"},
        {PNG_COLOR_TYPE_RGBA, 16, false, "RGBA 16"},       {PNG_COLOR_TYPE_PALETTE, 8, false, "palette"},
        {PNG_COLOR_TYPE_PALETTE, 4, true, "palette 4-bit + tRNS"}, {PNG_COLOR_TYPE_PALETTE, 1, false, "palette 1-bit"},
    };
    unsigned seed = 1;
    for (const Variant& v : variants)
        for (bool interlaced : {false, true})
            expectSameAsModule(makePng(37, 23, v.type, v.depth, v.trns, interlaced, seed++),
                               std::string(v.name) + (interlaced ? " interlaced" : ""));
}

TEST(ImageDecodeTest, JpegsDecodeAsOpenImageIoDoes) {
    expectSameAsModule(makeJpeg(61, 47, TJPF_GRAY, TJSAMP_GRAY), "grey JPEG");
    expectSameAsModule(makeJpeg(61, 47, TJPF_RGB, TJSAMP_420), "4:2:0 JPEG");
    expectSameAsModule(makeJpeg(64, 48, TJPF_RGB, TJSAMP_422), "4:2:2 JPEG");
    expectSameAsModule(makeJpeg(33, 17, TJPF_RGB, TJSAMP_444), "4:4:4 JPEG");
}

TEST(ImageDecodeTest, CmykJpegsAreLeftToTheModule) {
    const auto cmyk = makeJpeg(32, 16, TJPF_CMYK, TJSAMP_444);
    EXPECT_FALSE(decodeDirect(cmyk.data(), cmyk.size(), 16384, "test", "").has_value());
    auto img = decodeImage8(cmyk); // through OpenImageIO
    ASSERT_TRUE(img) << img.error().message;
    EXPECT_EQ(img->width, 32);
}

/// The images embedded in a .glb (bufferView images of the BIN chunk).
std::vector<std::vector<std::uint8_t>> glbImages(const std::string& path) {
    const auto b = readBytes(path);
    auto u32 = [&](std::size_t at) {
        return std::uint32_t(b[at]) | std::uint32_t(b[at + 1]) << 8 | std::uint32_t(b[at + 2]) << 16 |
               std::uint32_t(b[at + 3]) << 24;
    };
    std::vector<std::vector<std::uint8_t>> out;
    if (b.size() < 20 || u32(0) != 0x46546C67) return out; // "glTF"
    const std::size_t jsonLen = u32(12);
    const auto doc = nlohmann::json::parse(b.begin() + 20, b.begin() + 20 + static_cast<long>(jsonLen));
    const std::size_t binAt = 20 + jsonLen + 8;
    for (const auto& img : doc.value("images", nlohmann::json::array())) {
        if (!img.contains("bufferView")) continue;
        const auto& view = doc["bufferViews"][img["bufferView"].get<std::size_t>()];
        const std::size_t off = binAt + view.value("byteOffset", std::size_t{0});
        const std::size_t len = view["byteLength"].get<std::size_t>();
        out.emplace_back(b.begin() + static_cast<long>(off), b.begin() + static_cast<long>(off + len));
    }
    return out;
}

TEST(ImageDecodeTest, PatternLibraryAndModelImagesDecodeAsOpenImageIoDoes) {
    int patterns = 0, textures = 0;
    const std::string library = std::string(dermis::build::sourceDir()) + "/patterns";
    for (const auto& e : std::filesystem::directory_iterator(library))
        if (e.path().extension() == ".png") {
            expectSameAsModule(readBytes(e.path().string()), e.path().string());
            ++patterns;
        }
    EXPECT_GE(patterns, 10) << "the built-in pattern library";
    const std::string models = std::string(dermis::build::testModelsDir());
    for (const auto& e : std::filesystem::recursive_directory_iterator(models))
        if (e.path().extension() == ".glb") {
            int k = 0;
            for (const auto& img : glbImages(e.path().string())) {
                expectSameAsModule(img, e.path().string() + " image " + std::to_string(k++));
                ++textures;
            }
        }
    EXPECT_GE(textures, 2) << "the test models' embedded textures";
}

TEST(ImageDecodeTest, DirectDecodersRejectDamageAndOversize) {
    auto png = makePng(40, 30, PNG_COLOR_TYPE_RGB, 8, false, false, 9);
    std::vector<std::uint8_t> cut(png.begin(), png.begin() + static_cast<long>(png.size() / 2));
    auto r = decodeDirect(cut.data(), cut.size(), 16384, "test", "f");
    ASSERT_TRUE(r.has_value());
    ASSERT_FALSE(*r);
    EXPECT_EQ(r->error().code, ErrorCode::Parse);
    EXPECT_NE(r->error().message.find("libpng"), std::string::npos) << r->error().message;
    auto big = decodeDirect(png.data(), png.size(), 32, "test", "f");
    ASSERT_TRUE(big.has_value());
    ASSERT_FALSE(*big);
    EXPECT_EQ(big->error().code, ErrorCode::InvalidArgument);
    EXPECT_NE(big->error().message.find("larger than the limit"), std::string::npos);
}

TEST(ImageDecodeTest, AMissingOrWrongModuleIsAClearError) {
    auto missing = oiio::loadOiioModule("/nonexistent/libdermis_oiio.so");
    ASSERT_FALSE(missing);
    EXPECT_EQ(missing.error().code, ErrorCode::Unavailable);
    EXPECT_NE(missing.error().message.find("/nonexistent/libdermis_oiio.so"), std::string::npos)
        << missing.error().message;
    // A real library that is not the module.
    auto wrong = oiio::loadOiioModule("libz.so.1");
    ASSERT_FALSE(wrong);
    EXPECT_NE(wrong.error().message.find("not the image module"), std::string::npos)
        << wrong.error().message;
    // The real one, found by the default search.
    auto api = oiio::oiioApi();
    ASSERT_TRUE(api) << api.error().message;
    EXPECT_EQ((*api)->abiVersion, oiio::kAbiVersion);
}
