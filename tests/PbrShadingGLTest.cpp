// PbrShadingGLTest — `render.shading: "pbr"` end to end through `dermis-server render` (issue
// #26), on the backend named by $DERMIS_TEST_GL: the Khronos material models of
// tests/models/fidelity shaded by their glTF materials under the default studio environment, and
// the characters still drawn. What each test checks is what the material says: alpha-mask holes,
// blended cards that let the background through, exposure and tone mapping, and that the default
// (legacy) frame is untouched; and `render.shading: "skin"`: light scattered under the surface
// (red past the terminator, wrinkles softer in red), nothing added under a uniform sky.
#include "BuildPaths.hpp"
#include "GltfTestBuilder.hpp"
#include "TestFiles.hpp"
#include "io/frame_io.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>

using namespace dermis;
using namespace dermis::test;
using nlohmann::json;

namespace {

const std::string kTestModels = dermis::build::testModelsDir();
const std::string kHelmet = kTestModels + "/fidelity/DamagedHelmet/DamagedHelmet.glb";
const std::string kAlpha = kTestModels + "/fidelity/AlphaBlendModeTest/AlphaBlendModeTest.glb";

std::string gl() {
    const char* env = std::getenv("DERMIS_TEST_GL");
    return std::string(" --gl ") + (env && *env ? env : "auto");
}

/// The frame of `model` rendered with `options` at 128² (no anti-aliasing: exact pixels).
Image8 render(const TempDir& dir, const std::string& model, const std::string& options,
              const json& render = json::object()) {
    json scene = {{"format", "dermis.scene/1"}, {"model", model}, {"render", render}};
    writeText(dir / "s.json", scene.dump());
    CliRun r = runServer(dir, "render --scene " + (dir / "s.json") + " --out " + (dir / "f.png") +
                                  " --size 128x128 --aa none " + options + gl());
    EXPECT_EQ(r.code, 0) << options << ": " << r.err;
    auto img = decodeFrame(readBytes(dir / "f.png"));
    EXPECT_TRUE(img) << options;
    return img ? *img : Image8{};
}

/// Pixels that differ from the top-left pixel (the background) by more than 8 in a channel.
std::size_t foreground(const Image8& img) {
    std::size_t n = 0;
    for (std::size_t p = 0; p + 3 < img.rgba.size(); p += 4)
        for (int c = 0; c < 3; ++c)
            if (std::abs(int(img.rgba[p + c]) - int(img.rgba[c])) > 8) {
                ++n;
                break;
            }
    return n;
}

double meanLuma(const Image8& img) {
    double sum = 0.0;
    for (std::size_t p = 0; p + 3 < img.rgba.size(); p += 4)
        sum += 0.2126 * img.rgba[p] + 0.7152 * img.rgba[p + 1] + 0.0722 * img.rgba[p + 2];
    return img.rgba.empty() ? 0.0 : sum / (img.rgba.size() / 4);
}

} // namespace

TEST(PbrShadingGLTest, TheHelmetIsShadedByItsMaterialAndLegacyStaysTheDefault) {
    TempDir dir;
    const Image8 legacy = render(dir, kHelmet, "");
    const Image8 legacyNamed = render(dir, kHelmet, "--shading legacy");
    EXPECT_EQ(legacy.rgba, legacyNamed.rgba) << "legacy is the default shading";
    const Image8 pbr = render(dir, kHelmet, "--shading pbr");
    ASSERT_EQ(pbr.rgba.size(), legacy.rgba.size());
    EXPECT_GT(foreground(pbr), 128u * 128u / 8) << "the helmet fills its frame";
    std::size_t differ = 0;
    for (std::size_t p = 0; p < pbr.rgba.size(); ++p)
        if (std::abs(int(pbr.rgba[p]) - int(legacy.rgba[p])) > 16) ++differ;
    EXPECT_GT(differ, pbr.rgba.size() / 20) << "pbr looks like legacy";
    // The scene member says the same as the option.
    const Image8 fromScene = render(dir, kHelmet, "", {{"shading", "pbr"}});
    EXPECT_EQ(fromScene.rgba, pbr.rgba);
}

