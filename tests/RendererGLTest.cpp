// RendererGLTest — the GPU renderer on a real GL context (Mesa's llvmpipe in CI; an NVIDIA EGL
// device where there is one). The backend comes from $DERMIS_TEST_GL (ctest runs this suite once
// per backend: osmesa and egl-surfaceless); without it, auto. A backend that cannot start fails
// the suite: nothing is skipped.
//
// Checks: uniform-block mirrors; GPU height maps equal the CPU reference within 2e-3 away from
// footprint edges (rotated, non-square, overlapping placements, every model and response, base
// map; and the default scene); pattern and base textures follow their content (ids, or the
// pixels' hash when an image has none, so in-place edits are seen); GPU skinning equals CPU
// skinning within 1e-4 (CesiumMan, default character); frames of CesiumMan and KayKit Barbarian
// are non-empty and change with time. The default scene's frames (reference images, MSAA,
// tessellation, displacement): DefaultCharacterGLTest.
#include "BuildPaths.hpp"
#include "ImageCompare.hpp"
#include "SceneFrame.hpp"
#include "core/bake.hpp"
#include "gl/renderer.hpp"
#include "io/gltf_loader.hpp"
#include "io/scene_files.hpp"
#include "uniform_blocks.hpp"

#include "RendererSuite.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <map>
#include <random>

using namespace dermis;
using namespace dermis::test;

