// PickGLTest — SPEC §6 Pick against what the renderer shows: on frames of the default character
// rendered by the GL renderer, the CPU ray cast (core pickFrame) hits exactly where the frame shows
// the character and misses on the background (away from silhouette edges), and the pixel where
// the left elbow crease changes the frame most picks a UV inside that placement's footprint, with
// forearm.l among its skin weights and a suggested driver.
#include "BuildPaths.hpp"
#include "core/pick.hpp"
#include "gl/renderer.hpp"
#include "io/scene_files.hpp"

#include "GlTestBackend.hpp"

#include <gtest/gtest.h>

#include <cstdlib>

using namespace dermis;

namespace {

const std::string kSource = dermis::build::sourceDir();

using test::requestedBackend;

class PickGLTest : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        auto r = Renderer::create(requestedBackend());
        if (r) renderer_ = std::move(*r);
        else error_ = r.error().message;
        auto l = loadSceneFile(kSource + "/models/default.scene.json");
        if (l) loaded_ = std::make_unique<LoadedScene>(std::move(*l));
        else error_ += l.error().message;
    }
    static void TearDownTestSuite() {
        renderer_.reset();
        loaded_.reset();
    }
    void SetUp() override { ASSERT_TRUE(renderer_ && loaded_) << error_; }

    struct Shot {
        FramePlan plan;
        Image8 image;
    };
    static Shot shoot(const Scene& scene, double yaw) {
        FrameOverrides o;
        o.width = 192;
        o.height = 192;
        o.msaa = 1;
        o.yaw = yaw;
        auto plan = planFrame(scene, loaded_->model, loaded_->images, loaded_->base, o);
        EXPECT_TRUE(plan) << plan.error().message;
        auto model = std::make_shared<const Model>(loaded_->model);
        auto frame = renderer_->renderFrame(frameRequest(*plan, model));
        EXPECT_TRUE(frame) << frame.error().message;
        return {std::move(*plan), frame ? frame->image : Image8{}};
    }
    static const std::uint8_t* px(const Image8& img, int x, int y) {
        return &img.rgba[(static_cast<std::size_t>(y) * img.width + x) * 4];
    }
    static int diff(const std::uint8_t* a, const std::uint8_t* b) {
        return std::abs(a[0] - b[0]) + std::abs(a[1] - b[1]) + std::abs(a[2] - b[2]);
    }

    static inline std::unique_ptr<Renderer> renderer_;
    static inline std::unique_ptr<LoadedScene> loaded_;
    static inline std::string error_;
};

TEST_F(PickGLTest, HitsWhereTheFrameShowsTheCharacter) {
    for (double yaw : {0.0, 120.0}) {
        const Shot s = shoot(loaded_->scene, yaw);
        const Image8& img = s.image;
        ASSERT_EQ(img.width, 192);
        const std::uint8_t* bg = px(img, 0, 0);
        auto isCharacter = [&](int x, int y) { return diff(px(img, x, y), bg) > 12; };
        int tested = 0, hits = 0, mismatches = 0;
        for (int y = 2; y < 190; y += 4)
            for (int x = 2; x < 190; x += 4) {
                const bool c = isCharacter(x, y);
                bool uniform = true; // skip silhouette edges: displacement may move them a pixel
                for (int dy = -2; dy <= 2; ++dy)
                    for (int dx = -2; dx <= 2; ++dx) uniform = uniform && isCharacter(x + dx, y + dy) == c;
                if (!uniform) continue;
                auto hit = pickFrame(s.plan, loaded_->model, x + 0.5, y + 0.5);
                ASSERT_TRUE(hit) << hit.error().message;
                ++tested;
                hits += hit->has_value();
                if (hit->has_value() != c) ++mismatches;
            }
        EXPECT_GT(hits, 100) << "yaw " << yaw;
        EXPECT_GT(tested - hits, 100) << "yaw " << yaw;
        EXPECT_EQ(mismatches, 0) << "of " << tested << " pixels at yaw " << yaw;
    }
    const Shot s = shoot(loaded_->scene, 0.0);
    auto outside = pickFrame(s.plan, loaded_->model, 192.0, 10.0);
    ASSERT_FALSE(outside);
    EXPECT_EQ(outside.error().field, "x");
    EXPECT_FALSE(pickFrame(s.plan, loaded_->model, 10.0, -1.0));
}

TEST_F(PickGLTest, TheElbowCreasePixelPicksTheElbowFootprint) {
    Scene on = loaded_->scene;
    on.placements.clear();
    for (const Placement& p : loaded_->scene.placements)
        if (p.id == "elbow_l") on.placements.push_back(p);
    ASSERT_EQ(on.placements.size(), 1u);
    on.pose.animation = "elbow_curl";
    on.pose.joints.clear();
    const Placement& elbow = on.placements[0];
    Footprint fp;
    fp.center = {elbow.center[0], elbow.center[1]};
    fp.scale = {elbow.scale[0], elbow.scale[1]};
    fp.rotationDeg = elbow.rotation;

    bool found = false;
    // Half bent, the inner elbow faces the camera from some side; fully bent, the forearm hides it.
    for (double time : {0.4, 0.25, 0.6}) {
    for (double yaw : {0.0, 30.0, -30.0, 60.0, 90.0, -60.0, -90.0}) {
        on.pose.time = time;
        Scene off = on;
        off.placements[0].enabled = false;
        const Shot a = shoot(on, yaw), b = shoot(off, yaw);
        int bestX = -1, bestY = -1, best = 0;
        for (int y = 0; y < 192; ++y)
            for (int x = 0; x < 192; ++x)
                if (int d = diff(px(a.image, x, y), px(b.image, x, y)); d > best) {
                    best = d;
                    bestX = x;
                    bestY = y;
                }
        if (best < 24) continue; // the crease does not show from here
        auto hit = pickFrame(a.plan, loaded_->model, bestX + 0.5, bestY + 0.5);
        ASSERT_TRUE(hit) << hit.error().message;
        ASSERT_TRUE(hit->has_value()) << "the crease pixel (" << bestX << ", " << bestY
                                      << ") at yaw " << yaw << " picks the background";
        const glm::dvec2 s = fp.toPattern(glm::dvec2((*hit)->uv));
        EXPECT_TRUE(s.x >= 0 && s.x <= 1 && s.y >= 0 && s.y <= 1)
            << "yaw " << yaw << ": uv (" << (*hit)->uv.x << ", " << (*hit)->uv.y
            << ") is outside the elbow footprint (pattern coords " << s.x << ", " << s.y << ")";
        bool forearm = false;
        for (auto [node, w] : (*hit)->joints)
            forearm = forearm || (loaded_->model.nodes[static_cast<std::size_t>(node)].name == "forearm.l" && w > 0.05f);
        EXPECT_TRUE(forearm) << "yaw " << yaw;
        const SuggestedDriver d = suggestDriver(loaded_->model, (*hit)->joints);
        EXPECT_FALSE(d.joint.empty());
        EXPECT_NE(d.thetaMin, d.thetaMax);
        found = true;
        break;
    }
    if (found) break;
    }
    EXPECT_TRUE(found) << "the left elbow crease shows from none of the yaws tried";
}

} // namespace
