// AntiAliasingTest — `render.aa` in the core (pure, no GL): the post-process edge pass
// (antiAliasEdges) on synthetic edges against a supersampled truth, SSIM, the one place `auto`
// becomes a mode (resolveAntiAliasing), the scene field and the frame overrides.
#include "core/edge_aa.hpp"
#include "core/frame_plan.hpp"
#include "core/image_similarity.hpp"
#include "core/render_settings.hpp"
#include "core/scene.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <functional>

using namespace dermis;

namespace {

/// A w×h frame of `inside` colour where f(x, y) > 0 (pixel centres at x + 0.5) and a dark
/// background elsewhere, with `samples`² samples per pixel averaged (1: aliased, like a
/// 1-sample raster).
Image8 raster(int w, int h, int samples, const std::function<double(double, double)>& f) {
    Image8 img;
    img.width = w;
    img.height = h;
    img.rgba.resize(static_cast<std::size_t>(w) * h * 4);
    const double inside[3] = {230, 200, 170}, outside[3] = {12, 14, 17};
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            double cover = 0.0;
            for (int sy = 0; sy < samples; ++sy)
                for (int sx = 0; sx < samples; ++sx)
                    cover += f(x + (sx + 0.5) / samples, y + (sy + 0.5) / samples) > 0.0 ? 1.0 : 0.0;
            cover /= samples * samples;
            std::uint8_t* p = &img.rgba[(static_cast<std::size_t>(y) * w + x) * 4];
            for (int c = 0; c < 3; ++c)
                p[c] = static_cast<std::uint8_t>(std::lround(outside[c] + (inside[c] - outside[c]) * cover));
            p[3] = 255;
        }
    return img;
}

/// A disc and a slanted half-plane: edges at every angle and a near-horizontal one.
double shapes(double x, double y) {
    const double disc = 30.0 - std::hypot(x - 48.0, y - 48.0);
    const double plane = (y - 100.0) - 0.2 * (x - 10.0);
    return std::max(disc, plane);
}

double meanAbs(const Image8& a, const Image8& b) {
    double s = 0.0;
    for (std::size_t i = 0; i < a.rgba.size(); ++i) s += std::abs(int(a.rgba[i]) - int(b.rgba[i]));
    return s / static_cast<double>(a.rgba.size());
}

} // namespace

TEST(AntiAliasingTest, TheEdgePassBringsAnAliasedFrameCloserToTheSupersampledTruth) {
    const Image8 truth = raster(128, 128, 8, shapes);
    const Image8 aliased = raster(128, 128, 1, shapes);
    Image8 post = aliased;
    antiAliasEdges(post);
    const double before = *ssim(aliased, truth), after = *ssim(post, truth);
    EXPECT_GT(after, before + 0.005) << "aliased " << before << ", post " << after;
    EXPECT_LT(meanAbs(post, truth), meanAbs(aliased, truth));
    // Pixels far from every edge are untouched, alpha everywhere.
    std::size_t changed = 0;
    for (int y = 0; y < 128; ++y)
        for (int x = 0; x < 128; ++x) {
            const std::size_t i = (static_cast<std::size_t>(y) * 128 + x) * 4;
            EXPECT_EQ(post.rgba[i + 3], 255);
            const bool differs = post.rgba[i] != aliased.rgba[i] || post.rgba[i + 1] != aliased.rgba[i + 1] ||
                                 post.rgba[i + 2] != aliased.rgba[i + 2];
            changed += differs;
            if (differs) {
                // The nearest edge lies within 2 pixels of every changed pixel.
                bool nearEdge = false;
                for (int dy = -2; dy <= 2 && !nearEdge; ++dy)
                    for (int dx = -2; dx <= 2 && !nearEdge; ++dx)
                        nearEdge = (shapes(x + 0.5, y + 0.5) > 0) != (shapes(x + dx + 0.5, y + dy + 0.5) > 0);
                EXPECT_TRUE(nearEdge) << "pixel " << x << "," << y << " changed away from any edge";
            }
        }
    EXPECT_GT(changed, 100u);
}