namespace {

const std::string kTestModels = dermis::build::testModelsDir();
const std::string kSource = dermis::build::sourceDir();
const std::string kCesium = kTestModels + "/CesiumMan/CesiumMan.glb";
const std::string kBarbarian = kTestModels + "/KayKitBarbarian/Barbarian.glb";

using test::requestedBackend;

class RendererGLTest : public RendererSuite {};

std::shared_ptr<const Model> loadModel(const std::string& path) {
    auto m = loadGltfFile(path);
    EXPECT_TRUE(m) << (m ? "" : m.error().message);
    return m ? std::make_shared<const Model>(std::move(*m)) : nullptr;
}

// --- context and uniform blocks -----------------------------------------------------------------

TEST_F(RendererGLTest, ReportsTheBackendAndDriver) {
    const RendererInfo& i = gl().info();
    if (requestedBackend() != GlBackend::Auto) EXPECT_EQ(i.backend, toString(requestedBackend()));
    EXPECT_FALSE(i.vendor.empty());
    EXPECT_FALSE(i.renderer.empty());
    EXPECT_NE(i.version.find("4."), std::string::npos) << i.version;
    EXPECT_GE(i.maxTextureSize, 4096);
    EXPECT_GE(i.maxSamples, 4);
}

TEST_F(RendererGLTest, UniformBlocksMatchTheirCppMirrors) {
    struct Member {
        const char* name;
        std::size_t offset;
    };
    const std::map<std::string, std::pair<std::size_t, std::vector<Member>>> expected = {
        {"HeightPassBlock",
         {sizeof(gl::HeightPassBlock),
          {{"u_centerScale", offsetof(gl::HeightPassBlock, centerScale)},
           {"u_rotation", offsetof(gl::HeightPassBlock, rotation)},
           {"u_drive", offsetof(gl::HeightPassBlock, drive)},
           {"u_mode", offsetof(gl::HeightPassBlock, mode)},
           {"u_mapSize", offsetof(gl::HeightPassBlock, mapSize)},
           {"u_anchor", offsetof(gl::HeightPassBlock, anchor)},
           {"u_anchorNormal", offsetof(gl::HeightPassBlock, anchorNormal)},
           {"u_anchorTangent", offsetof(gl::HeightPassBlock, anchorTangent)},
           {"u_anchorBinormal", offsetof(gl::HeightPassBlock, anchorBinormal)}}}},
        {"FrameBlock",
         {sizeof(gl::FrameBlock),
          {{"u_viewProj", offsetof(gl::FrameBlock, viewProj)},
           {"u_cameraPos", offsetof(gl::FrameBlock, cameraPos)},
           {"u_lightDir", offsetof(gl::FrameBlock, lightDir)},
           {"u_heights", offsetof(gl::FrameBlock, heights)},
           {"u_heightmapSize", offsetof(gl::FrameBlock, heightmapSize)},
           {"u_viewport", offsetof(gl::FrameBlock, viewport)}}}},
        {"PartBlock",
         {sizeof(gl::PartBlock),
          {{"u_baseColor", offsetof(gl::PartBlock, baseColor)},
           {"u_part", offsetof(gl::PartBlock, part)},
           {"u_emissive", offsetof(gl::PartBlock, emissive)},
           {"u_material", offsetof(gl::PartBlock, material)},
           {"u_maps", offsetof(gl::PartBlock, maps)},
           {"u_uvTransform[0]", offsetof(gl::PartBlock, uvTransform)},
           {"u_morph", offsetof(gl::PartBlock, morph)}}}},
        {"EnvironmentBlock",
         {sizeof(gl::EnvironmentBlock),
          {{"u_irradianceSh[0]", offsetof(gl::EnvironmentBlock, irradianceSh)},
           {"u_envParams", offsetof(gl::EnvironmentBlock, params)},
           {"u_envMode", offsetof(gl::EnvironmentBlock, mode)}}}},
        {"KeyLightBlock",
         {sizeof(gl::KeyLightBlock),
          {{"u_shadowViewProj", offsetof(gl::KeyLightBlock, shadowViewProj)},
           {"u_keyDirection", offsetof(gl::KeyLightBlock, direction)},
           {"u_keyRadiance", offsetof(gl::KeyLightBlock, radiance)},
           {"u_shadowParams", offsetof(gl::KeyLightBlock, shadowParams)}}}},
        {"OutlineBlock",
         {sizeof(gl::OutlineBlock),
          {{"u_outlineCount", offsetof(gl::OutlineBlock, count)},
           {"u_outlineRect[0]", offsetof(gl::OutlineBlock, rect)},
           {"u_outlineStyle[0]", offsetof(gl::OutlineBlock, style)},
           {"u_outlineAnchor[0]", offsetof(gl::OutlineBlock, anchor)},
           {"u_outlineAxisU[0]", offsetof(gl::OutlineBlock, axisU)},
           {"u_outlineAxisV[0]", offsetof(gl::OutlineBlock, axisV)}}}},
    };
    for (const auto& [block, want] : expected) {
        auto layout = gl().blockLayout(block);
        ASSERT_TRUE(layout) << layout.error().message;
        EXPECT_EQ(static_cast<std::size_t>(layout->size), want.first) << block;
        std::map<std::string, int> got(layout->offsets.begin(), layout->offsets.end());
        EXPECT_EQ(got.size(), want.second.size()) << block << ": members the mirror lacks";
        for (const Member& m : want.second) {
            ASSERT_TRUE(got.count(m.name)) << block << "." << m.name << " is not active";
            EXPECT_EQ(static_cast<std::size_t>(got[m.name]), m.offset) << block << "." << m.name;
        }
    }
    EXPECT_FALSE(gl().blockLayout("NoSuchBlock"));
}

// --- stage 1: height maps -----------------------------------------------------------------------

/// A smooth signed test pattern of size w×h with values in [−1, 1].
HeightImage testPattern(int w, int h, double fx, double fy) {
    HeightImage img(w, h);
    for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i)
            img.at(i, j) = static_cast<float>(std::sin(fx * (i + 0.5) / w * 6.283 + 0.3) *
                                              std::cos(fy * (j + 0.5) / h * 6.283 - 0.2));
    return img;
}

/// True when texel (i, j)'s centre lies within `margin` UV of some active footprint's edge.
bool nearAnEdge(const std::vector<BakePlacement>& ps, int i, int j, int W, int H, double margin) {
    const glm::dvec2 uv((i + 0.5) / W, (j + 0.5) / H);
    for (const BakePlacement& p : ps) {
        if (p.t <= 0.0) continue;
        const glm::dvec2 s = p.footprint.toPattern(uv);
        const double du = std::min(std::abs(s.x), std::abs(1.0 - s.x)) * p.footprint.scale.x;
        const double dv = std::min(std::abs(s.y), std::abs(1.0 - s.y)) * p.footprint.scale.y;
        const bool insideU = s.x > -margin / p.footprint.scale.x && s.x < 1.0 + margin / p.footprint.scale.x;
        const bool insideV = s.y > -margin / p.footprint.scale.y && s.y < 1.0 + margin / p.footprint.scale.y;
        if ((du < margin && insideV) || (dv < margin && insideU)) return true;
    }
    return false;
}

