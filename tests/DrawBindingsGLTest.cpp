// DrawBindingsGLTest — every draw's uniform and storage blocks are backed by a buffer range that
// lies inside its store and holds the block (RendererOptions::checkBindings), across the sequences
// that shrink the renderer's shared buffers, on the backend named by $DERMIS_TEST_GL. Each block
// in shaders/common.glsl is active in every program (std140), and Mesa's llvmpipe reads every
// bound uniform range on every draw: a range left at a placement's or a part's offset in a buffer
// that a later job re-allocated smaller made the draw read past the store (AddressSanitizer: SEGV
// in swrast_dri under glDrawElements in SweepHttpTest, RendersHttpTest and View3dHttpTest). It
// checks:
//   * frames with a 12-placement height pass, then with 1, then none (a pass that draws no
//     placement), then flat maps after a bake without placements;
//   * a frame of a many-part model (Barbarian), then of a one-part model (CesiumMan), then a
//     height pass, then transform-feedback skinning;
//   * pbr frames and tessellated displacement after both; the key light's shadow pass on the
//     many-part model, then a frame of the one-part model;
//   * the images of the checked renderer equal those of an unchecked one (the check only reads);
//   * a key light's first frame (which makes its textures) equals its next;
//   * a shadow map reused while only the camera moves, and drawn again when the pose, the heights
//     (vertex displacement) or the light change, gives the frames a fresh renderer gives.
#include "BuildPaths.hpp"
#include "GlTestBackend.hpp"
#include "gl/renderer.hpp"
#include "io/gltf_loader.hpp"

#include "core/rig.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>

using namespace dermis;
using namespace dermis::test;

namespace {

const std::string kModels = dermis::build::testModelsDir();

std::shared_ptr<const Model> load(const std::string& relative) {
    auto m = loadGltfFile(kModels + relative);
    EXPECT_TRUE(m) << relative << ": " << (m ? "" : m.error().message);
    return m ? std::make_shared<const Model>(std::move(*m)) : nullptr;
}

std::unique_ptr<Renderer> checkedRenderer() {
    RendererOptions options;
    options.checkBindings = true;
    options.softwareCpuBakeCoverage = 0.0; // always the GL height pass: its draws are checked
    auto r = Renderer::create(requestedBackend(), options);
    EXPECT_TRUE(r) << "no GL context for backend " << toString(requestedBackend()) << ": "
                   << (r ? "" : r.error().message);
    return r ? std::move(*r) : nullptr;
}

/// A 32² bump: a cosine dome.
std::shared_ptr<const PatternImage> dome() {
    HeightImage img(32, 32);
    for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 32; ++x) {
            const double r = std::hypot(x - 15.5, y - 15.5) / 16.0;
            img.data[static_cast<std::size_t>(y) * 32 + x] =
                r < 1.0 ? static_cast<float>(0.5 + 0.5 * std::cos(r * 3.14159265)) : 0.0f;
        }
    return makePatternImage(std::move(img));
}

/// `count` placements of `pattern` spread over the map, bump and displacement alternating.
HeightPassInput heights(const PatternImage& pattern, int count) {
    HeightPassInput in;
    in.width = in.height = 256;
    for (int k = 0; k < count; ++k) {
        BakePlacement p;
        p.pattern = &pattern.pixels;
        p.patternId = pattern.contentId;
        p.footprint.center = {0.1 + 0.07 * k, 0.2 + 0.05 * k};
        p.footprint.scale = {0.2, 0.2};
        p.h = 1.0;
        p.t = 0.5;
        p.target = k % 2 ? Target::Displacement : Target::Bump;
        in.placements.push_back(p);
    }
    return in;
}

FrameRequest request(const std::shared_ptr<const Model>& m, std::optional<HeightPassInput> maps) {
    FrameRequest req;
    req.model = m;
    req.world = worldMatrices(*m, m->clips.empty() ? restPose(*m) : sampleClip(*m, 0, 0.3f));
    req.render.size = {96, 96};
    req.render.aa = AntiAliasing::None;
    req.heights = std::move(maps);
    return req;
}