TEST(AntiAliasingTest, TheEdgePassLeavesFlatImagesAndTinyOnesAlone) {
    Image8 flat = raster(64, 64, 1, [](double, double) { return -1.0; });
    const Image8 before = flat;
    antiAliasEdges(flat);
    EXPECT_EQ(flat.rgba, before.rgba);
    // A gentle gradient (below FXAA's contrast threshold) is not an edge either.
    Image8 ramp = flat;
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x)
            for (int c = 0; c < 3; ++c) ramp.rgba[(static_cast<std::size_t>(y) * 64 + x) * 4 + c] = static_cast<std::uint8_t>(60 + x);
    const Image8 rampBefore = ramp;
    antiAliasEdges(ramp);
    EXPECT_EQ(ramp.rgba, rampBefore.rgba);
    Image8 tiny = raster(2, 5, 1, shapes);
    const Image8 tinyBefore = tiny;
    antiAliasEdges(tiny);
    EXPECT_EQ(tiny.rgba, tinyBefore.rgba);
    Image8 broken = raster(16, 16, 1, shapes);
    broken.rgba.resize(10);
    antiAliasEdges(broken); // a buffer that does not match its size: left alone, no crash
    EXPECT_EQ(broken.rgba.size(), 10u);
}

TEST(AntiAliasingTest, TheEdgePassDoesNotDependOnTheThreadCount) {
    const Image8 aliased = raster(300, 257, 1, shapes);
    Image8 one = aliased, two = aliased, five = aliased;
    antiAliasEdges(one, 1);
    antiAliasEdges(two, 2);
    antiAliasEdges(five, 5);
    EXPECT_NE(one.rgba, aliased.rgba);
    EXPECT_EQ(one.rgba, two.rgba);
    EXPECT_EQ(one.rgba, five.rgba);
}

// The pass looks for edges only where the luma differs from the corner's (the background of a
// rendered frame) in a row or the rows beside it: elsewhere a pixel and its neighbours are flat.
// Exact: with the corner pixel changed — so that nearly every pixel differs from its luma and
// every row is searched whole — the result away from that corner is the same.
TEST(AntiAliasingTest, SkippingTheFlatBackgroundChangesNoPixel) {
    const Image8 aliased = raster(300, 257, 1, shapes);
    Image8 skipping = aliased, whole = aliased;
    whole.rgba[0] = 250; // pixel (0, 0): another luma than the background's
    antiAliasEdges(skipping, 2);
    antiAliasEdges(whole, 2);
    EXPECT_NE(skipping.rgba, aliased.rgba);
    int compared = 0;
    for (int y = 32; y < aliased.height; ++y)
        for (int x = 32; x < aliased.width; ++x)
            for (int c = 0; c < 4; ++c, ++compared) {
                const std::size_t i = (static_cast<std::size_t>(y) * aliased.width + x) * 4 + c;
                ASSERT_EQ(skipping.rgba[i], whole.rgba[i]) << "pixel " << x << "," << y;
            }
    EXPECT_GT(compared, 200000);
}

TEST(AntiAliasingTest, SsimIsOneForTheSameImageLowerForOthersAndChecksSizes) {
    const Image8 a = raster(64, 64, 1, shapes);
    const Image8 b = raster(64, 64, 4, shapes);
    EXPECT_DOUBLE_EQ(*ssim(a, a), 1.0);
    const double ab = *ssim(a, b);
    EXPECT_LT(ab, 1.0);
    EXPECT_GT(ab, 0.5);
    EXPECT_DOUBLE_EQ(ab, *ssim(b, a));
    const Image8 moved = raster(64, 64, 1, [](double x, double y) { return shapes(x + 9, y); });
    EXPECT_LT(*ssim(a, moved), ab);
    const auto wrong = ssim(a, raster(32, 64, 1, shapes));
    ASSERT_FALSE(wrong);
    EXPECT_EQ(wrong.error().field, "b");
    EXPECT_FALSE(ssim(raster(4, 4, 1, shapes), raster(4, 4, 1, shapes)));
}

TEST(AntiAliasingTest, BoxDownsampleAveragesBlocks) {
    Image8 img;
    img.width = 5;
    img.height = 4;
    img.rgba.assign(5 * 4 * 4, 0);
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 5; ++x) img.rgba[(static_cast<std::size_t>(y) * 5 + x) * 4] = static_cast<std::uint8_t>(10 * x + y);
    auto half = boxDownsample(img, 2);
    ASSERT_TRUE(half);
    EXPECT_EQ(half->width, 2); // the fifth column is not a whole block
    EXPECT_EQ(half->height, 2);
    EXPECT_EQ(half->rgba[0], 6);  // (0 + 1 + 10 + 11) / 4 = 5.5 → 6
    EXPECT_EQ(half->rgba[4], 26); // (20 + 21 + 30 + 31) / 4 = 25.5 → 26
    EXPECT_EQ(half->rgba[8], 8);  // (2 + 3 + 12 + 13) / 4
    EXPECT_EQ(boxDownsample(img, 1)->rgba, img.rgba);
    EXPECT_FALSE(boxDownsample(img, 0));
    EXPECT_FALSE(boxDownsample(img, 5));
}