struct MapComparison {
    float maxDiff = 0.0f;
    std::size_t compared = 0, nonZero = 0;
};

MapComparison compareMaps(const HeightImage& gpu, const HeightImage& cpu,
                          const std::vector<BakePlacement>& ps) {
    MapComparison c;
    const int W = cpu.width, H = cpu.height;
    const double margin = 2.0 * std::max(1.0 / W, 1.0 / H);
    for (int j = 0; j < H; ++j)
        for (int i = 0; i < W; ++i) {
            if (nearAnEdge(ps, i, j, W, H, margin)) continue;
            ++c.compared;
            if (cpu.at(i, j) != 0.0f) ++c.nonZero;
            c.maxDiff = std::max(c.maxDiff, std::abs(gpu.at(i, j) - cpu.at(i, j)));
        }
    return c;
}

TEST_F(RendererGLTest, HeightPassEqualsTheCpuReference) {
    PatternImages images;
    images["a"] = makePatternImage(testPattern(64, 40, 1.5, 2.0)); // non-square
    images["b"] = makePatternImage(testPattern(32, 32, 3.0, 1.0));
    images["c"] = makePatternImage(testPattern(50, 70, 0.7, 2.5));
    HeightImage base = testPattern(97, 61, 4.0, 4.0); // a static map of another size
    for (float& v : base.data) v *= 0.1f;

    std::vector<BakePlacement> ps;
    const char* keys[] = {"a", "b", "c"};
    const double rotations[] = {0.0, 30.0, -75.0, 90.0, 200.0, 12.5, 145.0, -160.0};
    int n = 0;
    for (DeformModel m : {DeformModel::Scale, DeformModel::Bias})
        for (Response r : {Response::Log2, Response::Ln, Response::Linear, Response::Smoothstep}) {
            BakePlacement p;
            p.pattern = &images[keys[n % 3]]->pixels;
            p.patternId = images[keys[n % 3]]->contentId;
            // Overlapping footprints along a diagonal, non-square and rotated.
            p.footprint.center = {0.2 + 0.08 * n, 0.25 + 0.06 * n};
            p.footprint.scale = {0.22 + 0.02 * (n % 3), 0.13 + 0.03 * (n % 2)};
            p.footprint.rotationDeg = rotations[n];
            p.model = m;
            p.response = r;
            p.target = n % 2 ? Target::Displacement : Target::Bump;
            p.h = 0.5 + 0.25 * n;
            p.t = n == 3 ? 1.0 : 0.15 + 0.1 * n; // every response mid-range, one at t = 1
            ps.push_back(p);
            ++n;
        }
    BakePlacement off = ps[0]; // t = 0 contributes nothing
    off.t = 0.0;
    off.footprint.center = {0.8, 0.2};
    ps.push_back(off);

    HeightPassInput in;
    in.placements = ps;
    in.base = &base;
    in.width = 320;
    in.height = 200; // non-square map
    auto gpu = gl().bakeHeightMaps(in);
    ASSERT_TRUE(gpu) << gpu.error().message;
    BakeSettings bs;
    bs.width = in.width;
    bs.height = in.height;
    bs.base = &base;
    auto cpu = bakeHeightMaps(ps, bs);
    ASSERT_TRUE(cpu) << cpu.error().message;
    ASSERT_EQ(gpu->bump.width, 320);
    ASSERT_EQ(gpu->bump.height, 200);
    for (auto [g, c, name] : {std::tuple{&gpu->bump, &cpu->bump, "bump"},
                              std::tuple{&gpu->displacement, &cpu->displacement, "displacement"}}) {
        const MapComparison r = compareMaps(*g, *c, ps);
        EXPECT_LE(r.maxDiff, 2e-3f) << name;
        EXPECT_GT(r.compared, 320u * 200u / 2) << name;
        EXPECT_GT(r.nonZero, 2000u) << name << ": the comparison must cover deformed texels";
    }
    // Row 0 is v near 0: the map is not flipped (a placement near v = 0.25 lands in the top half).
    double topHalf = 0.0, bottomHalf = 0.0;
    for (int j = 0; j < 200; ++j)
        for (int i = 0; i < 320; ++i)
            (j < 100 ? topHalf : bottomHalf) += std::abs(gpu->displacement.at(i, j));
    EXPECT_GT(topHalf, 0.0);
    EXPECT_GT(bottomHalf, 0.0);
}