TEST(PbrShadingGLTest, ExposureZeroLeavesABlackSilhouette) {
    TempDir dir;
    // Exposure scales all light before tone mapping (the environment's and the emissive one, as
    // three.js's toneMappingExposure does): at 0 the helmet is a black shape on the background.
    const Image8 dark = render(dir, kHelmet, "--shading pbr --exposure 0");
    const Image8 lit = render(dir, kHelmet, "--shading pbr");
    EXPECT_GT(foreground(dark), foreground(lit) * 9 / 10) << "the silhouette is drawn";
    std::size_t black = 0;
    for (std::size_t p = 0; p + 3 < dark.rgba.size(); p += 4)
        if (dark.rgba[p] < 3 && dark.rgba[p + 1] < 3 && dark.rgba[p + 2] < 3) ++black;
    EXPECT_GT(black, foreground(lit) * 9 / 10);
}

TEST(PbrShadingGLTest, ExposureAndToneMappingChangeTheFrame) {
    TempDir dir;
    const Image8 neutral = render(dir, kHelmet, "--shading pbr");
    const Image8 aces = render(dir, kHelmet, "--shading pbr --tone-mapping aces");
    const Image8 bright = render(dir, kHelmet, "--shading pbr --exposure 4");
    EXPECT_NE(neutral.rgba, aces.rgba);
    EXPECT_GT(meanLuma(bright), meanLuma(neutral) + 5.0);
}

/// A square of side 2 in the XY plane facing +Z, textured with an 8×1 image whose left half is
/// transparent and right half opaque (alpha ramps across the middle and, the sampler wrapping,
/// across the left edge), in material `alphaMode` (with baseColorFactor alpha `alpha`).
std::string alphaQuad(const TempDir& dir, const std::string& alphaMode, double alpha) {
    namespace g = dermis::test::gltf;
    g::Builder b;
    const int pos =
        b.add(std::vector<float>{-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0}, g::kFloat, "VEC3");
    const int nrm =
        b.add(std::vector<float>{0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}, g::kFloat, "VEC3");
    const int uv = b.add(std::vector<float>{0, 1, 1, 1, 1, 0, 0, 0}, g::kFloat, "VEC2");
    const int idx = b.add(std::vector<std::uint16_t>{0, 1, 2, 0, 2, 3}, g::kUShort, "SCALAR");
    std::vector<std::uint8_t> texels;
    for (int i = 0; i < 8; ++i)
        texels.insert(texels.end(), {230, 230, 230, std::uint8_t(i < 4 ? 0 : 255)});
    writeImage(dir / "a.png", 8, 1, 4, texels, OIIO::TypeDesc::UINT8);
    const int img = b.view(readBytes(dir / "a.png"));
    b.doc["images"] = json::array({{{"bufferView", img}, {"mimeType", "image/png"}}});
    b.doc["textures"] = json::array({{{"source", 0}}});
    json pbr = json::object();
    pbr["baseColorFactor"] = {1, 1, 1, alpha};
    pbr["metallicFactor"] = 0;
    pbr["baseColorTexture"] = {{"index", 0}};
    json material = json::object();
    material["alphaMode"] = alphaMode;
    material["doubleSided"] = true;
    material["pbrMetallicRoughness"] = pbr;
    b.doc["materials"] = json::array({material});
    json prim = json::object();
    prim["attributes"] = {{"POSITION", pos}, {"NORMAL", nrm}, {"TEXCOORD_0", uv}};
    prim["indices"] = idx;
    prim["material"] = 0;
    json mesh = json::object();
    mesh["primitives"] = json::array({prim});
    b.doc["meshes"] = json::array({mesh});
    b.doc["nodes"] = json::array({{{"mesh", 0}}});
    b.doc["scenes"] = json::array({{{"nodes", {0}}}});
    b.doc["scene"] = 0;
    const std::vector<std::uint8_t> glb = b.glb();
    const std::string path = dir / (alphaMode + ".glb");
    writeText(path, std::string(glb.begin(), glb.end()));
    return path;
}