TEST(AntiAliasingTest, AutoIsPostOnSoftwareRasterizersAndMsaaElsewhere) {
    RenderSettings rs;
    EXPECT_EQ(rs.aa, AntiAliasing::Auto);
    auto r = resolveAntiAliasing(rs, true, 8);
    EXPECT_EQ(r.mode, AntiAliasing::Post);
    EXPECT_EQ(r.samples, 1);
    EXPECT_EQ(r.label(), "post");
    r = resolveAntiAliasing(rs, false, 8);
    EXPECT_EQ(r.mode, AntiAliasing::Msaa);
    EXPECT_EQ(r.samples, 4);
    EXPECT_EQ(r.label(), "msaa4");
    rs.aa = AntiAliasing::Msaa;
    EXPECT_EQ(resolveAntiAliasing(rs, true, 8).label(), "msaa4"); // always selectable
    EXPECT_EQ(resolveAntiAliasing(rs, false, 2).samples, 2);      // the GL's limit
    EXPECT_EQ(resolveAntiAliasing(rs, false, 0).samples, 1);
    rs.msaa = 1;
    EXPECT_EQ(resolveAntiAliasing(rs, false, 8).label(), "none");
    rs.aa = AntiAliasing::None;
    rs.msaa = 4;
    EXPECT_EQ(resolveAntiAliasing(rs, false, 8).samples, 1);
    EXPECT_EQ(resolveAntiAliasing(rs, false, 8).label(), "none");
    rs.aa = AntiAliasing::Post;
    EXPECT_EQ(resolveAntiAliasing(rs, false, 8).label(), "post"); // on a GPU when asked
}

TEST(AntiAliasingTest, TheSceneFieldParsesRoundTripsAndNamesItsErrors) {
    for (const char* name : {"auto", "msaa", "post", "none"}) {
        auto a = antiAliasingFromString(name);
        ASSERT_TRUE(a) << name;
        EXPECT_EQ(toString(*a), name);
    }
    EXPECT_FALSE(antiAliasingFromString("fxaa"));
    EXPECT_FALSE(antiAliasingFromString("Post"));
    const PatternManifest manifest;
    auto s = parseSceneText(R"({"format":"dermis.scene/1","render":{"aa":"post","msaa":2}})", manifest);
    ASSERT_TRUE(s) << s.error().message;
    EXPECT_EQ(s->render.aa, AntiAliasing::Post);
    const nlohmann::json doc = toJson(*s);
    EXPECT_EQ(doc["render"]["aa"], "post");
    EXPECT_EQ(doc["render"]["msaa"], 2);
    auto old = parseSceneText(R"({"format":"dermis.scene/1"})", manifest); // documents before aa
    ASSERT_TRUE(old);
    EXPECT_EQ(old->render.aa, AntiAliasing::Auto);
    auto bad = parseSceneText(R"({"format":"dermis.scene/1","render":{"aa":"fxaa"}})", manifest);
    ASSERT_FALSE(bad);
    EXPECT_EQ(bad.error().field, "/render/aa");
    EXPECT_NE(bad.error().message.find("\"post\""), std::string::npos) << bad.error().message;
}

TEST(AntiAliasingTest, AnMsaaOverrideSelectsMsaaAndAnAaOverrideWins) {
    Model model;
    model.nodes.push_back({"root", -1, glm::vec3(0.0f), glm::quat(1, 0, 0, 0), glm::vec3(1.0f)});
    model.joints = {0};
    Scene scene;
    scene.render.size = {64, 64};
    const PatternImages images;
    FrameOverrides o;
    auto plan = planFrame(scene, model, images, nullptr, o);
    ASSERT_TRUE(plan) << plan.error().message;
    EXPECT_EQ(plan->render.aa, AntiAliasing::Auto);
    o.msaa = 1; // the editor's quick frames while dragging, `--msaa 1`: no anti-aliasing
    plan = planFrame(scene, model, images, nullptr, o);
    ASSERT_TRUE(plan);
    EXPECT_EQ(plan->render.aa, AntiAliasing::Msaa);
    EXPECT_EQ(resolveAntiAliasing(plan->render, true, 8).label(), "none");
    o.aa = AntiAliasing::Post;
    plan = planFrame(scene, model, images, nullptr, o);
    ASSERT_TRUE(plan);
    EXPECT_EQ(plan->render.aa, AntiAliasing::Post);
}
