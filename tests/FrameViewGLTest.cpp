// FrameViewGLTest — what a frame shows (FrameView, core/render_settings.hpp) on the GL renderer,
// through the one frame plan (FrameOverrides::view → FramePlan → frameRequest): on the default
// scene the four views (shaded, bump, displacement, normal) are four different pictures with the
// same background; without patterns the bump and displacement views are exactly mid grey (byte
// 128) wherever the skin is, with patterns some skin pixels leave it; the normal view's pixels
// decode to unit vectors (|2c − 1| ≈ 1) and show the bump mapping. A request with a view that
// FrameView does not name is refused. Frames without MSAA, so that no pixel mixes skin with the
// background.
#include "BuildPaths.hpp"
#include "core/frame_plan.hpp"
#include "gl/renderer.hpp"
#include "io/scene_files.hpp"

#include "GlTestBackend.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <map>

using namespace dermis;

namespace {

const std::string kSource = dermis::build::sourceDir();

using test::requestedBackend;

const FrameView kViews[] = {FrameView::Shaded, FrameView::Bump, FrameView::Displacement,
                            FrameView::Normal};

class FrameViewGLTest : public ::testing::Test {
  protected:
    static void SetUpTestSuite() {
        auto r = Renderer::create(requestedBackend());
        if (r)
            renderer_ = std::move(*r);
        else
            error_ = r.error().message;
        auto l = loadSceneFile(kSource + "/models/default.scene.json");
        if (l) {
            loaded_ = std::make_unique<LoadedScene>(std::move(*l));
            model_ = std::make_shared<const Model>(loaded_->model);
        } else {
            error_ += l.error().message;
        }
    }
    static void TearDownTestSuite() {
        renderer_.reset();
        model_.reset();
        loaded_.reset();
    }
    void SetUp() override { ASSERT_TRUE(renderer_ && loaded_) << error_; }

    /// The default scene (its pose: the squat at 1.25 s, where the stomach wrinkles and knee
    /// creases are on) in `view`, 160², no MSAA; without its placements when `patterns` is false.
    static Image8 shoot(FrameView view, bool patterns = true) {
        Scene scene = loaded_->scene;
        if (!patterns) scene.placements.clear();
        FrameOverrides o;
        o.width = o.height = 160;
        o.msaa = 1;
        o.view = view;
        auto plan = planFrame(scene, *model_, loaded_->images, nullptr, o);
        EXPECT_TRUE(plan) << plan.error().message;
        if (!plan) return {};
        EXPECT_EQ(plan->view, view);
        const FrameRequest request = frameRequest(*plan, model_);
        EXPECT_EQ(request.view, view);
        auto frame = renderer_->renderFrame(request);
        EXPECT_TRUE(frame) << frame.error().message;
        return frame ? std::move(frame->image) : Image8{};
    }
    static bool isBackground(const Image8& img, std::size_t p) {
        return img.rgba[p] == img.rgba[0] && img.rgba[p + 1] == img.rgba[1] &&
               img.rgba[p + 2] == img.rgba[2];
    }

