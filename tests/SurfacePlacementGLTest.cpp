// SurfacePlacementGLTest — surface placements (SPEC §8) and height-map layouts on the GPU
// renderer, on a real GL context ($DERMIS_TEST_GL; ctest runs it per backend, like
// RendererGLTest): the GPU height pass equals the CPU reference (bakeHeightMaps through the
// rest-surface map) within RendererGLTest's tolerance (2e-3) away from the decals' edges, on the
// default character and on CesiumMan, mixed with UV placements; a frame drawn with a re-indexed
// copy of the model's own layout is the same frame; a frame with another layout (the second UV
// attribute) keeps the base colour and shows the same decal; a surface placement changes a frame
// only near its anchor.
#include "BuildPaths.hpp"
#include "core/bake.hpp"
#include "core/camera.hpp"
#include "core/frame_plan.hpp"
#include "core/pick.hpp"
#include "core/texture_layout.hpp"
#include "gl/renderer.hpp"
#include "io/gltf_loader.hpp"
#include "io/scene_files.hpp"

#include "ImageCompare.hpp"
#include "RendererSuite.hpp"
#include "SceneFrame.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace dermis;
using namespace dermis::test;

namespace {

const std::string kTestModels = dermis::build::testModelsDir();
const std::string kSource = dermis::build::sourceDir();
const std::string kCesium = kTestModels + "/CesiumMan/CesiumMan.glb";

class SurfacePlacementGLTest : public RendererSuite {
protected:
    void SetUp() override {
        RendererSuite::SetUp();
        if (HasFatalFailure()) return;
        auto l = loadSceneFile(kSource + "/models/default.scene.json");
        ASSERT_TRUE(l) << l.error().message;
        loaded_ = std::make_unique<LoadedScene>(std::move(*l));
        model_ = std::make_shared<const Model>(loaded_->model);
    }
    std::unique_ptr<LoadedScene> loaded_;
    std::shared_ptr<const Model> model_;
};

/// The anchor of part `pi`'s vertex `v` (bind space), with a tangent ⟂ its normal.
SurfaceAnchor anchorAt(const Model& m, std::size_t pi, std::size_t v) {
    const MeshPart& part = m.parts[pi];
    const glm::dvec3 p(part.positions[v]);
    glm::dvec3 n = part.normals.size() == part.positions.size() ? glm::dvec3(part.normals[v])
                                                                : glm::dvec3(0, 0, 1);
    n = glm::normalize(n);
    const glm::dvec3 helper = std::abs(n.y) < 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0);
    const glm::dvec3 t = glm::normalize(helper - glm::dot(helper, n) * n);
    SurfaceAnchor a;
    a.position = {p.x, p.y, p.z};
    a.normal = {n.x, n.y, n.z};
    a.tangent = {t.x, t.y, t.z};
    return a;
}

/// The model's size: the largest extent of its bind-space bounds (sizes in model units follow it;
/// bind space need not be y-up).
double modelHeight(const Model& m) {
    glm::dvec3 lo(1e30), hi(-1e30);
    for (const MeshPart& p : m.parts)
        for (const glm::vec3& q : p.positions) {
            lo = glm::min(lo, glm::dvec3(q));
            hi = glm::max(hi, glm::dvec3(q));
        }
    const glm::dvec3 e = hi - lo;
    const double size = std::max(e.x, std::max(e.y, e.z));
    return size > 0.0 ? size : 1.0;
}

/// A surface placement of `pattern` at part `pi` vertex `v`, driven by `joint` so that t = 1 in
/// any pose (θ range [−360, −359] about x; θ is in (−180, 180]).
Placement surfacePlacement(const Model& m, const std::string& id, const std::string& pattern,
                           const std::string& joint, std::size_t pi, std::size_t v, double size,
                           double rotation = 0.0) {
    Placement p;
    p.id = id;
    p.pattern = pattern;
    p.joint = joint;
    p.thetaMin = -360;
    p.thetaMax = -359;
    p.projection = Projection::Surface;
    p.anchor = anchorAt(m, pi, v);
    p.size = {size, 0.7 * size};
    p.rotation = rotation;
    return p;
}