TEST(PbrShadingGLTest, AlphaMaskCutsHolesAndBlendLetsTheBackgroundThrough) {
    TempDir dir;
    const json front = {{"camera", {{"yaw", 0}, {"pitch", 0}}}};
    // Legacy ignores alpha: the whole square is drawn. MASK (cutoff 0.5) keeps the opaque half.
    const std::string mask = alphaQuad(dir, "MASK", 1.0);
    const std::size_t whole = foreground(render(dir, mask, "--shading legacy", front));
    const std::size_t half = foreground(render(dir, mask, "--shading pbr", front));
    EXPECT_GT(whole, 128u * 128u / 4);
    EXPECT_NEAR(static_cast<double>(half) / static_cast<double>(whole), 0.5, 0.08);
    // BLEND with factor alpha 1: the transparent half shows the background through, a ramp
    // between; OPAQUE ignores alpha.
    const std::size_t opaque =
        foreground(render(dir, alphaQuad(dir, "OPAQUE", 1.0), "--shading pbr", front));
    EXPECT_EQ(opaque, whole);
    const Image8 blended = render(dir, alphaQuad(dir, "BLEND", 1.0), "--shading pbr", front);
    const std::size_t seen = foreground(blended);
    EXPECT_LT(seen, whole * 3 / 4);
    EXPECT_GT(seen, whole / 3);
    // A uniform alpha of 0.5 mixes the lit square halfway with the background: darker than the
    // opaque square's pixel at the centre of its right half, brighter than the background.
    const Image8 solid = render(dir, alphaQuad(dir, "OPAQUE", 1.0), "--shading pbr", front);
    const Image8 glass = render(dir, alphaQuad(dir, "BLEND", 0.5), "--shading pbr", front);
    const std::size_t centre = (64u * 128u + 80u) * 4u;
    EXPECT_LT(glass.rgba[centre], solid.rgba[centre] - 10);
    EXPECT_GT(glass.rgba[centre], glass.rgba[0] + 10);
}

TEST(PbrShadingGLTest, TheCharactersRenderWithPbrOnEveryShape) {
    TempDir dir;
    // Skinned characters through the pbr programs: CesiumMan (textured), RiggedFigure (no UVs,
    // no material), the Barbarian (palette texture, props), and the tessellated variant.
    for (const char* model : {"CesiumMan/CesiumMan.glb", "RiggedFigure/RiggedFigure.glb",
                              "KayKitBarbarian/Barbarian.glb"}) {
        const Image8 img = render(dir, kTestModels + "/" + model, "--shading pbr");
        EXPECT_GT(foreground(img), 128u * 128u / 50) << model;
        const Image8 tess = render(dir, kTestModels + "/" + model, "--shading pbr",
                                   {{"displacement", "tessellated"}});
        EXPECT_GT(foreground(tess), 128u * 128u / 50) << model << " tessellated";
    }
    // The skin programs (linked on their first frame), vertex and tessellated.
    for (const char* displacement : {"vertex", "tessellated"}) {
        const Image8 skin = render(dir, kTestModels + "/KayKitBarbarian/Barbarian.glb", "--shading skin",
                                   {{"displacement", displacement}});
        EXPECT_GT(foreground(skin), 128u * 128u / 50) << "skin, " << displacement;
    }
}

