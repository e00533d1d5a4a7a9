// KeyLightGLTest — `render.key_light` end to end through `dermis-server render` (issue #26), on the
// backend named by $DERMIS_TEST_GL: the light falls on the side it names and adds nothing at
// intensity 0; a sphere's shadow falls on a floor where the light sends it, and only darkens; a
// lit surface keeps its light with shadows on (no acne); skin wraps the light past the
// terminator in red; a character casts shadows vertex and tessellated. (A suite of its own:
// under the sanitizers every render here costs tens of seconds.)
#include "RenderCliTestHelpers.hpp"
#include "TestFiles.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>

using namespace dermis;
using namespace dermis::test;
using nlohmann::json;

namespace {

json keyLight(json direction, double intensity, bool shadow) {
    return {{"direction", std::move(direction)}, {"intensity", intensity}, {"shadow", shadow}};
}

/// Pixels of `a` darker than `b` by more than `by` levels, and brighter by more than it, by the
/// largest channel (the one tone mapping keeps monotonic: PBR Neutral desaturates a brighter
/// colour, so a darkened highlight may gain in its weaker channels).
struct Changed {
    std::size_t darker = 0, brighter = 0;
};
int peak(const Image8& img, std::size_t p) {
    return std::max({int(img.rgba[p]), int(img.rgba[p + 1]), int(img.rgba[p + 2])});
}
Changed changed(const Image8& a, const Image8& b, int by) {
    Changed c;
    for (std::size_t p = 0; p + 3 < std::min(a.rgba.size(), b.rgba.size()); p += 4) {
        const int d = peak(a, p) - peak(b, p);
        c.darker += d < -by;
        c.brighter += d > by;
    }
    return c;
}

/// Foreground pixels of `img` (differing from pixel 0).
std::size_t foreground(const Image8& img) {
    std::size_t n = 0;
    for (std::size_t p = 0; p + 3 < img.rgba.size(); p += 4) {
        bool fg = false;
        for (int k = 0; k < 3; ++k)
            fg = fg || std::abs(int(img.rgba[p + k]) - int(img.rgba[k])) > 8;
        n += fg;
    }
    return n;
}

} // namespace

TEST(KeyLightGLTest, TheLightFallsOnTheSideItNamesAndAddsNothingAtZero) {
    TempDir dir;
    // A white sphere under a dim uniform sky: with no key light both halves are alike; a key
    // light towards +x (world; the camera looks along −z) lights the right half, one towards −x
    // the left; at intensity 0 the frame is the one without it.
    const std::string sphere = whiteSphereGlb(dir);
    writeUniformHdr(dir / "dim.hdr", 64, 32, glm::vec3(0.05f));
    const std::string opts = "--shading pbr --environment " + (dir / "dim.hdr");
    const Image8 none = render(dir, sphere, opts);
    const Image8 right = render(dir, sphere, opts, {{"key_light", keyLight({1, 0, 0.3}, 4.0, false)}});
    const Image8 left = render(dir, sphere, opts, {{"key_light", keyLight({-1, 0, 0.3}, 4.0, false)}});
    const Image8 zero = render(dir, sphere, opts, {{"key_light", keyLight({1, 0, 0.3}, 0.0, true)}});
    ASSERT_EQ(none.height, 128);
    auto halves = [](const Image8& img) {
        return std::pair{meanChannel(img, 1, 0, 128, 0, 64), meanChannel(img, 1, 0, 128, 64, 128)};
    };
    const auto [noneL, noneR] = halves(none);
    const auto [rightL, rightR] = halves(right);
    const auto [leftL, leftR] = halves(left);
    EXPECT_LT(std::abs(noneL - noneR), 2.0);
    EXPECT_GT(rightR, rightL + 40.0) << "lit from +x: left " << rightL << ", right " << rightR;
    EXPECT_GT(leftL, leftR + 40.0) << "lit from −x: left " << leftL << ", right " << leftR;
    EXPECT_GT(rightR, noneR + 40.0);
    // (Another program: the compiler may order the same sums differently.)
    int worst = 0;
    double sum = 0.0;
    for (std::size_t p = 0; p < none.rgba.size(); ++p) {
        const int d = std::abs(int(none.rgba[p]) - int(zero.rgba[p]));
        worst = std::max(worst, d);
        sum += d;
    }
    EXPECT_LE(worst, 2) << "intensity 0 adds nothing";
    EXPECT_LT(sum / double(none.rgba.size()), 0.5);
}