/// The first joint name of `m` (every placement needs a driver).
std::string someJoint(const Model& m) {
    return m.joints.empty() ? m.nodes.front().name : m.nodes[static_cast<std::size_t>(m.joints.front())].name;
}

/// Whether texel (i, j) lies near where a surface placement's decal is cut (the pattern square's
/// border, the depth limit, the back-face limit) or a UV placement's footprint edge: there float
/// and double rounding may decide differently.
bool nearAnEdge(const HeightMapInput& in, int i, int j) {
    const int W = in.width, H = in.height;
    const std::size_t idx = static_cast<std::size_t>(j) * W + i;
    const double margin = 2.0 * std::max(1.0 / W, 1.0 / H);
    for (const BakePlacement& p : in.placements) {
        if (p.t <= 0.0) continue;
        if (!p.surface) {
            const glm::dvec2 s = p.footprint.toPattern({(i + 0.5) / W, (j + 0.5) / H});
            const double mu = margin / p.footprint.scale.x, mv = margin / p.footprint.scale.y;
            if (s.x > -mu && s.x < 1 + mu && s.y > -mv && s.y < 1 + mv &&
                (std::abs(s.x) < mu || std::abs(s.x - 1) < mu || std::abs(s.y) < mv || std::abs(s.y - 1) < mv))
                return true;
            continue;
        }
        if (!in.rest->coverage[idx]) continue;
        const SurfaceFrame f(p);
        const glm::dvec3 d = glm::dvec3(in.rest->position[idx]) - f.c;
        const double s0 = glm::dot(d, f.t) * f.invW + 0.5, s1 = glm::dot(d, f.b) * f.invH + 0.5;
        const double dn = std::abs(glm::dot(d, f.n)), facing = glm::dot(glm::dvec3(in.rest->normal[idx]), f.n);
        constexpr double e = 1e-4;
        if (std::abs(s0) < e || std::abs(s0 - 1) < e || std::abs(s1) < e || std::abs(s1 - 1) < e ||
            std::abs(dn - f.depth) < e * f.depth || std::abs(facing) < e)
            return true;
    }
    return false;
}

struct Comparison {
    float maxDiff = 0.0f;
    std::size_t compared = 0, nonZero = 0;
};

Comparison compare(const HeightImage& gpu, const HeightImage& cpu, const HeightMapInput& in) {
    Comparison c;
    for (int j = 0; j < cpu.height; ++j)
        for (int i = 0; i < cpu.width; ++i) {
            if (nearAnEdge(in, i, j)) continue;
            ++c.compared;
            if (cpu.at(i, j) != 0.0f) ++c.nonZero;
            c.maxDiff = std::max(c.maxDiff, std::abs(gpu.at(i, j) - cpu.at(i, j)));
        }
    return c;
}

/// GPU height pass vs the CPU reference for the plan of `scene` on `model`.
void expectGpuEqualsCpu(Renderer& gl, const Scene& scene, const std::shared_ptr<const Model>& model,
                        const PatternImages& images, std::size_t minNonZero) {
    auto plan = planFrame(scene, *model, images, nullptr);
    ASSERT_TRUE(plan) << plan.error().message;
    const HeightMapInput& in = plan->heights;
    ASSERT_TRUE(in.rest);
    auto gpu = gl.bakeHeightMaps(in);
    ASSERT_TRUE(gpu) << gpu.error().message;
    auto cpu = bakeHeightMaps(in);
    ASSERT_TRUE(cpu) << cpu.error().message;
    for (auto [g, c, name] : {std::tuple{&gpu->bump, &cpu->bump, "bump"},
                              std::tuple{&gpu->displacement, &cpu->displacement, "displacement"}}) {
        const Comparison r = compare(*g, *c, in);
        EXPECT_LE(r.maxDiff, 2e-3f) << name;
        EXPECT_GT(r.compared, static_cast<std::size_t>(in.width) * in.height * 9 / 10) << name;
        EXPECT_GT(r.nonZero, minNonZero) << name << ": the comparison must cover deformed texels";
    }
}