/// A Radiance .hdr of w × h texels (flat RGBE scanlines): radiance `sky` in the rows above the
/// horizon (the upper half) and `ground` below it.
void writeSkyHdr(const std::string& path, int w, int h, glm::vec3 sky, glm::vec3 ground) {
    std::string text = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y " + std::to_string(h) + " +X " +
                       std::to_string(w) + "\n";
    auto rgbe = [](glm::vec3 rgb) {
        std::string t(4, '\0');
        const float v = std::max({rgb.r, rgb.g, rgb.b});
        if (v <= 0.0f) return t;
        int e = 0;
        const float scale = std::frexp(v, &e) * 256.0f / v;
        t = {static_cast<char>(rgb.r * scale), static_cast<char>(rgb.g * scale),
             static_cast<char>(rgb.b * scale), static_cast<char>(e + 128)};
        return t;
    };
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            text += rgbe(y < h / 2 ? sky : ground);
    writeText(path, text);
}

/// A Radiance .hdr of w × h texels of one radiance `rgb`.
void writeUniformHdr(const std::string& path, int w, int h, glm::vec3 rgb) {
    writeSkyHdr(path, w, h, rgb, rgb);
}

TEST(PbrShadingGLTest, AnEnvironmentFileLightsTheFrame) {
    TempDir dir;
    // Under a uniformly red sky the grey-white parts of the helmet turn red; under the default
    // studio (neutral grey) they do not.
    writeUniformHdr(dir / "red.hdr", 64, 32, glm::vec3(1.5f, 0.0f, 0.0f));
    const Image8 studio = render(dir, kHelmet, "--shading pbr");
    const Image8 red = render(dir, kHelmet, "--shading pbr --environment " + (dir / "red.hdr"));
    auto redness = [](const Image8& img) {
        double r = 0.0, g = 0.0;
        for (std::size_t p = 0; p + 3 < img.rgba.size(); p += 4) {
            r += img.rgba[p];
            g += img.rgba[p + 1];
        }
        return r / std::max(g, 1.0);
    };
    EXPECT_GT(redness(red), 1.5 * redness(studio));
    // A file that is not an image fails with a message naming it.
    writeText(dir / "bad.hdr", "not an image");
    writeText(dir / "s.json", json({{"format", "dermis.scene/1"}, {"model", kHelmet}}).dump());
    CliRun r = runServer(dir, "render --scene " + (dir / "s.json") + " --out " + (dir / "f.png") +
                                  " --shading pbr --environment " + (dir / "bad.hdr") + gl());
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.err.find("bad.hdr"), std::string::npos) << r.err;
}

TEST(PbrShadingGLTest, MaterialViewsTakeTheMaterialApart) {
    TempDir dir;
    const Image8 shaded = render(dir, kHelmet, "--shading pbr");
    const Image8 base = render(dir, kHelmet, "--shading pbr --view basecolor");
    const Image8 light = render(dir, kHelmet, "--shading pbr --view lighting");
    const Image8 normal = render(dir, kHelmet, "--shading pbr --view normal");
    const Image8 legacyNormal = render(dir, kHelmet, "--view normal");
    EXPECT_NE(base.rgba, shaded.rgba);
    EXPECT_NE(light.rgba, shaded.rgba);
    EXPECT_NE(normal.rgba, legacyNormal.rgba)
        << "pbr's normal view includes the model's normal map";
    // The lighting view is the light on white: grey wherever the helmet is.
    std::size_t grey = 0, fg = 0;
    for (std::size_t p = 0; p + 3 < light.rgba.size(); p += 4) {
        if (light.rgba[p] == light.rgba[0] && light.rgba[p + 1] == light.rgba[1]) continue;
        ++fg;
        if (std::abs(int(light.rgba[p]) - int(light.rgba[p + 2])) <= 3) ++grey;
    }
    EXPECT_GT(fg, 1000u);
    EXPECT_GT(grey, fg * 9 / 10);
}

