// ModelDerivedTest — the per-model derived data (core ModelDerived, ModelDerivedSlot) that lint,
// the picks and mirror share: the cached UV index and symmetry plane equal freshly computed ones
// (default character, CesiumMan) and the cached driver suggestions core suggestDriver's (also
// the KayKit Barbarian, many clips), and core mirrorPlacement and lintScene give identical answers
// with the cached rest skin and plane as without (all three models); each piece is built once per
// model, on first use, also when
// many threads ask at once; a slot hands out the same object for the same model and a new one
// for another; the object keeps its model alive and is freed with its last holder. Through the
// Service (CPU, no renderer needed): pick by UV, mirror and lint answer what the core computes
// with fresh data, repeatedly, and deleting the model frees it with its derived data. No GL, no
// HTTP.
#include "BuildPaths.hpp"
#include "TestFiles.hpp"
#include "core/lint.hpp"
#include "core/model_derived.hpp"
#include "core/pick.hpp"
#include "core/propose.hpp"
#include "gl/renderer.hpp"
#include "io/gltf_loader.hpp"
#include "io/scene_files.hpp"
#include "service/service.hpp"

#include <gtest/gtest.h>

#include <memory>
#include <thread>
#include <vector>

using namespace dermis;
using json = nlohmann::json;

namespace {

const std::string kSource = dermis::build::sourceDir();
const std::string kCesium =
    std::string(dermis::build::testModelsDir()) + "/CesiumMan/CesiumMan.glb";
const std::string kBarbarian =
    std::string(dermis::build::testModelsDir()) + "/KayKitBarbarian/Barbarian.glb";

std::shared_ptr<const Model> loadShared(const std::string& path) {
    auto m = loadGltfFile(path);
    EXPECT_TRUE(m) << path << ": " << (m ? "" : m.error().message);
    return m ? std::make_shared<const Model>(std::move(*m)) : nullptr;
}

std::shared_ptr<const Model> defaultCharacter() {
    return loadShared(resolveModelPath("builtin:default", "", kSource));
}

/// The cached lookup answers like a fresh one at every point of a 97×97 UV grid, and the cached
/// plane is the fresh plane.
void expectSameAsFresh(const std::shared_ptr<const Model>& model) {
    const ModelDerived derived(model);
    const UvLookup fresh(*model);
    int hits = 0;
    for (int j = 0; j < 97; ++j)
        for (int i = 0; i < 97; ++i) {
            const glm::dvec2 uv{(i + 0.5) / 97.0, (j + 0.5) / 97.0};
            const auto a = derived.uvLookup().find(uv), b = fresh.find(uv);
            ASSERT_EQ(a.has_value(), b.has_value()) << uv.x << ", " << uv.y;
            if (!a) continue;
            ++hits;
            EXPECT_EQ(a->part, b->part);
            EXPECT_EQ(a->triangle, b->triangle);
            EXPECT_EQ(a->chart, b->chart);
            EXPECT_EQ(a->bary, b->bary);
            EXPECT_EQ(derived.uvLookup().position(*a), fresh.position(*b));
        }
    EXPECT_GT(hits, 500); // the grid meets the atlas
    EXPECT_EQ(derived.uvLookup().chartCount(), fresh.chartCount());
    const SymmetryPlane plane = symmetryPlane(*model);
    EXPECT_EQ(derived.symmetryPlane().axis, plane.axis);
    EXPECT_EQ(derived.symmetryPlane().offset, plane.offset);
    EXPECT_EQ(derived.symmetryPlane().error, plane.error);
}

/// The cached driver suggestion equals core suggestDriver at the skin under every hit of a 41×41
/// UV grid (and for an empty list); the clips are sampled once.
void expectSameSuggestions(const std::shared_ptr<const Model>& model) {
    const ModelDerived derived(model);
    int compared = 0;
    for (int j = 0; j < 41; ++j)
        for (int i = 0; i < 41; ++i) {
            const auto hit =
                pickUv(*model, derived.uvLookup(), {(i + 0.5) / 41.0, (j + 0.5) / 41.0});
            if (!hit) continue;
            const SuggestedDriver a = derived.suggestDriver(hit->joints);
            const SuggestedDriver b = suggestDriver(*model, hit->joints);
            ASSERT_EQ(a.joint, b.joint) << i << ", " << j;
            EXPECT_EQ(a.axis, b.axis);
            EXPECT_EQ(a.thetaMin, b.thetaMin);
            EXPECT_EQ(a.thetaMax, b.thetaMax);
            ++compared;
        }
    EXPECT_GT(compared, 100);
    EXPECT_EQ(derived.clipRangeBuilds(), model->clips.empty() ? 0 : 1);
    EXPECT_EQ(derived.suggestDriver({}).joint, "");
}

/// Core mirrorPlacement and lintScene with the cached rest skin, plane and lookup answer exactly
/// what they answer computing everything per call: twins of placements on every skin joint over
/// a UV grid, then lint of a scene holding those placements and their twins (every second twin
/// turned by 30°, so that mirror pairs are both symmetric and not).
void expectSameMirrorAndLint(const std::shared_ptr<const Model>& model) {
    const ModelDerived derived(model);
    const UvLookup fresh(*model);
    const SymmetryPlane plane = symmetryPlane(*model);
    const RestSkin rest = restSkin(*model);
    ASSERT_EQ(derived.restSkin().world.size(), rest.world.size());
    for (std::size_t n = 0; n < rest.world.size(); ++n)
        EXPECT_EQ(derived.restSkin().world[n], rest.world[n]);
    ASSERT_EQ(derived.restSkin().parts.size(), rest.parts.size());
    for (std::size_t k = 0; k < rest.parts.size(); ++k)
        EXPECT_EQ(derived.restSkin().parts[k].positions, rest.parts[k].positions);
    EXPECT_EQ(derived.restSkin().bounds.min, rest.bounds.min);
    EXPECT_EQ(derived.restSkin().bounds.max, rest.bounds.max);
    EXPECT_EQ(derived.symmetryPlane().axis, plane.axis);
    EXPECT_EQ(derived.symmetryPlane().offset, plane.offset);
    EXPECT_EQ(derived.symmetryPlane().error, plane.error);
    EXPECT_EQ(symmetryPlane(rest).offset, plane.offset);

    Scene scene;
    int mirrored = 0, k = 0;
    for (int j = 0; j < 9; ++j)
        for (int i = 0; i < 9; ++i, ++k) {
            Placement p;
            p.id = "p" + std::to_string(k);
            p.pattern = "crease";
            p.center = {(i + 0.5) / 9.0, (j + 0.5) / 9.0};
            p.scale = {0.04, 0.07};
            p.rotation = 10.0 * k;
            const int node = model->joints[static_cast<std::size_t>(k) % model->joints.size()];
            p.joint = model->nodes[static_cast<std::size_t>(node)].name;
            p.axisName = k % 2 ? "z" : "";
            p.axis = k % 2 ? std::array<double, 3>{0, 0, 1} : std::array<double, 3>{0.6, 0.0, 0.8};
            p.thetaMin = 5.0;
            p.thetaMax = 60.0;
            const auto a = mirrorPlacement(p, *model, fresh, plane);
            const auto b = mirrorPlacement(p, *model, derived.uvLookup(), derived.symmetryPlane(),
                                           derived.restSkin());
            ASSERT_EQ(static_cast<bool>(a), static_cast<bool>(b)) << p.id;
            scene.placements.push_back(p);
            if (!a) {
                EXPECT_EQ(a.error().code, b.error().code);
                EXPECT_EQ(a.error().message, b.error().message);
                continue;
            }
            ++mirrored;
            EXPECT_EQ(a->center, b->center) << p.id;
            EXPECT_EQ(a->scale, b->scale);
            EXPECT_EQ(a->rotation, b->rotation);
            EXPECT_EQ(a->joint, b->joint);
            EXPECT_EQ(a->axis, b->axis);
            EXPECT_EQ(a->axisName, b->axisName);
            Placement twin = *b;
            twin.id = p.id + "_twin";
            if (mirrored % 2) twin.rotation += 30.0;
            scene.placements.push_back(twin);
        }
    EXPECT_GT(mirrored, 10);
    const PatternImages images;
    const auto a = lintScene(scene, *model, fresh, images);
    const auto b = lintScene(scene, derived, images);
    ASSERT_EQ(a.size(), b.size());
    int asymmetric = 0;
    for (std::size_t f = 0; f < a.size(); ++f) {
        EXPECT_EQ(a[f].code, b[f].code) << f;
        EXPECT_EQ(a[f].severity, b[f].severity);
        EXPECT_EQ(a[f].placement, b[f].placement);
        EXPECT_EQ(a[f].message, b[f].message);
        asymmetric += a[f].code == "mirror_asymmetric";
    }
    EXPECT_GT(asymmetric, 0); // the mirror-pair check ran
    EXPECT_EQ(derived.restSkinBuilds(), 1);
    EXPECT_EQ(derived.symmetryPlaneBuilds(), 1);
    EXPECT_EQ(derived.uvLookupBuilds(), 1);
}

/// A renderer for a service whose tests never render; keeps the models it is told to forget.
class ForgetfulRenderer final : public FrameRenderer {
public:
    ForgetfulRenderer() { info_.backend = "none"; }
    const RendererInfo& info() const override { return info_; }
    Result<HeightMaps> bakeHeightMaps(const HeightPassInput&) override { return refused(); }
    Result<FrameResult> renderFrame(const FrameRequest&) override { return refused(); }
    void forgetModel(const std::shared_ptr<const Model>& model) override {
        forgotten->push_back(model);
    }
    /// Shared with the test (the service owns the renderer).
    std::shared_ptr<std::vector<std::weak_ptr<const Model>>> forgotten =
        std::make_shared<std::vector<std::weak_ptr<const Model>>>();

private:
    static Error refused() {
        return makeError(ErrorCode::Unsupported, "test", "", "no renders here");
    }
    RendererInfo info_;
};

} // namespace