Image8 frame(Renderer& gl, const FrameRequest& req, const char* what) {
    auto f = gl.renderFrame(req);
    EXPECT_TRUE(f) << what << ": " << (f ? "" : f.error().message);
    return f ? f->image : Image8{};
}

} // namespace

TEST(DrawBindingsGLTest, AHeightPassWithFewerPlacementsThenFrames) {
    auto gl = checkedRenderer();
    ASSERT_TRUE(gl);
    const auto cesium = load("/CesiumMan/CesiumMan.glb");
    ASSERT_TRUE(cesium);
    const auto pattern = dome();
    frame(*gl, request(cesium, heights(*pattern, 12)), "12 placements");
    frame(*gl, request(cesium, heights(*pattern, 1)), "1 placement after 12");
    frame(*gl, request(cesium, heights(*pattern, 12)), "12 placements after 1");
    // A height pass without placements draws nothing that would re-bind the block's range.
    frame(*gl, request(cesium, heights(*pattern, 0)), "no placements after 12");
    frame(*gl, request(cesium, heights(*pattern, 12)), "12 placements after none");
    auto none = gl->bakeHeightMaps(heights(*pattern, 0));
    EXPECT_TRUE(none) << "a height pass without placements: " << (none ? "" : none.error().message);
    frame(*gl, request(cesium, std::nullopt), "flat after a pass without placements");
    FrameRequest pbr = request(cesium, heights(*pattern, 12));
    pbr.render.shading = Shading::Pbr;
    frame(*gl, pbr, "pbr, 12 placements");
    pbr.heights = heights(*pattern, 2);
    pbr.render.displacement = DisplacementMode::Tessellated;
    frame(*gl, pbr, "pbr tessellated, 2 placements after 12");
}

TEST(DrawBindingsGLTest, AManyPartModelThenAOnePartModelThenAHeightPass) {
    auto gl = checkedRenderer();
    ASSERT_TRUE(gl);
    const auto barbarian = load("/KayKitBarbarian/Barbarian.glb");
    const auto cesium = load("/CesiumMan/CesiumMan.glb");
    ASSERT_TRUE(barbarian && cesium);
    ASSERT_GT(barbarian->parts.size(), cesium->parts.size() + 2);
    const auto pattern = dome();
    frame(*gl, request(barbarian, std::nullopt), "Barbarian");
    frame(*gl, request(cesium, std::nullopt), "CesiumMan after Barbarian");
    frame(*gl, request(barbarian, std::nullopt), "Barbarian after CesiumMan");
    auto maps = gl->bakeHeightMaps(heights(*pattern, 3));
    EXPECT_TRUE(maps) << "height pass after Barbarian: " << (maps ? "" : maps.error().message);
    auto skinned = gl->skinOnGpu(cesium, worldMatrices(*cesium, restPose(*cesium)));
    EXPECT_TRUE(skinned) << "transform feedback after Barbarian: "
                         << (skinned ? "" : skinned.error().message);
    frame(*gl, request(barbarian, std::nullopt), "Barbarian after transform feedback");
    // The key light's shadow pass (its own FrameBlock buffer, the part blocks by range) on the
    // many-part model, then a frame of the one-part model under it.
    FrameRequest lit = request(barbarian, std::nullopt);
    lit.render.shading = Shading::Skin;
    lit.render.keyLight = KeyLight{};
    frame(*gl, lit, "Barbarian, skin with a shadowed key light");
    lit = request(cesium, heights(*pattern, 2));
    lit.render.shading = Shading::Pbr;
    lit.render.keyLight = KeyLight{};
    frame(*gl, lit, "CesiumMan, pbr with a shadowed key light after the Barbarian");
}