namespace {

/// A white rough dielectric sphere of radius 1 (a latitude-longitude grid, normals = positions).
std::string whiteSphere(const TempDir& dir) {
    namespace g = dermis::test::gltf;
    constexpr int kLon = 48, kLat = 24;
    std::vector<float> pos, uv;
    std::vector<std::uint16_t> idx;
    for (int j = 0; j <= kLat; ++j)
        for (int i = 0; i <= kLon; ++i) {
            const double th = M_PI * j / kLat, ph = 2.0 * M_PI * i / kLon;
            pos.insert(pos.end(), {float(std::sin(th) * std::cos(ph)), float(std::cos(th)),
                                   float(std::sin(th) * std::sin(ph))});
            uv.insert(uv.end(), {float(i) / kLon, float(j) / kLat});
        }
    for (int j = 0; j < kLat; ++j)
        for (int i = 0; i < kLon; ++i) {
            const auto a = std::uint16_t(j * (kLon + 1) + i), b = std::uint16_t(a + kLon + 1);
            idx.insert(idx.end(), {a, std::uint16_t(a + 1), b, std::uint16_t(a + 1), std::uint16_t(b + 1), b});
        }
    g::Builder b;
    const int p = b.add(pos, g::kFloat, "VEC3"), n = b.add(pos, g::kFloat, "VEC3");
    const int t = b.add(uv, g::kFloat, "VEC2"), i = b.add(idx, g::kUShort, "SCALAR");
    json pbr = {{"baseColorFactor", {0.9, 0.9, 0.9, 1.0}}, {"metallicFactor", 0}, {"roughnessFactor", 0.6}};
    b.doc["materials"] = json::array({{{"pbrMetallicRoughness", pbr}}});
    json prim = {{"attributes", {{"POSITION", p}, {"NORMAL", n}, {"TEXCOORD_0", t}}}, {"indices", i}, {"material", 0}};
    b.doc["meshes"] = json::array({{{"primitives", json::array({prim})}}});
    b.doc["nodes"] = json::array({{{"mesh", 0}}});
    b.doc["scenes"] = json::array({{{"nodes", {0}}}});
    b.doc["scene"] = 0;
    const std::vector<std::uint8_t> glb = b.glb();
    writeText(dir / "sphere.glb", std::string(glb.begin(), glb.end()));
    return dir / "sphere.glb";
}

/// Mean of channel `c` over the pixels of rows [y0, y1) that differ from the background.
double meanChannel(const Image8& img, int c, int y0, int y1) {
    double sum = 0.0;
    std::size_t n = 0;
    for (int y = y0; y < y1; ++y)
        for (int x = 0; x < img.width; ++x) {
            const std::size_t p = (std::size_t(y) * img.width + x) * 4;
            bool fg = false;
            for (int k = 0; k < 3; ++k)
                fg = fg || std::abs(int(img.rgba[p + k]) - int(img.rgba[k])) > 8;
            if (!fg) continue;
            sum += img.rgba[p + c];
            ++n;
        }
    return n ? sum / n : 0.0;
}

/// Energy of the detail of channel `c` inside the frame's foreground: the mean absolute
/// difference of each pixel from its four neighbours' mean.
double detail(const Image8& img, int c) {
    double sum = 0.0;
    std::size_t n = 0;
    auto at = [&](int x, int y) { return double(img.rgba[(std::size_t(y) * img.width + x) * 4 + c]); };
    for (int y = 1; y + 1 < img.height; ++y)
        for (int x = 1; x + 1 < img.width; ++x) {
            const std::size_t p = (std::size_t(y) * img.width + x) * 4;
            if (img.rgba[p] == img.rgba[0] && img.rgba[p + 1] == img.rgba[1]) continue;
            sum += std::abs(at(x, y) - 0.25 * (at(x - 1, y) + at(x + 1, y) + at(x, y - 1) + at(x, y + 1)));
            ++n;
        }
    return n ? sum / n : 0.0;
}

} // namespace