/// `m`'s own layout with every part's vertex list reversed (same triangles, same corners, same
/// UVs: the same texture space indexed differently).
TextureLayout reversedModelLayout(const Model& m) {
    TextureLayout l = modelTextureLayout(m);
    for (PartLayout& p : l.parts) {
        const std::size_t n = p.source.size();
        PartLayout q;
        for (std::size_t v = 0; v < n; ++v) {
            q.source.push_back(p.source[n - 1 - v]);
            q.uvs.push_back(p.uvs[n - 1 - v]);
        }
        for (std::uint32_t i : p.indices) q.indices.push_back(static_cast<std::uint32_t>(n - 1 - i));
        p = std::move(q);
    }
    return l;
}

/// `m`'s own layout transposed and shrunk into [0.05, 0.95]² (another texture space: a UV
/// placement lands elsewhere, a surface placement on the same skin).
TextureLayout transposedModelLayout(const Model& m) {
    TextureLayout l = modelTextureLayout(m);
    l.kind = "generated";
    for (PartLayout& p : l.parts)
        for (glm::vec2& uv : p.uvs) uv = glm::vec2(0.05f + 0.9f * uv.y, 0.05f + 0.9f * uv.x);
    return l;
}

/// Pixels whose colour differs by more than `threshold` in a channel: count and their bounds.
struct Changed {
    std::size_t count = 0;
    int x0 = 1 << 30, y0 = 1 << 30, x1 = -1, y1 = -1;
};
Changed changedPixels(const Image8& a, const Image8& b, int threshold = 2) {
    Changed c;
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x) {
            const std::size_t p = (static_cast<std::size_t>(y) * a.width + x) * 4;
            bool diff = false;
            for (int k = 0; k < 3; ++k) diff = diff || std::abs(int(a.rgba[p + k]) - int(b.rgba[p + k])) > threshold;
            if (!diff) continue;
            ++c.count;
            c.x0 = std::min(c.x0, x);
            c.y0 = std::min(c.y0, y);
            c.x1 = std::max(c.x1, x);
            c.y1 = std::max(c.y1, y);
        }
    return c;
}

/// A vertex of `m` (part, vertex) that the camera of `plan` sees: its posed normal within ~45°
/// of the direction to the eye and nothing in front of it (a pick at its pixel hits within 1 %
/// of the model's size). Of those, the one with the most skin weight on `node` (any joint: −1,
/// then the one nearest the middle of the posed bounds' height). Part −1 when none is seen.
std::pair<int, std::size_t> facingVertex(const Model& m, const FramePlan& plan, int node) {
    const std::vector<SkinnedPart> posed = skin(m, plan.world);
    const FrameCamera cam = planCamera(plan, m);
    const Bounds bounds = framingBounds(posed);
    const float midY = 0.5f * (bounds.min.y + bounds.max.y);
    const float tolerance = 0.01f * glm::length(bounds.max - bounds.min);
    std::vector<std::pair<float, std::pair<int, std::size_t>>> candidates;
    for (std::size_t pi = 0; pi < m.parts.size(); ++pi) {
        const MeshPart& part = m.parts[pi];
        for (std::size_t v = 0; v < posed[pi].positions.size(); ++v) {
            const glm::vec3 toEye = glm::normalize(cam.eye - posed[pi].positions[v]);
            if (glm::dot(posed[pi].normals[v], toEye) < 0.7f) continue;
            float score = -std::abs(posed[pi].positions[v].y - midY);
            if (node >= 0) {
                score = 0.0f;
                for (int c = 0; c < 4 && v < part.joints.size(); ++c)
                    if (part.joints[v][c] < part.influences.size() &&
                        part.influences[part.joints[v][c]].node == node)
                        score += part.weights[v][c];
            }
            candidates.push_back({score, {static_cast<int>(pi), v}});
        }
    }
    std::stable_sort(candidates.begin(), candidates.end(),
                     [](const auto& a, const auto& b) { return a.first > b.first; });
    for (std::size_t k = 0; k < candidates.size() && k < 400; ++k) {
        const auto [pi, v] = candidates[k].second;
        const glm::vec3 p = posed[static_cast<std::size_t>(pi)].positions[v];
        const auto px = projectToPixel(cam, p);
        if (!px || px->x < 0 || px->y < 0 || px->x >= cam.width || px->y >= cam.height) continue;
        auto hit = pickFrame(plan, m, px->x, px->y);
        if (hit && *hit && glm::length((*hit)->position - p) < tolerance) return candidates[k].second;
    }
    return {-1, 0};
}