TEST(ModelDerivedTest, CachedDataEqualsFreshOnTheDefaultCharacter) {
    auto model = defaultCharacter();
    ASSERT_TRUE(model);
    expectSameAsFresh(model);
}

TEST(ModelDerivedTest, CachedDataEqualsFreshOnCesiumMan) {
    auto model = loadShared(kCesium);
    ASSERT_TRUE(model);
    expectSameAsFresh(model);
}

TEST(ModelDerivedTest, CachedDriverSuggestionsEqualCoreOnes) {
    for (const auto& model : {defaultCharacter(), loadShared(kCesium), loadShared(kBarbarian)}) {
        ASSERT_TRUE(model);
        SCOPED_TRACE(std::to_string(model->clips.size()) + " clips");
        expectSameSuggestions(model);
    }
}

TEST(ModelDerivedTest, CachedRestSkinGivesTheSameTwinsAndLint) {
    for (const auto& model : {defaultCharacter(), loadShared(kCesium), loadShared(kBarbarian)}) {
        ASSERT_TRUE(model);
        SCOPED_TRACE(std::to_string(model->joints.size()) + " joints");
        expectSameMirrorAndLint(model);
    }
}

TEST(ModelDerivedTest, EachPieceIsBuiltOnFirstUseOnly) {
    auto model = defaultCharacter();
    ASSERT_TRUE(model);
    const ModelDerived d(model);
    EXPECT_EQ(d.uvLookupBuilds(), 0);
    EXPECT_EQ(d.symmetryPlaneBuilds(), 0);
    EXPECT_EQ(d.clipRangeBuilds(), 0);
    EXPECT_EQ(d.restSkinBuilds(), 0);
    const UvLookup* first = &d.uvLookup();
    EXPECT_EQ(d.uvLookupBuilds(), 1);
    EXPECT_EQ(d.symmetryPlaneBuilds(), 0); // pick and lint never pay for the plane
    EXPECT_EQ(&d.uvLookup(), first);
    // Lint of a scene without UV placements pays for neither the UV diagnosis, nor the plane,
    // nor the rest skin.
    Scene scene;
    (void)lintScene(scene, d, PatternImages{});
    EXPECT_EQ(d.uvDiagnosisBuilds(), 0);
    EXPECT_EQ(d.symmetryPlaneBuilds(), 0);
    EXPECT_EQ(d.restSkinBuilds(), 0);
    const SymmetryPlane* plane = &d.symmetryPlane();
    EXPECT_EQ(d.restSkinBuilds(), 1); // the plane is computed from the rest skin
    EXPECT_EQ(&d.symmetryPlane(), plane);
    const RestSkin* rest = &d.restSkin();
    EXPECT_EQ(&d.restSkin(), rest);
    EXPECT_EQ(d.uvLookupBuilds(), 1);
    EXPECT_EQ(d.symmetryPlaneBuilds(), 1);
    EXPECT_EQ(d.restSkinBuilds(), 1);
    // With a UV placement it reads the UV diagnosis (built once, from the same rest skin and
    // plane), also on the next lint.
    scene.placements.push_back(Placement{});
    scene.placements.back().id = "a";
    scene.placements.back().pattern = "crease";
    scene.placements.back().joint = d.model().nodes[static_cast<std::size_t>(d.model().joints.at(0))].name;
    (void)lintScene(scene, d, PatternImages{});
    (void)lintScene(scene, d, PatternImages{});
    EXPECT_EQ(d.uvDiagnosisBuilds(), 1);
    EXPECT_EQ(d.restSkinBuilds(), 1);
    EXPECT_EQ(d.symmetryPlaneBuilds(), 1);
    const ModelDerived empty(nullptr); // an empty model: nothing to find, nothing thrown
    EXPECT_FALSE(empty.uvLookup().find({0.5, 0.5}));
    EXPECT_EQ(empty.uvLookup().chartCount(), 0);
    EXPECT_EQ(empty.symmetryPlane().axis, 0);
    EXPECT_TRUE(empty.restSkin().parts.empty());
    EXPECT_EQ(empty.suggestDriver({}).joint, "");
}