    static std::unique_ptr<Renderer> renderer_;
    static std::unique_ptr<LoadedScene> loaded_;
    static std::shared_ptr<const Model> model_;
    static std::string error_;
};
std::unique_ptr<Renderer> FrameViewGLTest::renderer_;
std::unique_ptr<LoadedScene> FrameViewGLTest::loaded_;
std::shared_ptr<const Model> FrameViewGLTest::model_;
std::string FrameViewGLTest::error_;

TEST_F(FrameViewGLTest, TheFourViewsAreDifferentPicturesOnOneBackground) {
    std::map<FrameView, Image8> frames;
    for (FrameView v : kViews) {
        frames[v] = shoot(v);
        ASSERT_EQ(frames[v].rgba.size(), 160u * 160u * 4u) << toString(v);
    }
    const std::size_t pixels = 160 * 160;
    for (FrameView a : kViews)
        for (FrameView b : kViews) {
            if (a >= b) continue;
            std::size_t differ = 0;
            for (std::size_t p = 0; p < pixels * 4; p += 4)
                for (int c = 0; c < 3; ++c)
                    if (std::abs(int(frames[a].rgba[p + c]) - int(frames[b].rgba[p + c])) > 4) {
                        ++differ;
                        break;
                    }
            // Bump and displacement differ only where their patterns are; the others all over.
            const bool heights = a == FrameView::Bump && b == FrameView::Displacement;
            EXPECT_GT(differ, heights ? 40 : pixels / 20) << toString(a) << " vs " << toString(b);
        }
    // Same background (the top-left pixel is off the character) and the same silhouette.
    std::size_t skin = 0;
    for (std::size_t p = 0; p < pixels * 4; p += 4)
        skin += !isBackground(frames[FrameView::Shaded], p);
    EXPECT_GT(skin, pixels / 10);
    for (FrameView v : kViews) {
        for (int c = 0; c < 4; ++c)
            EXPECT_EQ(frames[v].rgba[c], frames[FrameView::Shaded].rgba[c]) << toString(v);
        std::size_t vSkin = 0;
        for (std::size_t p = 0; p < pixels * 4; p += 4)
            vSkin += !isBackground(frames[v], p);
        EXPECT_EQ(vSkin, skin) << toString(v);
    }
}

TEST_F(FrameViewGLTest, HeightViewsAreMidGreyWithoutPatternsAndNotWithThem) {
    for (FrameView v : {FrameView::Bump, FrameView::Displacement}) {
        const Image8 flat = shoot(v, false);
        ASSERT_FALSE(flat.rgba.empty());
        std::size_t skin = 0, off = 0;
        for (std::size_t p = 0; p < flat.rgba.size(); p += 4) {
            if (isBackground(flat, p)) continue;
            ++skin;
            for (int c = 0; c < 3; ++c)
                off += std::abs(int(flat.rgba[p + c]) - 128) > 1;
        }
        EXPECT_GT(skin, flat.rgba.size() / 4 / 10) << toString(v);
        EXPECT_EQ(off, 0u) << toString(v) << ": height 0 must be byte 128 everywhere on the skin";

        const Image8 patterned = shoot(v, true);
        ASSERT_FALSE(patterned.rgba.empty());
        std::size_t changed = 0, grey = 0;
        for (std::size_t p = 0; p < patterned.rgba.size(); p += 4) {
            if (isBackground(patterned, p)) continue;
            changed += std::abs(int(patterned.rgba[p]) - 128) > 8;
            grey += patterned.rgba[p] == patterned.rgba[p + 1] &&
                    patterned.rgba[p] == patterned.rgba[p + 2];
        }
        EXPECT_GT(changed, 20u) << toString(v) << ": the default scene's patterns must show";
        EXPECT_EQ(grey, skin) << toString(v) << ": heights are grey";
    }
}

TEST_F(FrameViewGLTest, NormalViewShowsUnitBumpMappedNormals) {
    const Image8 img = shoot(FrameView::Normal);
    ASSERT_FALSE(img.rgba.empty());
    std::size_t skin = 0, notUnit = 0;
    double worst = 0.0;
    for (std::size_t p = 0; p < img.rgba.size(); p += 4) {
        if (isBackground(img, p)) continue;
        ++skin;
        double len2 = 0.0;
        for (int c = 0; c < 3; ++c) {
            const double n = 2.0 * img.rgba[p + c] / 255.0 - 1.0;
            len2 += n * n;
        }
        const double err = std::abs(std::sqrt(len2) - 1.0);
        worst = std::max(worst, err);
        notUnit += err > 0.03;
    }
    EXPECT_GT(skin, img.rgba.size() / 4 / 10);
    EXPECT_EQ(notUnit, 0u) << "worst | |2c-1| - 1 | = " << worst;
    // The bump mapping shows: the same view without patterns differs on the skin.
    const Image8 flat = shoot(FrameView::Normal, false);
    ASSERT_EQ(flat.rgba.size(), img.rgba.size());
    std::size_t differ = 0;
    for (std::size_t p = 0; p < img.rgba.size(); p += 4)
        for (int c = 0; c < 3; ++c)
            if (std::abs(int(img.rgba[p + c]) - int(flat.rgba[p + c])) > 8) {
                ++differ;
                break;
            }
    EXPECT_GT(differ, 20u);
}

TEST_F(FrameViewGLTest, AViewFrameViewDoesNotNameIsRefused) {
    auto plan = planFrame(loaded_->scene, *model_, loaded_->images, nullptr, {});
    ASSERT_TRUE(plan) << plan.error().message;
    FrameRequest request = frameRequest(*plan, model_);
    request.render.size = {32, 32};
    request.view = static_cast<FrameView>(7);
    auto r = renderer_->renderFrame(request);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, ErrorCode::InvalidArgument);
    EXPECT_EQ(r.error().field, "view");
    request.view = FrameView::Bump; // and the renderer is still usable
    EXPECT_TRUE(renderer_->renderFrame(request));
}

} // namespace