TEST(KeyLightGLTest, ASphereCastsItsShadowOnTheFloorWhereTheLightSendsIt) {
    TempDir dir;
    // The sphere over a floor, the light above and behind it: its shadow falls on the floor in
    // front of it, towards the camera (the lower middle of the frame); shadows only darken.
    const std::string scene = whiteSphereGlb(dir, true);
    writeUniformHdr(dir / "dim.hdr", 64, 32, glm::vec3(0.05f));
    const std::string opts = "--shading pbr --environment " + (dir / "dim.hdr");
    json render0 = {{"camera", {{"pitch", 35}}}};
    json lit = render0, shadowed = render0;
    lit["key_light"] = keyLight({0, 1, -0.7}, 4.0, false);
    shadowed["key_light"] = keyLight({0, 1, -0.7}, 4.0, true);
    const Image8 a = render(dir, scene, opts, lit);
    const Image8 b = render(dir, scene, opts, shadowed);
    ASSERT_EQ(a.rgba.size(), b.rgba.size());
    const Changed c = changed(b, a, 40);
    EXPECT_GT(c.darker, 128u * 128u / 50) << "the shadow on the floor";
    EXPECT_EQ(changed(b, a, 2).brighter, 0u) << "a shadow never brightens";
    // Where: below the sphere's centre in the picture and about the middle column.
    double sx = 0.0, sy = 0.0;
    for (int y = 0; y < 128; ++y)
        for (int x = 0; x < 128; ++x) {
            const std::size_t p = (std::size_t(y) * 128 + x) * 4;
            if (peak(a, p) - peak(b, p) > 40) {
                sx += x;
                sy += y;
            }
        }
    sx /= double(c.darker);
    sy /= double(c.darker);
    EXPECT_NEAR(sx, 64.0, 10.0);
    EXPECT_GT(sy, 70.0) << "in front of the sphere, towards the camera";
}

TEST(KeyLightGLTest, ALitSurfaceKeepsItsLightWithShadowsOn) {
    TempDir dir;
    // Self-shadowing acne would darken the lit side of a lone sphere in speckles; only a band at
    // the terminator (where the lookup's softening meets the sphere's own shadow) may change.
    const std::string sphere = whiteSphereGlb(dir);
    writeUniformHdr(dir / "dim.hdr", 64, 32, glm::vec3(0.05f));
    const std::string opts = "--shading pbr --environment " + (dir / "dim.hdr");
    for (const json& direction : {json{1, 0.3, 0.3}, json{0.2, 1, 0.5}, json{-0.6, -0.2, 1}}) {
        const Image8 lit = render(dir, sphere, opts, {{"key_light", keyLight(direction, 4.0, false)}});
        const Image8 shadowed = render(dir, sphere, opts, {{"key_light", keyLight(direction, 4.0, true)}});
        const std::size_t sphereArea = foreground(lit);
        EXPECT_GT(sphereArea, 128u * 128u / 5);
        const Changed c = changed(shadowed, lit, 6);
        EXPECT_LT(c.darker, sphereArea / 25) << direction.dump() << ": " << c.darker << " of " << sphereArea;
    }
}

