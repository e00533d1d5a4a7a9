// DefaultCharacterGLTest — frames of the built-in character's default scene on a real GL context
// (Mesa's llvmpipe in CI; the backend from $DERMIS_TEST_GL, as RendererGLTest): reference images
// in three poses (MSAA 4x on every GL), CPU and GPU height maps give the same frame, deformation
// changes it, MSAA levels and tessellation, frame options validated, outlines on the footprint
// border, the camera target, the skipped height pass and the maps read back. A backend that
// cannot start fails the suite: nothing is skipped.
#include "BuildPaths.hpp"
#include "ImageCompare.hpp"
#include "RendererSuite.hpp"
#include "SceneFrame.hpp"
#include "core/bake.hpp"
#include "gl/renderer.hpp"
#include "io/scene_files.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <map>
#include <memory>
#include <string>
#include <vector>

using namespace dermis;
using namespace dermis::test;

namespace {

const std::string kSource = dermis::build::sourceDir();

/// The default scene with the pose, size and MSAA of a test.
Result<FrameResult> renderDefault(Renderer& gl, const LoadedScene& loaded,
                                  const std::shared_ptr<const Model>& model, const Pose& pose,
                                  RenderSettings render, bool cpuMaps = false) {
    Scene scene = loaded.scene;
    scene.pose = pose;
    scene.render = render;
    SceneFrameOptions opt;
    opt.cpuHeightMaps = cpuMaps;
    auto frame = makeSceneFrame(scene, model, loaded.images, nullptr, opt);
    if (!frame) return frame.error();
    return gl.renderFrame(frame->request);
}

class DefaultCharacterGLTest : public RendererSuite {
protected:
    void SetUp() override {
        RendererSuite::SetUp();
        auto l = loadSceneFile(kSource + "/models/default.scene.json");
        ASSERT_TRUE(l) << l.error().message;
        loaded_ = std::make_unique<LoadedScene>(std::move(*l));
        model_ = std::make_shared<const Model>(loaded_->model);
        settings_.size = {256, 256};
        settings_.aa = AntiAliasing::Msaa; // the references are MSAA 4x frames on every GL
    }
    static Pose pose(const std::string& clip, double time) {
        Pose p;
        p.animation = clip;
        p.time = time;
        return p;
    }
    std::unique_ptr<LoadedScene> loaded_;
    std::shared_ptr<const Model> model_;
    RenderSettings settings_;
};

TEST_F(DefaultCharacterGLTest, MatchesReferenceImagesInThreePoses) {
    struct Case {
        const char* name;
        const char* clip;
        double time, yaw, pitch;
    };
    const Case cases[] = {{"default_rest", "squat", 0.0, 0.0, 10.0},
                          {"default_squat", "squat", 1.25, 20.0, 10.0},
                          {"default_elbow_curl", "elbow_curl", 1.0, -35.0, 5.0}};
    std::vector<Image8> frames;
    for (const Case& c : cases) {
        RenderSettings rs = settings_;
        rs.camera.yaw = c.yaw;
        rs.camera.pitch = c.pitch;
        auto r = renderDefault(gl(), *loaded_, model_, pose(c.clip, c.time), rs);
        ASSERT_TRUE(r) << r.error().message;
        EXPECT_TRUE(compareWithReference(r->image, kSource + "/tests/reference/" + c.name + ".png"));
        frames.push_back(std::move(r->image));
    }
    // The tolerance still tells poses apart: the squat is not the rest pose.
    const char* update = std::getenv("DERMIS_UPDATE_REFERENCES");
    if (!update || std::string(update) != "1")
        EXPECT_FALSE(compareWithReference(frames[1], kSource + "/tests/reference/default_rest.png"));
}

TEST_F(DefaultCharacterGLTest, CpuAndGpuHeightMapsGiveTheSameFrame) {
    auto gpu = renderDefault(gl(), *loaded_, model_, pose("squat", 1.25), settings_, false);
    auto cpu = renderDefault(gl(), *loaded_, model_, pose("squat", 1.25), settings_, true);
    ASSERT_TRUE(gpu) << gpu.error().message;
    ASSERT_TRUE(cpu) << cpu.error().message;
    EXPECT_LT(meanAbsDiff(gpu->image, cpu->image), 0.05);
}

TEST_F(DefaultCharacterGLTest, DeformationChangesTheFrame) {
    // The same pose with strong displacement and bump mapping, and with neither: the bulges
    // change the silhouette (coverage) and the shading.
    RenderSettings strong = settings_;
    strong.displacementScale = 0.05;
    RenderSettings none = settings_;
    none.displacementScale = 0.0;
    none.bumpStrength = 0.0;
    auto a = renderDefault(gl(), *loaded_, model_, pose("elbow_curl", 1.0), strong);
    auto b = renderDefault(gl(), *loaded_, model_, pose("elbow_curl", 1.0), none);
    ASSERT_TRUE(a && b);
    EXPECT_GT(meanAbsDiff(a->image, b->image), 0.1);
    EXPECT_NE(coverage(a->image), coverage(b->image));
}

TEST_F(DefaultCharacterGLTest, MsaaLevelsAndTessellationRender) {
    std::map<int, Image8> byMsaa;
    for (int msaa : {1, 2, 4}) {
        RenderSettings rs = settings_;
        rs.msaa = msaa;
        auto r = renderDefault(gl(), *loaded_, model_, pose("squat", 1.25), rs);
        ASSERT_TRUE(r) << "msaa " << msaa << ": " << r.error().message;
        EXPECT_GT(coverage(r->image), 0.05);
        byMsaa[msaa] = std::move(r->image);
    }
    const double d14 = meanAbsDiff(byMsaa[1], byMsaa[4]);
    EXPECT_GT(d14, 0.0) << "4x MSAA should smooth edges";
    EXPECT_LT(d14, 3.0) << "…without changing the picture";

    RenderSettings tess = settings_;
    tess.displacement = DisplacementMode::Tessellated;
    auto t = renderDefault(gl(), *loaded_, model_, pose("squat", 1.25), tess);
    ASSERT_TRUE(t) << t.error().message;
    EXPECT_GT(coverage(t->image), 0.05);
    const double dt = meanAbsDiff(t->image, byMsaa[4]);
    EXPECT_LT(dt, 4.0) << "tessellation refines, it does not change the character";
    // Without displacement, tessellating the same triangles gives (nearly) the same frame.
    RenderSettings tessFlat = tess, vertFlat = settings_;
    tessFlat.displacementScale = vertFlat.displacementScale = 0.0;
    auto tf = renderDefault(gl(), *loaded_, model_, pose("squat", 1.25), tessFlat);
    auto vf = renderDefault(gl(), *loaded_, model_, pose("squat", 1.25), vertFlat);
    ASSERT_TRUE(tf && vf);
    EXPECT_LT(meanAbsDiff(tf->image, vf->image), 0.5);
}

TEST_F(DefaultCharacterGLTest, FrameOptionsAreValidated) {
    RenderSettings rs = settings_;
    rs.size = {0, 10};
    auto r = renderDefault(gl(), *loaded_, model_, pose("squat", 0.5), rs);
    ASSERT_FALSE(r);
    // One check for render settings everywhere (validateRenderSettings): it names the element.
    EXPECT_EQ(r.error().field, "/render/size/0");
    rs = settings_;
    rs.msaa = 3;
    r = renderDefault(gl(), *loaded_, model_, pose("squat", 0.5), rs);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().field, "/render/msaa");
    rs = settings_;
    rs.bumpStrength = std::nan("");
    r = renderDefault(gl(), *loaded_, model_, pose("squat", 0.5), rs);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().field, "/render/bump_strength");
    FrameRequest empty;
    auto e = gl().renderFrame(empty);
    ASSERT_FALSE(e);
    // Still renders after the errors.
    auto ok = renderDefault(gl(), *loaded_, model_, pose("squat", 0.5), settings_);
    ASSERT_TRUE(ok) << ok.error().message;
}