/// The changed pixels' mean absolute difference (colour channels) of a and b, over the pixels
/// where `ref0` and `ref1` differ (the decal's region).
double meanAbsDiffWhere(const Image8& a, const Image8& b, const Image8& ref0, const Image8& ref1) {
    double s = 0.0;
    std::size_t n = 0;
    for (std::size_t p = 0; p + 3 < a.rgba.size(); p += 4) {
        bool region = false;
        for (int k = 0; k < 3; ++k) region = region || std::abs(int(ref0.rgba[p + k]) - int(ref1.rgba[p + k])) > 2;
        if (!region) continue;
        for (int k = 0; k < 3; ++k) s += std::abs(int(a.rgba[p + k]) - int(b.rgba[p + k]));
        n += 3;
    }
    return n ? s / static_cast<double>(n) : 0.0;
}

} // namespace

// --- stage 1: GPU = CPU -------------------------------------------------------------------------

TEST_F(SurfacePlacementGLTest, HeightPassEqualsTheCpuReferenceOnTheDefaultCharacter) {
    Scene scene = loaded_->scene; // its UV placements stay: mixed in document order
    scene.pose.animation.reset();
    scene.pose.time = 0.0;
    scene.heightmapSize = {512, 512};
    const Model& m = *model_;
    const double size = 0.12 * modelHeight(m);
    const std::string joint = someJoint(m);
    int k = 0;
    for (std::size_t pi = 0; pi < m.parts.size(); ++pi) {
        const std::size_t n = m.parts[pi].positions.size();
        for (std::size_t v : {n / 7, n / 2, (5 * n) / 6}) {
            Placement p = surfacePlacement(m, "surface_" + std::to_string(k), k % 2 ? "crease" : "round_bulge",
                                           joint, pi, v, size, 25.0 * k);
            p.target = k % 3 == 0 ? Target::Displacement : Target::Bump;
            p.model = k % 4 == 1 ? DeformModel::Bias : DeformModel::Scale;
            if (k % 2) p.thetaMax = 360; // t strictly between 0 and 1 (every response path)
            scene.placements.push_back(p);
            ++k;
        }
    }
    expectGpuEqualsCpu(gl(), scene, model_, loaded_->images, 1000);
}

TEST_F(SurfacePlacementGLTest, HeightPassEqualsTheCpuReferenceOnCesiumMan) {
    auto loaded = loadGltfFile(kCesium);
    ASSERT_TRUE(loaded) << loaded.error().message;
    auto model = std::make_shared<const Model>(std::move(*loaded));
    Scene scene;
    scene.heightmapSize = {512, 512};
    const double size = 0.15 * modelHeight(*model);
    const std::string joint = someJoint(*model);
    int k = 0;
    for (std::size_t pi = 0; pi < model->parts.size(); ++pi) {
        const std::size_t n = model->parts[pi].positions.size();
        for (std::size_t v : {n / 5, n / 3, n / 2, (4 * n) / 5}) {
            Placement p = surfacePlacement(*model, "s" + std::to_string(k), k % 2 ? "crease" : "round_bulge",
                                           joint, pi, v, size, -40.0 * k);
            p.target = k % 2 ? Target::Displacement : Target::Bump;
            scene.placements.push_back(p);
            ++k;
        }
    }
    expectGpuEqualsCpu(gl(), scene, model, loaded_->images, 2000);
}

TEST_F(SurfacePlacementGLTest, HeightPassNeedsTheRestMap) {
    Scene scene;
    scene.heightmapSize = {64, 64};
    scene.placements.push_back(surfacePlacement(*model_, "s", "crease", someJoint(*model_), 0, 10, 0.2));
    auto plan = planFrame(scene, *model_, loaded_->images, nullptr);
    ASSERT_TRUE(plan) << plan.error().message;
    HeightMapInput in = plan->heights;
    in.rest.reset();
    auto r = gl().bakeHeightMaps(in);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().field, "/placements/0/projection");
}