TEST_F(RendererGLTest, HeightPassOfTheDefaultSceneEqualsTheCpuReference) {
    auto loaded = loadSceneFile(kSource + "/models/default.scene.json");
    ASSERT_TRUE(loaded) << loaded.error().message;
    auto model = std::make_shared<const Model>(loaded->model);
    for (double time : {0.5, 1.25}) {
        auto frame = makeSceneFrame(loaded->scene, model, loaded->images, nullptr, {time});
        ASSERT_TRUE(frame) << frame.error().message;
        const HeightPassInput& in = *frame->request.heights;
        auto gpu = gl().bakeHeightMaps(in);
        ASSERT_TRUE(gpu) << gpu.error().message;
        BakeSettings bs;
        bs.width = in.width;
        bs.height = in.height;
        auto cpu = bakeHeightMaps(in.placements, bs);
        ASSERT_TRUE(cpu);
        for (auto [g, c] : {std::pair{&gpu->bump, &cpu->bump},
                            std::pair{&gpu->displacement, &cpu->displacement}}) {
            const MapComparison r = compareMaps(*g, *c, in.placements);
            EXPECT_LE(r.maxDiff, 2e-3f) << "time " << time;
            EXPECT_GT(r.nonZero, 1000u) << "time " << time;
        }
    }
}

TEST_F(RendererGLTest, DisabledPlacementsLeaveTheGpuMapsAsIfAbsent) {
    auto loaded = loadSceneFile(kSource + "/models/default.scene.json");
    ASSERT_TRUE(loaded) << loaded.error().message;
    auto model = std::make_shared<const Model>(loaded->model);
    Scene disabled = loaded->scene, removed = loaded->scene;
    removed.placements.clear();
    for (std::size_t k = 0; k < disabled.placements.size(); ++k) {
        if (k % 3 == 0) removed.placements.push_back(disabled.placements[k]);
        else disabled.placements[k].enabled = false;
    }
    auto maps = [&](const Scene& scene) -> Result<HeightMaps> {
        auto frame = makeSceneFrame(scene, model, loaded->images, nullptr, {0.75});
        if (!frame) return frame.error();
        return gl().bakeHeightMaps(*frame->request.heights);
    };
    auto a = maps(disabled), b = maps(removed), all = maps(loaded->scene);
    ASSERT_TRUE(a && b && all);
    EXPECT_EQ(a->bump.data, b->bump.data);
    EXPECT_EQ(a->displacement.data, b->displacement.data);
    EXPECT_NE(a->bump.data, all->bump.data) << "disabling placements changed nothing";
}

TEST_F(RendererGLTest, HeightPassRejectsBadInput) {
    HeightPassInput in;
    in.width = 0;
    auto r = gl().bakeHeightMaps(in);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().field, "/heightmap/size");
    in.width = 64;
    in.height = 64;
    BakePlacement p; // no pattern
    p.t = 0.5;
    in.placements.push_back(p);
    r = gl().bakeHeightMaps(in);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().field, "/placements/0/pattern");
    // The renderer is still usable afterwards.
    in.placements.clear();
    auto ok = gl().bakeHeightMaps(in);
    ASSERT_TRUE(ok) << ok.error().message;
    EXPECT_EQ(ok->bump.data, std::vector<float>(64 * 64, 0.0f));
}

// --- stage 1: texture caches keyed by content id ----------------------------------------------

/// GPU and CPU maps of `in` agree within 2e-3 away from footprint edges (see compareMaps).
void expectMatchesCpu(const HeightMaps& gpu, const HeightPassInput& in) {
    auto cpu = bakeHeightMaps(in);
    ASSERT_TRUE(cpu) << cpu.error().message;
    for (auto [g, c] : {std::pair{&gpu.bump, &cpu->bump},
                        std::pair{&gpu.displacement, &cpu->displacement}}) {
        const MapComparison r = compareMaps(*g, *c, in.placements);
        EXPECT_LE(r.maxDiff, 2e-3f);
        EXPECT_GT(r.compared, 0u);
    }
}

