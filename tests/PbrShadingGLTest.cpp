// PbrShadingGLTest — `render.shading: "pbr"` end to end through `dermis-server render` (issue
// #26), on the backend named by $DERMIS_TEST_GL: the Khronos material models of
// tests/models/fidelity shaded by their glTF materials under the default studio environment, and
// the characters still drawn. What each test checks is what the material says: alpha-mask holes,
// blended cards that let the background through, exposure and tone mapping, that pbr is the
// default and that `legacy` keeps the old look. (`skin`: SkinShadingGLTest.)
#include "BuildPaths.hpp"
#include "GltfTestBuilder.hpp"
#include "RenderCliTestHelpers.hpp"
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

TEST(PbrShadingGLTest, TheHelmetIsShadedByItsMaterialAndPbrIsTheDefault) {
    TempDir dir;
    const Image8 legacy = render(dir, kHelmet, "--shading legacy");
    const Image8 pbr = render(dir, kHelmet, "--shading pbr");
    EXPECT_EQ(render(dir, kHelmet, "").rgba, pbr.rgba) << "pbr is the default shading";
    ASSERT_EQ(pbr.rgba.size(), legacy.rgba.size());
    EXPECT_GT(foreground(pbr), 128u * 128u / 8) << "the helmet fills its frame";
    std::size_t differ = 0;
    for (std::size_t p = 0; p < pbr.rgba.size(); ++p)
        if (std::abs(int(pbr.rgba[p]) - int(legacy.rgba[p])) > 16) ++differ;
    EXPECT_GT(differ, pbr.rgba.size() / 20) << "pbr looks like legacy";
    // The scene member says the same as the option.
    const Image8 fromScene = render(dir, kHelmet, "", {{"shading", "legacy"}});
    EXPECT_EQ(fromScene.rgba, legacy.rgba);
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

/// Two squares of side 0.9 facing +Z, left (x < 0) and right, each with the base colour texture
/// of a 2×2 image; the right one's material also has an occlusion texture of one grey `occlusion`
/// (0–255) when `occlusion` ≥ 0. (For the pbr program variants with and without the material's
/// other maps.)
std::string twoSquares(const TempDir& dir, const std::string& name, int occlusion) {
    namespace g = dermis::test::gltf;
    g::Builder b;
    std::vector<float> pos, nrm, uv;
    for (const float x0 : {-1.0f, 0.1f}) {
        pos.insert(pos.end(), {x0, -0.45f, 0, x0 + 0.9f, -0.45f, 0, x0 + 0.9f, 0.45f, 0, x0, 0.45f, 0});
        nrm.insert(nrm.end(), {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1});
        uv.insert(uv.end(), {0, 1, 1, 1, 1, 0, 0, 0});
    }
    const int p = b.add(pos, g::kFloat, "VEC3");
    const int n = b.add(nrm, g::kFloat, "VEC3");
    const int t = b.add(uv, g::kFloat, "VEC2");
    const int left = b.add(std::vector<std::uint16_t>{0, 1, 2, 0, 2, 3}, g::kUShort, "SCALAR");
    const int right = b.add(std::vector<std::uint16_t>{4, 5, 6, 4, 6, 7}, g::kUShort, "SCALAR");
    writeImage(dir / "base.png", 2, 2, 4,
               std::vector<std::uint8_t>{200, 120, 90, 255, 90, 160, 220, 255, 240, 230, 120, 255, 120, 200, 130, 255},
               OIIO::TypeDesc::UINT8);
    const std::uint8_t o = static_cast<std::uint8_t>(std::max(occlusion, 0));
    writeImage(dir / "occ.png", 2, 2, 4, std::vector<std::uint8_t>{o, o, o, 255, o, o, o, 255, o, o, o, 255, o, o, o, 255},
               OIIO::TypeDesc::UINT8);
    b.doc["images"] = json::array({{{"bufferView", b.view(readBytes(dir / "base.png"))}, {"mimeType", "image/png"}},
                                   {{"bufferView", b.view(readBytes(dir / "occ.png"))}, {"mimeType", "image/png"}}});
    b.doc["textures"] = json::array({{{"source", 0}}, {{"source", 1}}});
    json plain = {{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}, {"metallicFactor", 0.2}, {"roughnessFactor", 0.4}}}};
    json occluded = plain;
    if (occlusion >= 0) occluded["occlusionTexture"] = {{"index", 1}};
    b.doc["materials"] = json::array({plain, occluded});
    json mesh = {{"primitives", json::array()}};
    for (const auto& [indices, material] : {std::pair{left, 0}, std::pair{right, 1}})
        mesh["primitives"].push_back({{"attributes", {{"POSITION", p}, {"NORMAL", n}, {"TEXCOORD_0", t}}},
                                      {"indices", indices}, {"material", material}});
    b.doc["meshes"] = json::array({mesh});
    b.doc["nodes"] = json::array({{{"mesh", 0}}});
    b.doc["scenes"] = json::array({{{"nodes", {0}}}});
    b.doc["scene"] = 0;
    const std::vector<std::uint8_t> glb = b.glb();
    const std::string path = dir / (name + ".glb");
    writeText(path, std::string(glb.begin(), glb.end()));
    return path;
}