// --- stage 2: the second UV attribute --------------------------------------------------------------

TEST_F(SurfacePlacementGLTest, AReindexedCopyOfTheModelLayoutGivesTheSameFrame) {
    Scene scene = loaded_->scene;
    scene.pose.animation = "elbow_curl";
    scene.pose.time = 1.0;
    scene.render.size = {256, 256};
    scene.placements.push_back(surfacePlacement(*model_, "s", "round_bulge", someJoint(*model_), 0,
                                                model_->parts[0].positions.size() / 2,
                                                0.15 * modelHeight(*model_)));
    auto own = makeSceneFrame(scene, model_, loaded_->images, nullptr);
    ASSERT_TRUE(own) << own.error().message;
    auto a = gl().renderFrame(own->request);
    ASSERT_TRUE(a) << a.error().message;

    FrameOverrides o;
    o.layout = std::make_shared<const TextureLayout>(reversedModelLayout(*model_));
    auto plan = planFrame(scene, *model_, loaded_->images, nullptr, o);
    ASSERT_TRUE(plan) << plan.error().message;
    FrameRequest req = frameRequest(*plan, model_);
    EXPECT_EQ(req.layout, o.layout);
    auto b = gl().renderFrame(req);
    ASSERT_TRUE(b) << b.error().message;
    EXPECT_EQ(meanAbsDiff(a->image, b->image), 0.0);
    // The tessellated path reads the map UV too.
    scene.render.displacement = DisplacementMode::Tessellated;
    auto ownT = makeSceneFrame(scene, model_, loaded_->images, nullptr);
    ASSERT_TRUE(ownT);
    auto planT = planFrame(scene, *model_, loaded_->images, nullptr, o);
    ASSERT_TRUE(planT);
    auto at = gl().renderFrame(ownT->request);
    auto bt = gl().renderFrame(frameRequest(*planT, model_));
    ASSERT_TRUE(at && bt);
    EXPECT_EQ(meanAbsDiff(at->image, bt->image), 0.0);
}

TEST_F(SurfacePlacementGLTest, AnotherLayoutShowsTheSameDecalAndKeepsTheBaseColour) {
    auto loaded = loadGltfFile(kCesium); // a textured model: the base colour uses the model's UVs
    ASSERT_TRUE(loaded) << loaded.error().message;
    auto model = std::make_shared<const Model>(std::move(*loaded));
    Scene scene;
    scene.render.size = {256, 256};
    scene.render.displacementScale = 0.0; // bump only: the silhouette stays
    scene.render.bumpStrength = 4.0;
    scene.heightmapSize = {1024, 1024};
    {
        auto plan = planFrame(scene, *model, loaded_->images, nullptr);
        ASSERT_TRUE(plan) << plan.error().message;
        const auto [pi, v] = facingVertex(*model, *plan, -1);
        ASSERT_GE(pi, 0);
        scene.placements.push_back(surfacePlacement(*model, "s", "crease", someJoint(*model),
                                                    static_cast<std::size_t>(pi), v,
                                                    0.15 * modelHeight(*model)));
    }
    Scene off = scene;
    off.placements[0].enabled = false;

    auto render = [&](const Scene& s, std::shared_ptr<const TextureLayout> layout) -> Result<Image8> {
        FrameOverrides o;
        o.layout = std::move(layout);
        auto plan = planFrame(s, *model, loaded_->images, nullptr, o);
        if (!plan) return plan.error();
        auto r = gl().renderFrame(frameRequest(*plan, model));
        if (!r) return r.error();
        return r->image;
    };
    const auto other = std::make_shared<const TextureLayout>(transposedModelLayout(*model));
    auto ownOff = render(off, nullptr), otherOff = render(off, other);
    auto ownOn = render(scene, nullptr), otherOn = render(scene, other);
    ASSERT_TRUE(ownOff && otherOff && ownOn && otherOn);
    // Without patterns the layout changes nothing: the base colour keeps the model's UVs.
    EXPECT_EQ(meanAbsDiff(*ownOff, *otherOff), 0.0);
    // The decal changes the frame in both layouts, and the same way (the maps differ only by
    // where their texels fall on the skin): compared over the pixels the decal changes.
    const Changed own = changedPixels(*ownOn, *ownOff), moved = changedPixels(*otherOn, *otherOff);
    EXPECT_GT(own.count, 100u);
    EXPECT_GT(moved.count, 100u);
    const double effect = meanAbsDiffWhere(*ownOn, *ownOff, *ownOn, *ownOff);
    const double between = meanAbsDiffWhere(*ownOn, *otherOn, *ownOn, *ownOff);
    EXPECT_GT(effect, 4.0);
    EXPECT_LT(between, 0.25 * effect) << "effect " << effect;
}

