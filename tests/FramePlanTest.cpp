// FramePlanTest — the one path from a scene to a frame (core planFrame) and the one check of
// render settings (core validateRenderSettings). Pure: a small hand-built rig, no files.
#include "core/bake.hpp"
#include "core/frame_plan.hpp"
#include "core/render_settings.hpp"

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include <cmath>

using namespace dermis;

namespace {

/// Two joints (root → elbow) and one UV-mapped triangle skinned to both.
Model tinyModel() {
    Model m;
    m.nodes.push_back({"root", -1, glm::vec3(0.0f), glm::quat(1, 0, 0, 0), glm::vec3(1.0f)});
    m.nodes.push_back({"group", 0, glm::vec3(0.0f), glm::quat(1, 0, 0, 0), glm::vec3(1.0f)});
    m.nodes.push_back({"elbow", 1, glm::vec3(0, 1, 0), glm::quat(1, 0, 0, 0), glm::vec3(1.0f)});
    m.joints = {0, 2};
    MeshPart p;
    p.positions = {{0, 0, 0}, {1, 0, 0}, {0, 2, 0}};
    p.uvs = {{0, 0}, {1, 0}, {0, 1}};
    p.joints = {glm::u16vec4(0), glm::u16vec4(0), glm::u16vec4(1, 0, 0, 0)};
    p.weights = {glm::vec4(1, 0, 0, 0), glm::vec4(1, 0, 0, 0), glm::vec4(1, 0, 0, 0)};
    p.indices = {0, 1, 2};
    p.influences = {{0, glm::mat4(1.0f)}, {2, glm::inverse(glm::translate(glm::mat4(1.0f), glm::vec3(0, 1, 0)))}};
    m.parts.push_back(p);
    return m;
}

Scene tinyScene() {
    Scene s;
    s.model = "tiny";
    Placement pl;
    pl.id = "a";
    pl.pattern = "bumps";
    pl.joint = "elbow";
    pl.thetaMin = 0;
    pl.thetaMax = 90;
    s.placements.push_back(pl);
    JointPose jp;
    jp.axisAngles = std::array<double, 3>{45.0, 0.0, 0.0};
    s.pose.joints["elbow"] = jp;
    s.heightmapSize = {32, 16};
    s.render.size = {200, 100};
    return s;
}

PatternImages tinyImages() {
    PatternImages images;
    images["bumps"] = makePatternImage(HeightImage(4, 4, 0.5f));
    return images;
}

TEST(FramePlanTest, PlansPoseHeightsAndSettings) {
    const Model m = tinyModel();
    const PatternImages images = tinyImages();
    auto plan = planFrame(tinyScene(), m, images, nullptr);
    ASSERT_TRUE(plan) << plan.error().message;
    EXPECT_EQ(plan->world.size(), m.nodes.size());
    ASSERT_EQ(plan->heights.placements.size(), 1u);
    const BakePlacement& b = plan->heights.placements[0];
    EXPECT_EQ(b.pattern, &images.at("bumps")->pixels);
    EXPECT_EQ(b.patternId, images.at("bumps")->contentId);
    EXPECT_NEAR(b.t, 0.5, 1e-4); // 45° of [0, 90]
    EXPECT_EQ(plan->heights.width, 32);
    EXPECT_EQ(plan->heights.height, 16);
    EXPECT_EQ(plan->render.size, (std::array<int, 2>{200, 100}));
}

TEST(FramePlanTest, DisabledPlacementsAreCheckedButContributeNothing) {
    const Model m = tinyModel();
    const PatternImages images = tinyImages();
    Scene s = tinyScene();
    Placement off = s.placements[0];
    off.id = "b";
    off.enabled = false;
    off.h = 5.0;
    s.placements.push_back(off);
    auto plan = planFrame(s, m, images, nullptr);
    ASSERT_TRUE(plan) << plan.error().message;
    ASSERT_EQ(plan->heights.placements.size(), 1u);
    EXPECT_EQ(plan->heights.placements[0].h, 1.0);
    auto with = bakeHeightMaps(plan->heights, 1);
    s.placements.pop_back();
    auto without = bakeScene(s, m, images);
    ASSERT_TRUE(with && without);
    EXPECT_EQ(with->bump.data, without->bump.data);
    // A disabled placement must still be valid: an unknown joint fails naming it.
    off.joint = "nope";
    s.placements.push_back(off);
    auto bad = planFrame(s, m, images, nullptr);
    ASSERT_FALSE(bad);
    EXPECT_EQ(bad.error().field, "/placements/1/joint");
}

TEST(FramePlanTest, KeepsItsImagesAlive) {
    const Model m = tinyModel();
    PatternImages images = tinyImages();
    auto base = makePatternImage(HeightImage(8, 8, 0.25f));
    const std::uint64_t baseId = base->contentId;
    auto plan = planFrame(tinyScene(), m, images, base);
    ASSERT_TRUE(plan);
    images.clear(); // the owner lets go (a pattern deleted during a render)
    base.reset();
    EXPECT_EQ(plan->heights.placements[0].pattern->at(1, 1), 0.5f);
    ASSERT_NE(plan->heights.base, nullptr);
    EXPECT_EQ(plan->heights.base->at(0, 0), 0.25f);
    EXPECT_EQ(plan->heights.baseId, baseId);
    auto maps = bakeHeightMaps(plan->heights, 1);
    ASSERT_TRUE(maps);
    EXPECT_EQ(maps->bump.width, 32);
}

TEST(FramePlanTest, OverridesApplyBeforeTheOneCheck) {
    const Model m = tinyModel();
    const PatternImages images = tinyImages();
    FrameOverrides o;
    o.width = 64;
    o.msaa = 1;
    o.yaw = 30.0;
    auto plan = planFrame(tinyScene(), m, images, nullptr, o);
    ASSERT_TRUE(plan);
    EXPECT_EQ(plan->render.size, (std::array<int, 2>{64, 100}));
    EXPECT_EQ(plan->render.msaa, 1);
    EXPECT_EQ(plan->render.camera.yaw, 30.0);

    RenderLimits limits;
    limits.maxSide = 128;
    o = {};
    auto tooWide = planFrame(tinyScene(), m, images, nullptr, o, limits); // the scene's 200
    ASSERT_FALSE(tooWide);
    EXPECT_EQ(tooWide.error().code, ErrorCode::TooLarge);
    EXPECT_EQ(tooWide.error().field, "/render/size/0");
    o.width = 100;
    EXPECT_TRUE(planFrame(tinyScene(), m, images, nullptr, o, limits));
    o.msaa = 3;
    EXPECT_EQ(planFrame(tinyScene(), m, images, nullptr, o).error().field, "/render/msaa");
    o = {};
    o.time = -1.0;
    EXPECT_EQ(planFrame(tinyScene(), m, images, nullptr, o).error().field, "/pose/time");
    o.time = std::nan("");
    EXPECT_EQ(planFrame(tinyScene(), m, images, nullptr, o).error().field, "/pose/time");
}

TEST(FramePlanTest, FailsWithTheSceneFieldNamed) {
    const Model m = tinyModel();
    Scene s = tinyScene();
    s.placements[0].joint = "knee";
    EXPECT_EQ(planFrame(s, m, tinyImages(), nullptr).error().field, "/placements/0/joint");
    s = tinyScene();
    s.pose.animation = "walk";
    EXPECT_EQ(planFrame(s, m, tinyImages(), nullptr).error().field, "/pose/animation");
    s = tinyScene();
    EXPECT_EQ(planFrame(s, m, PatternImages{}, nullptr).error().field, "/placements/0/pattern");
    Model noUv = tinyModel();
    noUv.parts[0].uvs.clear();
    EXPECT_EQ(planFrame(tinyScene(), noUv, tinyImages(), nullptr).error().field, "/placements/0");
}

TEST(RenderSettingsTest, EveryRangeIsCheckedWithItsField) {
    EXPECT_TRUE(validateRenderSettings(RenderSettings{}));
    const struct {
        void (*change)(RenderSettings&);
        const char* field;
        ErrorCode code;
    } cases[] = {
        {[](RenderSettings& r) { r.size[0] = 0; }, "/render/size/0", ErrorCode::InvalidArgument},
        {[](RenderSettings& r) { r.size[1] = kMaxRenderSize + 1; }, "/render/size/1", ErrorCode::InvalidArgument},
        {[](RenderSettings& r) { r.camera.yaw = INFINITY; }, "/render/camera/yaw", ErrorCode::InvalidArgument},
        {[](RenderSettings& r) { r.camera.pitch = 90.5; }, "/render/camera/pitch", ErrorCode::InvalidArgument},
        {[](RenderSettings& r) { r.camera.pitch = NAN; }, "/render/camera/pitch", ErrorCode::InvalidArgument},
        {[](RenderSettings& r) { r.camera.distance = 0.0; }, "/render/camera/distance", ErrorCode::InvalidArgument},
        {[](RenderSettings& r) { r.camera.target = std::array<double, 3>{0.0, NAN, 0.0}; }, "/render/camera/target", ErrorCode::InvalidArgument},
        {[](RenderSettings& r) { r.camera.target = std::array<double, 3>{2e6, 0.0, 0.0}; }, "/render/camera/target", ErrorCode::InvalidArgument},
        {[](RenderSettings& r) { r.displacementScale = -0.1; }, "/render/displacement_scale", ErrorCode::InvalidArgument},
        {[](RenderSettings& r) { r.bumpStrength = NAN; }, "/render/bump_strength", ErrorCode::InvalidArgument},
        {[](RenderSettings& r) { r.msaa = 8; }, "/render/msaa", ErrorCode::InvalidArgument},
    };
    for (const auto& c : cases) {
        RenderSettings r;
        c.change(r);
        auto s = validateRenderSettings(r, {}, "test");
        ASSERT_FALSE(s) << c.field;
        EXPECT_EQ(s.error().field, c.field);
        EXPECT_EQ(s.error().code, c.code);
        EXPECT_EQ(s.error().message.rfind("test: ", 0), 0u) << s.error().message;
    }
    RenderSettings r;
    r.size = {4096, 512};
    RenderLimits limits;
    limits.maxSide = 2048;
    auto s = validateRenderSettings(r, limits);
    ASSERT_FALSE(s);
    EXPECT_EQ(s.error().code, ErrorCode::TooLarge);
    EXPECT_EQ(s.error().field, "/render/size/0");
    r.camera.pitch = -90.0;
    r.size = {1, 1};
    EXPECT_TRUE(validateRenderSettings(r, limits));
}

} // namespace
