// SkinShadingGLTest — `render.shading: "skin"` end to end through `dermis-server render` (issue
// #26), on the backend named by $DERMIS_TEST_GL: light scattered under the surface (red past the
// terminator of a white sphere lit from above; the wrinkles' relief softer in red than in blue),
// nothing added under a uniform sky (skin equals pbr but for the second specular lobe), and the
// skin programs drawing a character vertex and tessellated. (A suite of its own: under the
// sanitizers every render here costs tens of seconds.)
#include "BuildPaths.hpp"
#include "GltfTestBuilder.hpp"
#include "RenderCliTestHelpers.hpp"
#include "TestFiles.hpp"
#include "io/frame_io.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>

using namespace dermis;
using namespace dermis::test;
using nlohmann::json;

namespace {

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

TEST(SkinShadingGLTest, SkinScattersRedPastTheTerminator) {
    TempDir dir;
    // A white sphere under a sky lit from above only: pbr shades its underside grey (every
    // channel alike); skin's scattering carries red furthest round the terminator, so the
    // underside turns red and the top keeps its light.
    const std::string sphere = whiteSphereGlb(dir);
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

TEST(SkinShadingGLTest, SkinUnderAUniformSkyAddsNoLight) {
    TempDir dir;
    // Light from every direction alike has no bands for the scattering to blur: the diffuse
    // light is pbr's, and only the second specular lobe differs (a little).
    const std::string sphere = whiteSphereGlb(dir);
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

TEST(SkinShadingGLTest, SkinSoftensWrinklesInRed) {
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

TEST(SkinShadingGLTest, TheSkinProgramsDrawACharacterVertexAndTessellated) {
    TempDir dir;
    // The skin programs (linked on the first skin frame) on the Barbarian (props, palette texture).
    const std::string barbarian = std::string(dermis::build::testModelsDir()) + "/KayKitBarbarian/Barbarian.glb";
    const Image8 pbr = render(dir, barbarian, "--shading pbr");
    for (const char* displacement : {"vertex", "tessellated"}) {
        const Image8 skin = render(dir, barbarian, "--shading skin", {{"displacement", displacement}});
        ASSERT_EQ(skin.rgba.size(), pbr.rgba.size()) << displacement;
        std::size_t drawn = 0, differ = 0;
        for (std::size_t p = 0; p + 3 < skin.rgba.size(); p += 4) {
            bool fg = false, d = false;
            for (int c = 0; c < 3; ++c) {
                fg = fg || std::abs(int(skin.rgba[p + c]) - int(skin.rgba[c])) > 8;
                d = d || skin.rgba[p + c] != pbr.rgba[p + c];
            }
            drawn += fg;
            differ += d;
        }
        EXPECT_GT(drawn, 128u * 128u / 50) << displacement;
        EXPECT_GT(differ, drawn / 4) << displacement << ": skin shades unlike pbr";
    }
}
