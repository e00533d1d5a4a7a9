// AntiAliasingGLTest — `render.aa` on a real GL context (Mesa's llvmpipe in CI; an NVIDIA EGL
// device where there is one): what `auto` resolves to on this GL, a reference frame of the
// default character per mode (MSAA 4x, post-process, none), and each mode measured by SSIM
// against a supersampled frame and against MSAA 4x (printed as JSON; post must beat none).
#include "BuildPaths.hpp"
#include "ImageCompare.hpp"
#include "SceneFrame.hpp"
#include "core/image_similarity.hpp"
#include "gl/renderer.hpp"
#include "io/scene_files.hpp"

#include "RendererSuite.hpp"

#include <gtest/gtest.h>

#include <cstdio>

using namespace dermis;
using namespace dermis::test;

namespace {

const std::string kSource = dermis::build::sourceDir();

class AntiAliasingGLTest : public RendererSuite {
protected:
    static void SetUpTestSuite() {
        RendererSuite::SetUpTestSuite();
        auto l = loadSceneFile(kSource + "/models/default.scene.json");
        if (!l) {
            createError_ = l.error().message;
            return;
        }
        loaded_ = std::make_unique<LoadedScene>(std::move(*l));
        model_ = std::make_shared<const Model>(loaded_->model);
    }
    static void TearDownTestSuite() {
        RendererSuite::TearDownTestSuite();
        loaded_.reset();
        model_.reset();
    }
    void SetUp() override {
        RendererSuite::SetUp();
        ASSERT_TRUE(loaded_) << createError_;
    }

    /// The default scene squatting (the reference pose of RendererGLTest), side² (256), with `aa`.
    static Result<FrameResult> squat(AntiAliasing aa, int msaa = 4, int side = 256) {
        Scene scene = loaded_->scene;
        scene.pose.animation = "squat";
        scene.pose.time = 1.25;
        scene.render.size = {side, side};
        scene.render.camera.yaw = 20.0;
        scene.render.camera.pitch = 10.0;
        scene.render.aa = aa;
        scene.render.msaa = msaa;
        auto frame = makeSceneFrame(scene, model_, loaded_->images, nullptr, {});
        if (!frame) return frame.error();
        return renderer_->renderFrame(frame->request);
    }

    inline static std::unique_ptr<LoadedScene> loaded_;
    inline static std::shared_ptr<const Model> model_;
};

} // namespace

TEST_F(AntiAliasingGLTest, AutoIsPostOnASoftwareRasterizerAndMsaaOnAGpu) {
    const RendererInfo& info = renderer_->info();
    const bool mesaSoftware = info.renderer.find("llvmpipe") != std::string::npos ||
                              info.renderer.find("softpipe") != std::string::npos;
    EXPECT_EQ(info.software, mesaSoftware) << info.renderer;
    auto r = squat(AntiAliasing::Auto);
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_EQ(r->antiAliasing, info.software ? "post" : "msaa4") << info.renderer;
    auto m = squat(AntiAliasing::Msaa);
    ASSERT_TRUE(m) << m.error().message;
    EXPECT_EQ(m->antiAliasing, "msaa4"); // always selectable
    auto one = squat(AntiAliasing::Msaa, 1);
    ASSERT_TRUE(one);
    EXPECT_EQ(one->antiAliasing, "none");
}

TEST_F(AntiAliasingGLTest, EachModeMatchesItsReferenceFrame) {
    const struct {
        AntiAliasing aa;
        const char* reference;
    } cases[] = {{AntiAliasing::Msaa, "default_squat"}, // MSAA 4x: RendererGLTest's reference
                 {AntiAliasing::Post, "default_squat_post"},
                 {AntiAliasing::None, "default_squat_none"}};
    for (const auto& c : cases) {
        auto r = squat(c.aa);
        ASSERT_TRUE(r) << toString(c.aa) << ": " << r.error().message;
        EXPECT_TRUE(compareWithReference(r->image, kSource + "/tests/reference/" + c.reference + ".png"))
            << toString(c.aa);
    }
}

TEST_F(AntiAliasingGLTest, PostIsCloserToASupersampledFrameThanNoAntiAliasing) {
    // The truth: the same frame at 4× the size with MSAA 4x, each 4×4 block averaged (64 samples
    // a pixel). The framing depends on the aspect only, so the pictures line up.
    auto big = squat(AntiAliasing::Msaa, 4, 1024);
    ASSERT_TRUE(big) << big.error().message;
    const Image8 truth = *boxDownsample(big->image, 4);
    auto msaa = squat(AntiAliasing::Msaa), post = squat(AntiAliasing::Post), none = squat(AntiAliasing::None);
    ASSERT_TRUE(msaa && post && none);
    const double sNone = *ssim(none->image, truth), sPost = *ssim(post->image, truth),
                 sMsaa = *ssim(msaa->image, truth), postVsMsaa = *ssim(post->image, msaa->image),
                 noneVsMsaa = *ssim(none->image, msaa->image);
    std::printf("{\"ssim\": {\"size\": 256, \"vs_supersampled\": {\"none\": %.4f, \"post\": %.4f, "
                "\"msaa4\": %.4f}, \"vs_msaa4\": {\"none\": %.4f, \"post\": %.4f}}}\n",
                sNone, sPost, sMsaa, noneVsMsaa, postVsMsaa);
    EXPECT_GT(sPost, sNone);
    EXPECT_GT(postVsMsaa, 0.95);
    // The post pass starts from the 1-sample frame and changes a few percent of its pixels.
    std::size_t changed = 0;
    for (std::size_t i = 0; i < post->image.rgba.size(); i += 4)
        changed += post->image.rgba[i] != none->image.rgba[i] || post->image.rgba[i + 1] != none->image.rgba[i + 1] ||
                   post->image.rgba[i + 2] != none->image.rgba[i + 2];
    const double fraction = static_cast<double>(changed) / (256.0 * 256.0);
    EXPECT_GT(fraction, 0.002);
    EXPECT_LT(fraction, 0.2);
}