TEST_F(DefaultCharacterGLTest, OutlinesDrawOnTheFootprintBorderAndNothingWithoutThem) {
    Scene scene = loaded_->scene;
    scene.pose = pose("squat", 1.25);
    scene.render = settings_;
    auto frame = makeSceneFrame(scene, model_, loaded_->images, nullptr);
    ASSERT_TRUE(frame) << frame.error().message;
    auto plain = gl().renderFrame(frame->request);
    ASSERT_TRUE(plain) << plain.error().message;
    const Placement& stomach = scene.placements.at(0);
    ASSERT_EQ(stomach.id, "stomach");
    FrameRequest outlined = frame->request;
    outlined.outlines.push_back({glm::vec2(stomach.center[0], stomach.center[1]),
                                 glm::vec2(stomach.scale[0], stomach.scale[1]),
                                 static_cast<float>(stomach.rotation), FrameOutline::Selected});
    auto a = gl().renderFrame(outlined);
    ASSERT_TRUE(a) << a.error().message;
    // Some pixels change, fewer than a tenth of the frame, and the band's pixels are orange.
    std::size_t changed = 0, orange = 0;
    for (std::size_t p = 0; p + 3 < a->image.rgba.size(); p += 4) {
        const auto* x = &a->image.rgba[p];
        const auto* y = &plain->image.rgba[p];
        if (x[0] == y[0] && x[1] == y[1] && x[2] == y[2]) continue;
        ++changed;
        if (x[0] > 200 && x[1] > 110 && x[1] < 200 && x[2] < 90) ++orange;
    }
    EXPECT_GT(changed, 60u);
    EXPECT_LT(changed, 256u * 256u / 10u);
    EXPECT_GT(orange, 30u) << changed;
    // The brush and hover kinds draw too, differently from the selection.
    outlined.outlines[0].kind = FrameOutline::Brush;
    auto b = gl().renderFrame(outlined);
    ASSERT_TRUE(b) << b.error().message;
    EXPECT_NE(b->image.rgba, a->image.rgba);
    EXPECT_NE(b->image.rgba, plain->image.rgba);
    // No outlines: byte for byte the frame without (the outline block is uploaded empty).
    auto again = gl().renderFrame(frame->request);
    ASSERT_TRUE(again);
    EXPECT_EQ(again->image.rgba, plain->image.rgba);
    // Bad outlines are refused.
    outlined.outlines[0].scale = glm::vec2(0.0f, 0.1f);
    EXPECT_FALSE(gl().renderFrame(outlined));
    outlined.outlines.assign(kMaxFrameOutlines + 1, FrameOutline{});
    EXPECT_FALSE(gl().renderFrame(outlined));
}