TEST(ModelDerivedTest, ASlotBuildsOncePerModelUnderConcurrentUse) {
    auto model = defaultCharacter();
    ASSERT_TRUE(model);
    ModelDerivedSlot slot;
    EXPECT_EQ(slot.peek(), nullptr);
    constexpr int kThreads = 8;
    std::vector<const ModelDerived*> derived(kThreads);
    std::vector<const UvLookup*> lookups(kThreads);
    std::vector<const SymmetryPlane*> planes(kThreads);
    std::vector<const RestSkin*> rests(kThreads);
    std::vector<std::thread> threads;
    for (int k = 0; k < kThreads; ++k)
        threads.emplace_back([&, k] {
            const auto d = slot.get(model);
            derived[k] = d.get();
            lookups[k] = &d->uvLookup();
            rests[k] = &d->restSkin();
            planes[k] = &d->symmetryPlane();
        });
    for (auto& t : threads)
        t.join();
    for (int k = 1; k < kThreads; ++k) {
        EXPECT_EQ(derived[k], derived[0]);
        EXPECT_EQ(lookups[k], lookups[0]);
        EXPECT_EQ(planes[k], planes[0]);
        EXPECT_EQ(rests[k], rests[0]);
    }
    const auto d = slot.get(model);
    EXPECT_EQ(d.get(), derived[0]);
    EXPECT_EQ(d->uvLookupBuilds(), 1);
    EXPECT_EQ(d->symmetryPlaneBuilds(), 1);
    EXPECT_EQ(d->restSkinBuilds(), 1);
    EXPECT_EQ(&d->model(), model.get());

    // Another model (here: a copy) gets its own object; holders of the old one keep theirs.
    auto copy = std::make_shared<const Model>(*model);
    const auto other = slot.get(copy);
    EXPECT_NE(other.get(), d.get());
    EXPECT_EQ(other->uvLookupBuilds(), 0);
    EXPECT_EQ(&other->model(), copy.get());
    EXPECT_EQ(d->uvLookupBuilds(), 1);
}