TEST_F(RendererGLTest, BaseMapWithoutAnIdIsUploadedAgainWhenItsPixelsChangeInPlace) {
    // The cache used to be keyed by the image's address: the same object with new pixels (same
    // address, same size) would have kept the old texture, and the height pass would be skipped.
    HeightImage base = testPattern(40, 30, 2.0, 1.0);
    HeightPassInput in;
    in.base = &base; // baseId 0: the renderer hashes the pixels
    in.width = 80;
    in.height = 60;
    auto first = gl().bakeHeightMaps(in);
    ASSERT_TRUE(first) << first.error().message;
    expectMatchesCpu(*first, in);

    const float* address = base.data.data();
    for (float& v : base.data) v = 0.5f - 0.75f * v;
    ASSERT_EQ(base.data.data(), address);
    const auto before = gl().stats();
    auto second = gl().bakeHeightMaps(in);
    ASSERT_TRUE(second) << second.error().message;
    EXPECT_EQ(gl().stats().heightPasses, before.heightPasses + 1) << "the pass must run again";
    EXPECT_NE(second->bump.data, first->bump.data);
    expectMatchesCpu(*second, in);
}

TEST_F(RendererGLTest, PatternWithoutAnIdIsUploadedAgainWhenItsPixelsChangeInPlace) {
    HeightImage pattern = testPattern(48, 32, 1.0, 1.5);
    BakePlacement p;
    p.pattern = &pattern; // patternId 0: the renderer hashes the pixels
    p.footprint.center = {0.5, 0.45};
    p.footprint.scale = {0.6, 0.5};
    p.footprint.rotationDeg = 20.0;
    p.target = Target::Displacement;
    p.t = 0.6;
    HeightPassInput in;
    in.placements = {p};
    in.width = 96;
    in.height = 96;
    auto first = gl().bakeHeightMaps(in);
    ASSERT_TRUE(first) << first.error().message;
    expectMatchesCpu(*first, in);

    const float* address = pattern.data.data();
    for (float& v : pattern.data) v = -v;
    ASSERT_EQ(pattern.data.data(), address);
    const auto before = gl().stats();
    auto second = gl().bakeHeightMaps(in);
    ASSERT_TRUE(second) << second.error().message;
    EXPECT_EQ(gl().stats().heightPasses, before.heightPasses + 1) << "the pass must run again";
    EXPECT_NE(second->displacement.data, first->displacement.data);
    expectMatchesCpu(*second, in);
}

TEST_F(RendererGLTest, PatternTexturesAreCachedByContentId) {
    const auto a = makePatternImage(testPattern(32, 32, 1.0, 2.0));
    const auto b = makePatternImage(testPattern(32, 32, 2.5, 0.5));
    ASSERT_NE(a->contentId, b->contentId);
    auto inputFor = [](const PatternImage& image) {
        BakePlacement p;
        p.pattern = &image.pixels;
        p.patternId = image.contentId;
        p.footprint.center = {0.5, 0.5};
        p.footprint.scale = {0.5, 0.5};
        p.t = 0.7;
        HeightPassInput in;
        in.placements = {p};
        in.width = 64;
        in.height = 64;
        return in;
    };
    auto mapA = gl().bakeHeightMaps(inputFor(*a));
    auto mapB = gl().bakeHeightMaps(inputFor(*b));
    ASSERT_TRUE(mapA && mapB);
    // Different ids with different pixels: different maps, each the CPU reference's.
    EXPECT_NE(mapA->bump.data, mapB->bump.data);
    expectMatchesCpu(*mapA, inputFor(*a));
    expectMatchesCpu(*mapB, inputFor(*b));

    // The same inputs again: the height pass is skipped and the maps are the same.
    auto before = gl().stats();
    auto again = gl().bakeHeightMaps(inputFor(*b));
    ASSERT_TRUE(again);
    EXPECT_EQ(gl().stats().heightPassesSkipped, before.heightPassesSkipped + 1);
    EXPECT_EQ(again->bump.data, mapB->bump.data);

    // Back to a's id: its cached texture is used, bit for bit the first map.
    before = gl().stats();
    auto backToA = gl().bakeHeightMaps(inputFor(*a));
    ASSERT_TRUE(backToA);
    EXPECT_EQ(gl().stats().heightPasses, before.heightPasses + 1);
    EXPECT_EQ(backToA->bump.data, mapA->bump.data);

    // An id names its content: a placement that gives a's id is drawn with a's cached texture,
    // whatever pixels it points to (PatternImage ids are never reused for other pixels).
    HeightPassInput mislabelled = inputFor(*b);
    mislabelled.placements[0].patternId = a->contentId;
    mislabelled.placements[0].h = 1.0 + 1e-9; // not the key of the maps the targets hold
    before = gl().stats();
    auto byId = gl().bakeHeightMaps(mislabelled);
    ASSERT_TRUE(byId);
    EXPECT_EQ(gl().stats().heightPasses, before.heightPasses + 1);
    EXPECT_EQ(byId->bump.data, mapA->bump.data);

    // After forgetPatterns the textures are uploaded again from the pixels given.
    gl().forgetPatterns();
    auto reloaded = gl().bakeHeightMaps(inputFor(*a));
    ASSERT_TRUE(reloaded);
    EXPECT_EQ(reloaded->bump.data, mapA->bump.data);
}