TEST_F(SurfacePlacementGLTest, ASurfacePlacementChangesTheFrameOnlyNearItsAnchor) {
    Scene scene = loaded_->scene;
    scene.placements.clear();
    scene.pose.animation.reset();
    scene.render.size = {256, 256};
    scene.render.bumpStrength = 4.0;
    const Model& m = *model_;
    auto a = makeSceneFrame(scene, model_, loaded_->images, nullptr);
    ASSERT_TRUE(a) << a.error().message;
    const std::vector<SkinnedPart> posed = skin(m, a->plan->world);
    const FrameCamera cam = planCamera(*a->plan, m);
    // On the default character's left forearm, facing the camera.
    const auto [bestPartI, bestVertex] = facingVertex(m, *a->plan, m.findJoint("forearm.l"));
    ASSERT_GE(bestPartI, 0);
    const std::size_t bestPart = static_cast<std::size_t>(bestPartI);
    const double size = 0.06 * modelHeight(m);
    Scene on = scene;
    on.placements.push_back(surfacePlacement(m, "elbow", "round_bulge", "forearm.l", bestPart, bestVertex, size));
    on.placements[0].target = Target::Bump;
    auto b = makeSceneFrame(on, model_, loaded_->images, nullptr);
    ASSERT_TRUE(b) << b.error().message;
    auto fa = gl().renderFrame(a->request);
    auto fb = gl().renderFrame(b->request);
    ASSERT_TRUE(fa && fb);
    const Changed c = changedPixels(fa->image, fb->image);
    EXPECT_GT(c.count, 20u);
    // Where the anchor lands in the picture (posed), and how far the decal reaches there.
    const glm::vec3 anchor = posed[bestPart].positions[bestVertex];
    const auto px = projectToPixel(cam, anchor);
    ASSERT_TRUE(px);
    const auto edge = projectToPixel(cam, anchor + static_cast<float>(size) * glm::normalize(glm::cross(
                                                       posed[bestPart].normals[bestVertex], glm::vec3(0, 1, 0))));
    ASSERT_TRUE(edge);
    const double reach = 1.5 * glm::length(*edge - *px) + 6.0;
    EXPECT_LE(std::max(std::abs(c.x0 - px->x), std::abs(c.x1 - px->x)), reach);
    EXPECT_LE(std::max(std::abs(c.y0 - px->y), std::abs(c.y1 - px->y)), reach);
}

TEST_F(SurfacePlacementGLTest, AFrameDependsOnItsInputsOnlyAfterCpuBakedMaps) {
    // The default scene's 18 placements are baked by the CPU on a software rasterizer
    // (RendererOptions::softwareCpuBakeCoverage); the frame without placements after it must be
    // the frame without placements rendered cold (a stale-texture issue of llvmpipe, height_pass).
    Scene on = loaded_->scene;
    on.render.size = {128, 128};
    on.render.msaa = 1;
    Scene off = on;
    for (Placement& p : off.placements) p.enabled = false;
    auto render = [&](const Scene& s) -> Image8 {
        auto f = makeSceneFrame(s, model_, loaded_->images, nullptr);
        EXPECT_TRUE(f);
        if (!f) return {};
        auto r = gl().renderFrame(f->request);
        EXPECT_TRUE(r);
        return r ? r->image : Image8{};
    };
    const Image8 cold = render(off);
    const Image8 deformed = render(on);
    const Image8 after = render(off);
    EXPECT_GT(meanAbsDiff(cold, deformed), 0.0);
    EXPECT_EQ(meanAbsDiff(cold, after), 0.0);
}