TEST(DrawBindingsGLTest, TheCheckOnlyReads) {
    auto checked = checkedRenderer();
    RendererOptions plainOptions;
    plainOptions.softwareCpuBakeCoverage = 0.0;
    auto plain = Renderer::create(requestedBackend(), plainOptions);
    ASSERT_TRUE(checked && plain);
    const auto cesium = load("/CesiumMan/CesiumMan.glb");
    ASSERT_TRUE(cesium);
    const auto pattern = dome();
    for (int count : {12, 1}) {
        const FrameRequest req = request(cesium, heights(*pattern, count));
        const Image8 a = frame(*checked, req, "checked"), b = frame(**plain, req, "plain");
        ASSERT_FALSE(a.rgba.empty());
        EXPECT_EQ(a.rgba, b.rgba) << count << " placements";
    }
}

TEST(DrawBindingsGLTest, AKeyLightsFirstFrameEqualsItsNext) {
    // The key light's first frame makes its textures (the shadow map, the unshadowed one): on a
    // unit of their own, or they would replace what the frame bound before (the environment's
    // split-sum table on unit 8 was, once).
    for (bool shadow : {true, false}) {
        auto gl = checkedRenderer();
        ASSERT_TRUE(gl);
        const auto cesium = load("/CesiumMan/CesiumMan.glb");
        ASSERT_TRUE(cesium);
        FrameRequest lit = request(cesium, std::nullopt);
        lit.render.shading = Shading::Pbr;
        lit.render.keyLight = KeyLight{};
        lit.render.keyLight->shadow = shadow;
        const Image8 first = frame(*gl, lit, "first key light frame");
        const Image8 next = frame(*gl, lit, "next key light frame");
        ASSERT_FALSE(first.rgba.empty());
        EXPECT_EQ(first.rgba, next.rgba) << (shadow ? "shadowed" : "unshadowed");
    }
}

TEST(DrawBindingsGLTest, AReusedShadowMapEqualsAFreshOne) {
    // The shadow map is drawn again only when what casts changes (ShadowInputs): each frame of one
    // renderer, some of them reusing its map, must equal that frame from a fresh renderer.
    const auto cesium = load("/CesiumMan/CesiumMan.glb");
    ASSERT_TRUE(cesium);
    const auto pattern = dome();
    auto gl = checkedRenderer();
    ASSERT_TRUE(gl);
    FrameRequest req = request(cesium, heights(*pattern, 4));
    req.render.size = {128, 128};
    req.render.shading = Shading::Pbr;
    req.render.keyLight = KeyLight{};
    req.render.keyLight->direction = {0.8, 0.6, 0.3};
    req.render.displacementScale = 0.05; // the displaced placements move what casts
    const auto fresh = [&](const FrameRequest& r, const char* what) {
        auto other = checkedRenderer();
        return other ? frame(*other, r, what) : Image8{};
    };
    const auto check = [&](const FrameRequest& r, const char* what) {
        const Image8 mine = frame(*gl, r, what), theirs = fresh(r, what);
        EXPECT_FALSE(mine.rgba.empty()) << what;
        EXPECT_EQ(mine.rgba, theirs.rgba) << what;
        return mine;
    };
    const Image8 first = check(req, "first");
    FrameRequest orbit = req;
    orbit.render.camera.yaw = 40.0;
    const Image8 turned = check(orbit, "the camera turned (the map reused)");
    EXPECT_NE(first.rgba, turned.rgba);
    FrameRequest posed = orbit;
    posed.world = worldMatrices(*cesium, sampleClip(*cesium, 0, 0.9f));
    const Image8 moved = check(posed, "the pose moved");
    FrameRequest displaced = posed;
    displaced.heights->placements[1].t = 1.0; // a displacement placement at full activation
    displaced.heights->placements[3].t = 0.0;
    check(displaced, "the displacement changed");
    FrameRequest relit = displaced;
    relit.render.keyLight->direction = {-0.8, 0.6, 0.3};
    check(relit, "the light moved");
    check(displaced, "back to the first light");
    EXPECT_NE(first.rgba, moved.rgba);
}
