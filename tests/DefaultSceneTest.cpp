// DefaultSceneTest — the default pattern set (models/default.scene.json) on the default
// character: it validates as a scene, places every built-in pattern, and at the key frames of
// each clip its CPU height maps are non-zero only inside the placements' footprints, while every
// placement is driven by at least one clip. Reads files of this repository.
#include "BuildPaths.hpp"
#include "core/bake.hpp"
#include "io/scene_files.hpp"

#include <gtest/gtest.h>

#include <set>

using namespace dermis;

namespace {
const std::string kScene = std::string(dermis::build::sourceDir()) + "/models/default.scene.json";

bool inside(const Placement& p, glm::dvec2 uv) {
    Footprint f;
    f.center = {p.center[0], p.center[1]};
    f.scale = {p.scale[0], p.scale[1]};
    f.rotationDeg = p.rotation;
    const glm::dvec2 s = f.toPattern(uv);
    return s.x >= 0 && s.x <= 1 && s.y >= 0 && s.y <= 1;
}
} // namespace

TEST(DefaultSceneTest, PlacesEveryBuiltinPatternOnTheDefaultCharacter) {
    auto loaded = loadSceneFile(kScene);
    ASSERT_TRUE(loaded.ok()) << loaded.error().message;
    EXPECT_EQ(loaded->scene.model, "builtin:default");
    auto manifest = loadBuiltinManifest();
    ASSERT_TRUE(manifest.ok());
    std::set<std::string> used;
    for (const Placement& p : loaded->scene.placements) used.insert(p.pattern);
    for (const PatternInfo& info : manifest->patterns) EXPECT_TRUE(used.count(info.id)) << info.id;
    EXPECT_GE(loaded->scene.placements.size(), 15u);
    // Bulges go to the displacement map, bones use the bias model (manifest defaults).
    for (const Placement& p : loaded->scene.placements) {
        const PatternInfo* info = manifest->find(p.pattern);
        ASSERT_NE(info, nullptr);
        EXPECT_EQ(p.target, defaultTarget(info->kind)) << p.id;
        EXPECT_EQ(p.model, defaultModel(info->kind)) << p.id;
    }
}

TEST(DefaultSceneTest, EveryClipDeformsOnlyInsideTheFootprints) {
    auto loaded = loadSceneFile(kScene);
    ASSERT_TRUE(loaded.ok()) << loaded.error().message;
    Scene scene = loaded->scene;
    scene.heightmapSize = {256, 256};
    const Model& model = loaded->model;
    ASSERT_GE(model.clips.size(), 7u);
    std::vector<bool> driven(scene.placements.size(), false);
    for (const Clip& clip : model.clips) {
        // Key frames: every key time of the clip's channels.
        std::set<float> times;
        for (const Channel& ch : clip.channels) times.insert(ch.times.begin(), ch.times.end());
        scene.pose.animation = clip.name;
        bool clipDeforms = false;
        for (float t : times) {
            SceneBakeOptions opt;
            opt.time = t;
            auto maps = bakeScene(scene, model, loaded->images, opt);
            ASSERT_TRUE(maps.ok()) << maps.error().message;
            for (int j = 0; j < 256; ++j)
                for (int i = 0; i < 256; ++i) {
                    const glm::dvec2 uv((i + 0.5) / 256, (j + 0.5) / 256);
                    for (const HeightImage* m : {&maps->bump, &maps->displacement}) {
                        const float v = m->at(i, j);
                        if (v == 0.0f) continue;
                        clipDeforms = true;
                        const Target target =
                            m == &maps->bump ? Target::Bump : Target::Displacement;
                        bool covered = false;
                        for (std::size_t k = 0; k < scene.placements.size(); ++k) {
                            const Placement& p = scene.placements[k];
                            if (p.target != target || !inside(p, uv)) continue;
                            covered = true;
                            driven[k] = true;
                        }
                        ASSERT_TRUE(covered) << clip.name << " t=" << t << " texel " << i << ","
                                             << j << " is " << v << " outside every footprint";
                    }
                }
        }
        EXPECT_TRUE(clipDeforms) << clip.name << " deforms no skin at its key frames";
    }
    for (std::size_t k = 0; k < scene.placements.size(); ++k)
        EXPECT_TRUE(driven[k]) << scene.placements[k].id << " is driven by no clip";
}