TEST(KeyLightGLTest, SkinWrapsTheKeyLightPastTheTerminatorInRed) {
    TempDir dir;
    // A white sphere lit from above by the key light alone (a black sky): pbr leaves the lower
    // half black; skin carries red furthest past the terminator, while the top stays white.
    const std::string sphere = whiteSphereGlb(dir);
    writeUniformHdr(dir / "black.hdr", 64, 32, glm::vec3(0.0f));
    const std::string env = " --environment " + (dir / "black.hdr");
    const json light = {{"key_light", keyLight({0, 1, 0}, 4.0, true)}};
    const Image8 pbr = render(dir, sphere, "--shading pbr" + env, light);
    const Image8 skin = render(dir, sphere, "--shading skin" + env, light);
    ASSERT_EQ(pbr.height, 128);
    // The sphere's disc below its centre; meanChannel's foreground differs from the background,
    // which a black lower half does not: count over rows of the disc by columns 50..78.
    const double pbrR = meanChannel(pbr, 0, 66, 80, 50, 78), skinR = meanChannel(skin, 0, 66, 80, 50, 78);
    const double skinB = meanChannel(skin, 2, 66, 80, 50, 78);
    EXPECT_GT(skinR - skinB, 6.0) << "skin: R " << skinR << ", B " << skinB;
    EXPECT_GT(skinR, pbrR + 6.0);
    const double topR = meanChannel(skin, 0, 20, 40), topB = meanChannel(skin, 2, 20, 40);
    EXPECT_GT(topB, 100.0);
    EXPECT_LT(std::abs(topR - topB), 0.1 * topB) << "top R " << topR << ", B " << topB;
}

TEST(KeyLightGLTest, ACharacterCastsShadowsVertexAndTessellated) {
    TempDir dir;
    // The Barbarian (props, a palette texture) lit from its right: with shadows its props and
    // hat darken what lies behind them, in both skin programs and both displacement modes.
    const std::string barbarian = std::string(dermis::build::testModelsDir()) + "/KayKitBarbarian/Barbarian.glb";
    for (const char* shading : {"pbr", "skin"})
        for (const char* displacement : {"vertex", "tessellated"}) {
            // (No tone mapping: PBR Neutral's toe subtracts the darkest channel, so a darker red
            // may brighten blue; a clamp keeps every channel monotonic.)
            json lit = {{"displacement", displacement}, {"tone_mapping", "none"},
                        {"key_light", keyLight({1, 0.6, 0.4}, 4.0, false)}};
            json shadowed = lit;
            shadowed["key_light"]["shadow"] = true;
            const std::string opts = std::string("--shading ") + shading;
            const Image8 a = render(dir, barbarian, opts, lit);
            const Image8 b = render(dir, barbarian, opts, shadowed);
            ASSERT_EQ(a.rgba.size(), b.rgba.size()) << shading << " " << displacement;
            const Changed c = changed(b, a, 20);
            EXPECT_GT(c.darker, foreground(a) / 50) << shading << " " << displacement;
            EXPECT_EQ(changed(b, a, 2).brighter, 0u) << shading << " " << displacement;
        }
}

TEST(KeyLightGLTest, TheCommandLineSetsAndRemovesTheLight) {
    TempDir dir;
    // --key-light X,Y,Z[,INTENSITY] and --no-shadows draw what the scene member draws; --key-light
    // off removes the scene's; bad values exit 1 naming the option.
    const std::string sphere = whiteSphereGlb(dir);
    writeUniformHdr(dir / "dim.hdr", 64, 32, glm::vec3(0.05f));
    const std::string opts = "--shading pbr --environment " + (dir / "dim.hdr");
    const Image8 member = render(dir, sphere, opts, {{"key_light", keyLight({1, 0, 0.3}, 4.0, false)}});
    const Image8 option = render(dir, sphere, opts + " --key-light 1,0,0.3,4 --no-shadows");
    EXPECT_EQ(member.rgba, option.rgba);
    const Image8 none = render(dir, sphere, opts);
    const Image8 off = render(dir, sphere, opts + " --key-light off", {{"key_light", keyLight({1, 0, 0.3}, 4.0, true)}});
    EXPECT_EQ(none.rgba, off.rgba);
    writeText(dir / "s.json", json({{"format", "dermis.scene/1"}, {"model", sphere}}).dump());
    for (const char* bad : {"1,2", "0,0,0", "1,1,1,-2", "up"}) {
        CliRun r = runServer(dir, "render --scene " + (dir / "s.json") + " --out " + (dir / "x.png") +
                                      " --key-light " + bad + gl());
        EXPECT_EQ(r.code, 1) << bad << ": " << r.err;
        EXPECT_NE(r.err.find("--key-light"), std::string::npos) << bad << ": " << r.err;
    }
}