TEST_F(DefaultCharacterGLTest, ACameraTargetAtTheBoundsCentreGivesTheSameFrameAndAnotherOneMovesIt) {
    Scene scene = loaded_->scene;
    scene.pose = pose("squat", 1.25);
    scene.render = settings_;
    auto frame = makeSceneFrame(scene, model_, loaded_->images, nullptr);
    ASSERT_TRUE(frame) << frame.error().message;
    auto plain = gl().renderFrame(frame->request);
    ASSERT_TRUE(plain) << plain.error().message;
    const glm::vec3 c = plain->cameraTarget;
    EXPECT_EQ(c, 0.5f * (plain->boundsMin + plain->boundsMax));
    EXPECT_GT(plain->cameraDistance, 0.0f);
    FrameRequest at = frame->request;
    at.render.camera.target = std::array<double, 3>{c.x, c.y, c.z};
    auto same = gl().renderFrame(at);
    ASSERT_TRUE(same) << same.error().message;
    EXPECT_EQ(same->image.rgba, plain->image.rgba);
    at.render.camera.target = std::array<double, 3>{c.x, plain->boundsMax.y, c.z}; // the head
    at.render.camera.distance = 0.5 * plain->cameraDistance;
    auto head = gl().renderFrame(at);
    ASSERT_TRUE(head) << head.error().message;
    EXPECT_EQ(head->cameraTarget.y, plain->boundsMax.y);
    EXPECT_GT(meanAbsDiff(head->image, plain->image), 1.0);
}

TEST_F(DefaultCharacterGLTest, SkipsTheHeightPassWhenNoDriverChanged) {
    Scene scene = loaded_->scene;
    scene.render.size = {64, 64};
    SceneFrameOptions opt;
    opt.readHeightMaps = true;
    auto a = makeSceneFrame(scene, model_, loaded_->images, nullptr, opt);
    ASSERT_TRUE(a);
    auto first = gl().renderFrame(a->request);
    ASSERT_TRUE(first) << first.error().message;
    const auto before = gl().stats();
    // Only the camera moves: same maps, no height pass.
    scene.render.camera.yaw = 90.0;
    auto b = makeSceneFrame(scene, model_, loaded_->images, nullptr, opt);
    ASSERT_TRUE(b);
    auto second = gl().renderFrame(b->request);
    ASSERT_TRUE(second);
    auto after = gl().stats();
    EXPECT_EQ(after.heightPasses, before.heightPasses);
    EXPECT_EQ(after.heightPassesSkipped, before.heightPassesSkipped + 1);
    EXPECT_EQ(second->maps->bump.data, first->maps->bump.data);
    EXPECT_NE(second->image.rgba, first->image.rgba);
    // The pose moves a driving joint: the pass runs again and the maps change.
    opt.time = 0.4;
    auto c = makeSceneFrame(scene, model_, loaded_->images, nullptr, opt);
    ASSERT_TRUE(c);
    auto third = gl().renderFrame(c->request);
    ASSERT_TRUE(third);
    after = gl().stats();
    EXPECT_EQ(after.heightPasses, before.heightPasses + 1);
    EXPECT_NE(third->maps->bump.data, first->maps->bump.data);
}

TEST_F(DefaultCharacterGLTest, ReadsBackTheMapsItUsed) {
    Scene scene = loaded_->scene;
    scene.render.size = {64, 64};
    SceneFrameOptions opt;
    opt.readHeightMaps = true;
    auto frame = makeSceneFrame(scene, model_, loaded_->images, nullptr, opt);
    ASSERT_TRUE(frame);
    auto r = gl().renderFrame(frame->request);
    ASSERT_TRUE(r) << r.error().message;
    ASSERT_TRUE(r->maps);
    auto direct = gl().bakeHeightMaps(*frame->request.heights);
    ASSERT_TRUE(direct);
    EXPECT_EQ(r->maps->bump.data, direct->bump.data);
    EXPECT_EQ(r->maps->displacement.data, direct->displacement.data);
}

} // namespace