// A frame whose materials have no texture besides the base colour is drawn by the pbr program
// without the others' lookups (DERMIS_PBR_MAPS, renderer_impl.hpp pbrPrograms); one with them by
// the program with. Both shade the same pixels: a white occlusion map (occlusion 1) on the right
// square draws the frame without it, while a grey one darkens that square alone.
TEST(PbrShadingGLTest, TheProgramWithoutMaterialMapsShadesAsTheOneWithThem) {
    TempDir dir;
    const json front = {{"camera", {{"yaw", 0}, {"pitch", 0}}}};
    const Image8 none = render(dir, twoSquares(dir, "none", -1), "--shading pbr", front);
    const Image8 white = render(dir, twoSquares(dir, "white", 255), "--shading pbr", front);
    const Image8 grey = render(dir, twoSquares(dir, "grey", 100), "--shading pbr", front);
    ASSERT_EQ(none.width, 128);
    EXPECT_GT(foreground(none), 128u * 128u / 8) << "the squares are drawn";
    EXPECT_EQ(white.rgba, none.rgba) << "the variants differ where the map has no effect";
    std::size_t leftDiffer = 0, rightDarker = 0;
    for (int y = 0; y < 128; ++y)
        for (int x = 0; x < 128; ++x) {
            const std::size_t i = (static_cast<std::size_t>(y) * 128 + x) * 4;
            const bool differ = grey.rgba[i] != none.rgba[i] || grey.rgba[i + 1] != none.rgba[i + 1];
            if (x < 64) leftDiffer += differ;
            else rightDarker += grey.rgba[i + 1] + 8 < none.rgba[i + 1];
        }
    EXPECT_EQ(leftDiffer, 0u) << "the left square's material has no occlusion map";
    EXPECT_GT(rightDarker, 500u) << "the grey occlusion map darkens the right square";
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
    // The scene's render.environment names the same file relative to the document: the same
    // frame; builtin:studio is the studio's.
    EXPECT_EQ(render(dir, kHelmet, "--shading pbr", {{"environment", "red.hdr"}}).rgba, red.rgba);
    EXPECT_EQ(render(dir, kHelmet, "--shading pbr", {{"environment", "builtin:studio"}}).rgba, studio.rgba);
    {
        writeText(dir / "s.json", json({{"format", "dermis.scene/1"}, {"model", kHelmet},
                                        {"render", {{"shading", "pbr"}, {"environment", "missing.hdr"}}}})
                                      .dump());
        CliRun r = runServer(dir, "render --scene " + (dir / "s.json") + " --out " + (dir / "f.png") + gl());
        EXPECT_EQ(r.code, 1);
        EXPECT_NE(r.err.find("missing.hdr"), std::string::npos) << r.err;
    }
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
    const Image8 legacyNormal = render(dir, kHelmet, "--shading legacy --view normal");
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