TEST(PbrShadingGLTest, SkinScattersRedPastTheTerminator) {
    TempDir dir;
    // A white sphere under a sky lit from above only: pbr shades its underside grey (every
    // channel alike); skin's scattering carries red furthest round the terminator, so the
    // underside turns red and the top keeps its light.
    const std::string sphere = whiteSphere(dir);
    writeSkyHdr(dir / "sky.hdr", 64, 32, glm::vec3(2.0f), glm::vec3(0.0f));
    const std::string env = " --environment " + (dir / "sky.hdr");
    const Image8 pbr = render(dir, sphere, "--shading pbr" + env);
    const Image8 skin = render(dir, sphere, "--shading skin" + env);
    ASSERT_EQ(pbr.height, 128);
    // The lower part of the sphere's disc (rows 80..110 of 128: below its centre, still on it).
    const double pbrR = meanChannel(pbr, 0, 80, 110), pbrB = meanChannel(pbr, 2, 80, 110);
    const double skinR = meanChannel(skin, 0, 80, 110), skinB = meanChannel(skin, 2, 80, 110);
    EXPECT_LT(std::abs(pbrR - pbrB), 2.0) << "pbr shades white white";
    EXPECT_GT(skinR - skinB, 6.0) << "skin: R " << skinR << ", B " << skinB;
    EXPECT_GT(skinR, pbrR + 3.0) << "red light reaches further round than pbr's";
    // The lit top stays white: scattering moves light, it does not tint what is lit.
    const double topR = meanChannel(skin, 0, 20, 40), topB = meanChannel(skin, 2, 20, 40);
    EXPECT_GT(topB, 100.0);
    EXPECT_LT(std::abs(topR - topB), 0.1 * topB) << "top R " << topR << ", B " << topB;
}

TEST(PbrShadingGLTest, SkinUnderAUniformSkyAddsNoLight) {
    TempDir dir;
    // Light from every direction alike has no bands for the scattering to blur: the diffuse
    // light is pbr's, and only the second specular lobe differs (a little).
    const std::string sphere = whiteSphere(dir);
    writeUniformHdr(dir / "grey.hdr", 64, 32, glm::vec3(0.8f));
    const std::string env = " --environment " + (dir / "grey.hdr");
    const Image8 pbr = render(dir, sphere, "--shading pbr" + env);
    const Image8 skin = render(dir, sphere, "--shading skin" + env);
    ASSERT_EQ(pbr.rgba.size(), skin.rgba.size());
    double diff = 0.0;
    int worst = 0;
    for (std::size_t p = 0; p < pbr.rgba.size(); ++p) {
        const int d = std::abs(int(pbr.rgba[p]) - int(skin.rgba[p]));
        diff += d;
        worst = std::max(worst, d);
    }
    diff /= double(pbr.rgba.size());
    EXPECT_LT(diff, 1.0) << "mean |skin − pbr| in bytes";
    EXPECT_LE(worst, 8);
    EXPECT_GT(meanChannel(skin, 1, 0, 128), 60.0) << "the sphere is lit";
}

TEST(PbrShadingGLTest, SkinSoftensWrinklesInRed) {
    TempDir dir;
    // The default scene at its squat (wrinkles, bulges and bones active) under the studio:
    // skin's red diffuse takes a normal nearer the unbumped one, so the relief's detail loses
    // more of its contrast in red than in blue. The scene member says what the option says.
    json scene = json::parse(readBytes(std::string(dermis::build::sourceDir()) + "/models/default.scene.json"));
    scene["render"]["size"] = {256, 256};
    writeText(dir / "d.json", scene.dump());
    auto frame = [&](const std::string& shading) {
        CliRun r = runServer(dir, "render --scene " + (dir / "d.json") + " --out " + (dir / "w.png") +
                                      " --aa none --shading " + shading + gl());
        EXPECT_EQ(r.code, 0) << r.err;
        auto img = decodeFrame(readBytes(dir / "w.png"));
        return img ? *img : Image8{};
    };
    const Image8 pbr = frame("pbr"), skin = frame("skin");
    ASSERT_EQ(pbr.height, 256);
    const double red = detail(skin, 0) / detail(pbr, 0), blue = detail(skin, 2) / detail(pbr, 2);
    EXPECT_LT(red, blue - 0.05) << "detail kept: red " << red << ", blue " << blue;
    EXPECT_NE(pbr.rgba, skin.rgba);
}