TEST(ModelDerivedTest, FreedWithItsLastHolderAndKeepsItsModelUntilThen) {
    auto model = defaultCharacter();
    ASSERT_TRUE(model);
    const std::weak_ptr<const Model> weakModel = model;
    auto slot = std::make_shared<ModelDerivedSlot>(); // as a model entry holds it
    auto request = slot->get(model);                  // as a request in flight holds it
    (void)request->uvLookup();
    const std::weak_ptr<const ModelDerived> weakDerived = request;
    model.reset();
    slot.reset(); // the model's entry is gone (deleted)
    EXPECT_FALSE(weakModel.expired()) << "the request's lookup points into the model";
    EXPECT_GT(request->uvLookup().chartCount(), 0); // still usable
    request.reset();
    EXPECT_TRUE(weakDerived.expired());
    EXPECT_TRUE(weakModel.expired());
}

TEST(ModelDerivedTest, ServiceRoutesAnswerAsFreshDataAndADeletedModelIsFreed) {
    test::TempDir dir;
    auto renderer = std::make_unique<ForgetfulRenderer>();
    const auto forgotten = renderer->forgotten;
    ServiceConfig config;
    config.dataDir = dir / "data";
    config.contentDir = kSource;
    auto svc = Service::open(config, std::move(renderer));
    ASSERT_TRUE(svc) << svc.error().message;
    Service& s = **svc;

    auto added = s.addModel(test::readBytes(kCesium), "cesium");
    ASSERT_TRUE(added) << added.error().message;
    const std::string modelId = (*added)["id"];
    auto loaded = loadSceneFile(kSource + "/examples/cesiumman.scene.json");
    ASSERT_TRUE(loaded) << loaded.error().message;
    const Model& model = loaded->model;
    json doc = json::parse(test::readBytes(kSource + "/examples/cesiumman.scene.json"));
    doc["model"] = modelId;
    auto created = s.createScene(doc);
    ASSERT_TRUE(created) << created.error().message;
    const std::string id = (*created)["id"];

    const UvLookup fresh(model);
    const SymmetryPlane plane = symmetryPlane(model);
    const Placement& knee = loaded->scene.placements.at(0);
    ASSERT_EQ(knee.id, "knee_l");
    // The example has the right knee already, and mirroring onto a twin is refused (409): the
    // rounds mirror the left knee into a scene without it.
    ASSERT_TRUE(s.deletePlacement(id, "knee_r", {}));
    Scene withoutTwin = loaded->scene;
    withoutTwin.placements.erase(std::remove_if(withoutTwin.placements.begin(), withoutTwin.placements.end(),
                                                [](const Placement& p) { return p.id == "knee_r"; }),
                                 withoutTwin.placements.end());
    ASSERT_EQ(withoutTwin.placements.size() + 1, loaded->scene.placements.size());
    for (int round = 0; round < 3; ++round) { // the first builds, the others reuse
        SCOPED_TRACE("round " + std::to_string(round));
        // Pick by UV: the same rest-mesh point.
        auto pick = s.pickUv(id, knee.center[0], knee.center[1]);
        ASSERT_TRUE(pick) << pick.error().message;
        const auto hit = pickUv(model, fresh, {knee.center[0], knee.center[1]});
        ASSERT_TRUE(hit);
        ASSERT_TRUE((*pick)["hit"].get<bool>());
        EXPECT_EQ((*pick)["part"], hit->part);
        EXPECT_EQ((*pick)["triangle"], hit->triangle);
        EXPECT_FLOAT_EQ((*pick)["position"][0].get<float>(), hit->position.x);
        EXPECT_FLOAT_EQ((*pick)["position"][2].get<float>(), hit->position.z);
        // The suggestion: core suggestFromMotion from a fresh analysis (SPEC §8).
        const RestSkin rest = restSkin(model);
        const BodyMap body = mapBody(model, rest, plane);
        const MotionAnalysis motion = analyzeMotion(model, rest, body);
        const MotionSuggestion d = suggestFromMotion(model, rest, plane, body, motion,
                                                     proposePatterns(model, rest, plane, body, motion),
                                                     hit->joints, glm::dvec3(hit->position));
        EXPECT_EQ((*pick)["suggested"]["joint"], d.driver.joint);
        if (d.axisVector) {
            ASSERT_TRUE((*pick)["suggested"]["axis"].is_array());
            for (int k = 0; k < 3; ++k)
                EXPECT_NEAR((*pick)["suggested"]["axis"][k].get<double>(), (*d.axisVector)[k], 1e-9);
        } else {
            EXPECT_EQ((*pick)["suggested"]["axis"], d.driver.axis);
        }
        EXPECT_EQ((*pick)["suggested"]["theta_min"], d.driver.thetaMin);
        EXPECT_EQ((*pick)["suggested"]["theta_max"], d.driver.thetaMax);
        EXPECT_EQ((*pick)["suggested"]["role"], d.role);

        // Mirror: the twin core mirrorPlacement makes with a fresh lookup and plane.
        auto mirrored = s.mirrorPlacement(id, "knee_l", {});
        ASSERT_TRUE(mirrored) << mirrored.error().message;
        const json twin = (*mirrored)["scene"]["placements"].back();
        auto expected = mirrorPlacement(knee, model, fresh, plane);
        ASSERT_TRUE(expected) << expected.error().message;
        EXPECT_EQ(twin["joint"], expected->joint);
        EXPECT_NEAR(twin["center"][0].get<double>(), expected->center[0], 1e-6);
        EXPECT_NEAR(twin["center"][1].get<double>(), expected->center[1], 1e-6);
        ASSERT_TRUE(s.deletePlacement(id, twin["id"].get<std::string>(), {}));

        // Lint: the findings core lintScene gives with a fresh lookup.
        auto lint = s.lint(id);
        ASSERT_TRUE(lint) << lint.error().message;
        const auto findings = lintScene(withoutTwin, model, fresh, loaded->images);
        std::vector<std::string> got, want;
        for (const json& f : *lint)
            if (f["code"] != "unused_upload")
                got.push_back(f["code"].get<std::string>() + ": " +
                              f["message"].get<std::string>());
        for (const LintFinding& f : findings)
            want.push_back(f.code + ": " + f.message);
        EXPECT_EQ(got, want);
    }

    // Deleting the scene and then the model frees the model and so its derived data (which
    // holds it): nothing the routes built keeps it.
    ASSERT_TRUE(s.deleteScene(id, {}));
    ASSERT_TRUE(s.deleteModel(modelId));
    ASSERT_EQ(forgotten->size(), 1u);
    EXPECT_TRUE(forgotten->front().expired());
}