// --- stage 2: skinning --------------------------------------------------------------------------

void expectGpuSkinningMatchesCpu(Renderer& gl, const std::shared_ptr<const Model>& model) {
    ASSERT_TRUE(model);
    std::vector<LocalPose> poses = {restPose(*model)};
    for (std::size_t c = 0; c < model->clips.size() && c < 4; ++c)
        for (float f : {0.3f, 0.8f})
            poses.push_back(sampleClip(*model, static_cast<int>(c), f * model->clips[c].duration));
    std::size_t vertices = 0;
    for (const LocalPose& pose : poses) {
        const auto world = worldMatrices(*model, pose);
        const auto cpu = skin(*model, world);
        auto gpu = gl.skinOnGpu(model, world);
        ASSERT_TRUE(gpu) << gpu.error().message;
        ASSERT_EQ(gpu->size(), cpu.size());
        float maxPos = 0.0f, minDot = 1.0f;
        for (std::size_t pi = 0; pi < cpu.size(); ++pi) {
            ASSERT_EQ((*gpu)[pi].positions.size(), cpu[pi].positions.size());
            for (std::size_t v = 0; v < cpu[pi].positions.size(); ++v) {
                maxPos = std::max(maxPos, glm::length((*gpu)[pi].positions[v] - cpu[pi].positions[v]));
                minDot = std::min(minDot, glm::dot((*gpu)[pi].normals[v], cpu[pi].normals[v]));
                ++vertices;
            }
        }
        EXPECT_LE(maxPos, 1e-4f);
        EXPECT_GE(minDot, 0.9999f);
    }
    EXPECT_GT(vertices, 1000u);
}

TEST_F(RendererGLTest, GpuSkinningEqualsCpuSkinningOnCesiumMan) {
    expectGpuSkinningMatchesCpu(gl(), loadModel(kCesium));
}

TEST_F(RendererGLTest, GpuSkinningEqualsCpuSkinningOnTheDefaultCharacter) {
    expectGpuSkinningMatchesCpu(gl(), loadModel(kSource + "/models/default.glb"));
}

// --- stage 2: frames ----------------------------------------------------------------------------

/// Renders `model` posed by clip 0 at `time` with no placements.
Result<FrameResult> renderModel(Renderer& gl, const std::shared_ptr<const Model>& model,
                                double time, int size = 192) {
    Scene scene;
    scene.render.size = {size, size};
    scene.heightmapSize = {256, 256};
    PatternImages none;
    auto frame = makeSceneFrame(scene, model, none, nullptr, {time});
    if (!frame) return frame.error();
    return gl.renderFrame(frame->request);
}

void expectFramesChangeWithTime(Renderer& gl, const std::string& path, int clip) {
    auto model = loadModel(path);
    ASSERT_TRUE(model);
    ASSERT_GT(model->clips.size(), static_cast<std::size_t>(clip));
    const double d = model->clips[static_cast<std::size_t>(clip)].duration;
    std::vector<Image8> frames;
    for (double f : {0.1, 0.45, 0.8}) {
        auto r = renderModel(gl, model, f * d);
        ASSERT_TRUE(r) << r.error().message;
        EXPECT_EQ(r->image.width, 192);
        EXPECT_EQ(r->image.rgba.size(), 192u * 192u * 4u);
        const double cov = coverage(r->image);
        EXPECT_GT(cov, 0.04) << path << " at " << f * d << " s is (nearly) empty";
        EXPECT_LT(cov, 0.9) << path << ": the character should not fill the frame";
        frames.push_back(std::move(r->image));
    }
    EXPECT_GT(meanAbsDiff(frames[0], frames[1]), 0.2) << path;
    EXPECT_GT(meanAbsDiff(frames[1], frames[2]), 0.2) << path;
}

TEST_F(RendererGLTest, FramesOfCesiumManAreNonEmptyAndChangeWithTime) {
    expectFramesChangeWithTime(gl(), kCesium, 0);
}

TEST_F(RendererGLTest, FramesOfTheBarbarianAreNonEmptyAndChangeWithTime) {
    auto model = loadModel(kBarbarian);
    ASSERT_TRUE(model);
    // A clip with visible motion: the first whose name says it walks or runs, else clip 0.
    int clip = 0;
    for (std::size_t c = 0; c < model->clips.size(); ++c)
        if (model->clips[c].name.find("Walking") != std::string::npos) {
            clip = static_cast<int>(c);
            break;
        }
    expectFramesChangeWithTime(gl(), kBarbarian, clip);
}

} // namespace

// Issue #13 "no cliff": on a software rasterizer a height pass covering many map areas is baked by
// the CPU and uploaded (RendererOptions::softwareCpuBakeCoverage, default 2 map areas); on a
// hardware GL, with the option at 0, or for a small pass, the GL pass runs. The maps equal the
// CPU reference either way.
TEST_F(RendererGLTest, LargeHeightPassesOnASoftwareRasterizerAreBakedByTheCpu) {
    const auto pattern = makePatternImage(testPattern(64, 64, 2.0, 1.5));
    HeightPassInput in;
    in.width = 160;
    in.height = 120;
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(0.1, 0.9), rot(-180, 180);
    for (int k = 0; k < 60; ++k) { // 60 × 0.25 × 0.2 = 3 map areas
        BakePlacement p;
        p.pattern = &pattern->pixels;
        p.patternId = pattern->contentId;
        p.footprint.center = {u(rng), u(rng)};
        p.footprint.scale = {0.25, 0.2};
        p.footprint.rotationDeg = rot(rng);
        p.t = 0.3 + 0.01 * k;
        p.model = k % 2 ? DeformModel::Bias : DeformModel::Scale;
        p.target = k % 3 ? Target::Bump : Target::Displacement;
        in.placements.push_back(p);
    }
    const std::string name = gl().info().renderer;
    const bool software = name.find("llvmpipe") != std::string::npos ||
                          name.find("softpipe") != std::string::npos ||
                          name.find("swrast") != std::string::npos;
    const auto before = gl().stats();
    auto maps = gl().bakeHeightMaps(in);
    ASSERT_TRUE(maps) << maps.error().message;
    EXPECT_EQ(gl().stats().heightPassesOnCpu - before.heightPassesOnCpu, software ? 1u : 0u) << name;
    auto cpu = bakeHeightMaps(in);
    ASSERT_TRUE(cpu);
    if (software) { // the CPU bake itself, uploaded and read back: exact
        EXPECT_EQ(maps->bump.data, cpu->bump.data);
        EXPECT_EQ(maps->displacement.data, cpu->displacement.data);
    } else {
        expectMatchesCpu(*maps, in);
    }

    RendererOptions glOnly;
    glOnly.softwareCpuBakeCoverage = 0.0;
    auto other = Renderer::create(requestedBackend(), glOnly);
    ASSERT_TRUE(other) << other.error().message;
    auto viaGl = (*other)->bakeHeightMaps(in);
    ASSERT_TRUE(viaGl) << viaGl.error().message;
    EXPECT_EQ((*other)->stats().heightPasses, 1u);
    EXPECT_EQ((*other)->stats().heightPassesOnCpu, 0u);
    expectMatchesCpu(*viaGl, in);

    in.placements.resize(5); // 0.25 map areas: the GL pass
    const auto small = gl().stats();
    ASSERT_TRUE(gl().bakeHeightMaps(in));
    EXPECT_EQ(gl().stats().heightPasses, small.heightPasses + 1);
    EXPECT_EQ(gl().stats().heightPassesOnCpu, small.heightPassesOnCpu);
}
