// LintTest — the UV → surface lookup and the scene lint of SPEC §6, on the default character and
// purpose-built scenes: a footprint hanging off a UV chart, two overlapping footprints on one
// target, a θ range no clip reaches, a driver joint with no influence under the footprint, mirror
// pairs made asymmetric; the default elbow crease gets none of these and the default set's left /
// right pairs are symmetric. The model's own UVs (LintUvTest): on the KayKit Barbarian's palette
// atlas a right-elbow crease gets uv_overlap naming where it also shows (the left forearm, …) and
// no longer a wrong no_influence; uv_layout auto says the maps go to a generated layout; creases
// on every region of CesiumMan and the default character get none of these; RiggedFigure's UV
// placements get no_uvs, its surface placements not. No GL, no HTTP.
#include "core/lint.hpp"
#include "BuildPaths.hpp"
#include "core/uv_diagnosis.hpp"
#include "io/gltf_loader.hpp"
#include "io/scene_files.hpp"

#include "DefaultSceneFixture.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <optional>

using namespace dermis;

namespace {


class LintTest : public test::DefaultSceneTest {
protected:
    static void SetUpTestSuite() {
        DefaultSceneTest::SetUpTestSuite();
        if (loaded_) lookup_ = new UvLookup(loaded_->model);
    }
    static void TearDownTestSuite() {
        delete lookup_;
        lookup_ = nullptr;
        DefaultSceneTest::TearDownTestSuite();
    }

    static const Placement& elbow() {
        for (const Placement& p : loaded_->scene.placements)
            if (p.id == "elbow_l") return p;
        throw std::runtime_error("no elbow_l in the default scene");
    }
    /// Lint of a scene holding only `placements`.
    static std::vector<LintFinding> lint(const std::vector<Placement>& placements) {
        Scene s = loaded_->scene;
        s.placements = placements;
        return lintScene(s, loaded_->model, *lookup_, loaded_->images);
    }
    static int indexOf(const std::vector<Placement>& ps, const std::string& id) {
        for (std::size_t i = 0; i < ps.size(); ++i)
            if (ps[i].id == id) return static_cast<int>(i);
        throw std::runtime_error("no placement " + id);
    }
    /// The mirror_asymmetric findings of a lint.
    static std::vector<LintFinding> mirrorFindings(const std::vector<LintFinding>& f) {
        std::vector<LintFinding> out;
        for (const LintFinding& x : f)
            if (x.code == "mirror_asymmetric") out.push_back(x);
        return out;
    }
    static bool has(const std::vector<LintFinding>& f, const std::string& code, int placement) {
        for (const LintFinding& x : f)
            if (x.code == code && x.placement == placement) return true;
        return false;
    }
    static inline UvLookup* lookup_ = nullptr;
};

TEST_F(LintTest, LookupFindsTrianglesPositionsWeightsAndCharts) {
    const Model& m = loaded_->model;
    EXPECT_GT(lookup_->chartCount(), 4);
    int checked = 0;
    for (std::size_t pi = 0; pi < m.parts.size(); ++pi) {
        const MeshPart& p = m.parts[pi];
        for (std::size_t t = 0; t < p.indices.size() / 3; t += 97) {
            glm::dvec2 c(0.0);
            glm::vec3 pos(0.0f);
            for (int k = 0; k < 3; ++k) {
                c += glm::dvec2(p.uvs[p.indices[3 * t + k]]) / 3.0;
                pos += p.positions[p.indices[3 * t + k]] / 3.0f;
            }
            const auto hit = lookup_->find(c);
            ASSERT_TRUE(hit) << "triangle " << t;
            EXPECT_EQ(hit->part, static_cast<int>(pi));
            EXPECT_EQ(hit->triangle, static_cast<int>(t)); // the atlas has no overlaps
            EXPECT_NEAR(hit->bary.x, 1.0f / 3, 1e-4f);
            EXPECT_LT(glm::length(lookup_->position(*hit) - pos), 1e-5f);
            float sum = 0.0f;
            for (int joint : m.joints) sum += lookup_->weightOf(*hit, joint);
            EXPECT_NEAR(sum, 1.0f, 1e-4f);
            ++checked;
        }
    }
    EXPECT_GT(checked, 20);
    EXPECT_FALSE(lookup_->find({-0.1, 0.5}));
    EXPECT_FALSE(lookup_->find({0.5, 1.5}));
    EXPECT_FALSE(lookup_->find({NAN, 0.5}));
}

TEST_F(LintTest, TheDefaultElbowCreaseIsClean) {
    const auto f = lint({elbow()});
    for (const LintFinding& x : f) ADD_FAILURE() << x.code << ": " << x.message;
}

TEST_F(LintTest, FindsEachPurposeBuiltProblem) {
    // Off a chart: slide the crease towards empty atlas space; lint says off_chart exactly when
    // a sample where the pattern is not flat lands outside every chart.
    const HeightImage& crease = loaded_->images.at(elbow().pattern)->pixels;
    Placement off = elbow();
    off.id = "off";
    int hanging = 0;
    for (int k = 0; k < 60; ++k) {
        off.center[0] = elbow().center[0] + 0.004 * k;
        Footprint fp;
        fp.center = {off.center[0], off.center[1]};
        fp.scale = {off.scale[0], off.scale[1]};
        bool expected = false;
        for (int j = 0; j < 12; ++j)
            for (int i = 0; i < 12; ++i) {
                const glm::dvec2 st((i + 0.5) / 12, (j + 0.5) / 12);
                if (std::abs(sampleBilinear(crease, st.x, st.y)) > 0.02f && !lookup_->find(fp.toUV(st)))
                    expected = true;
            }
        EXPECT_EQ(has(lint({off}), "off_chart", 0), expected) << "shifted by " << 0.004 * k;
        hanging += expected;
    }
    EXPECT_GT(hanging, 0) << "the crease never hung off its chart";

    // Two footprints overlapping on the bump map (a third on displacement overlaps nothing).
    Placement twin = elbow(), other = elbow();
    twin.id = "twin";
    twin.center[0] += 0.01;
    other.id = "other";
    other.target = Target::Displacement;
    const auto overlap = lint({elbow(), twin, other});
    EXPECT_TRUE(has(overlap, "overlap", 0));
    EXPECT_FALSE(has(overlap, "overlap", 1)) << "each pair is reported once";
    for (const LintFinding& x : overlap)
        if (x.code == "overlap") EXPECT_EQ(x.message.find("other"), std::string::npos) << x.message;

    // Forty footprints on one spot: one finding per placement, each naming at most five others
    // (before: one per pair, 780 findings; the answer grew with the square of the count).
    std::vector<Placement> crowd;
    for (int k = 0; k < 40; ++k) {
        Placement c = elbow();
        c.id = "c" + std::to_string(k);
        c.center[0] += 0.0005 * k;
        crowd.push_back(c);
    }
    const auto crowded = lint(crowd);
    std::size_t overlapFindings = 0, bytes = 0;
    for (const LintFinding& x : crowded)
        if (x.code == "overlap") {
            ++overlapFindings;
            bytes += x.message.size();
            EXPECT_LT(x.message.size(), 400u) << x.message;
        }
    EXPECT_EQ(overlapFindings, 39u) << "one per placement that overlaps a later one";
    EXPECT_LT(bytes, 39u * 400u);
    ASSERT_TRUE(has(crowded, "overlap", 0));
    for (const LintFinding& x : crowded)
        if (x.code == "overlap" && x.placement == 0) {
            EXPECT_NE(x.message.find("overlaps 39 placements"), std::string::npos) << x.message;
            EXPECT_NE(x.message.find("and 34 more"), std::string::npos) << x.message;
        }

    // A θ range no clip reaches.
    Placement far = elbow();
    far.id = "far";
    far.thetaMin = 170;
    far.thetaMax = 179;
    EXPECT_TRUE(has(lint({far}), "unreachable_range", 0));

    // A driver joint with no skin weight under the footprint.
    Placement knee = elbow();
    knee.id = "knee_driven";
    knee.joint = "shin.l";
    EXPECT_TRUE(has(lint({knee}), "no_influence", 0));

    // Disabled placements are not linted.
    far.enabled = false;
    EXPECT_TRUE(lint({far}).empty());
}

TEST_F(LintTest, TheDefaultMirrorPairsAreSymmetric) {
    // Elbows, knees, biceps, thighs, clavicles (opposite axes, negated ranges) and scapulae pair
    // by joint name; the waist and rib pairs share one spine joint and are no pair.
    const auto f = lint(loaded_->scene.placements);
    for (const LintFinding& x : mirrorFindings(f)) ADD_FAILURE() << x.message;
}

TEST_F(LintTest, TheDefaultSceneLintsClean) {
    // What a fresh server's scene shows in the editor's lint panel: nothing.
    const auto f = lint(loaded_->scene.placements);
    for (const LintFinding& x : f)
        ADD_FAILURE() << x.code << " on " << loaded_->scene.placements[static_cast<std::size_t>(x.placement)].id
                      << ": " << x.message;
}

TEST_F(LintTest, FindsAsymmetricMirrorPairs) {
    const std::vector<Placement> all = loaded_->scene.placements;
    const int left = indexOf(all, "elbow_l"), right = indexOf(all, "elbow_r");
    auto expectOne = [&](const std::vector<Placement>& ps, const std::string& what) {
        const auto found = mirrorFindings(lint(ps));
        ASSERT_EQ(found.size(), 1u) << what;
        EXPECT_EQ(found[0].placement, std::min(left, right)) << what;
        EXPECT_EQ(found[0].severity, LintSeverity::Warning);
        EXPECT_NE(found[0].message.find("'elbow_l'"), std::string::npos) << found[0].message;
        EXPECT_NE(found[0].message.find("'elbow_r'"), std::string::npos) << found[0].message;
        EXPECT_NE(found[0].message.find(what), std::string::npos) << found[0].message;
    };

    std::vector<Placement> moved = all; // 0.05 UV = 51 texels at 1024²
    moved[static_cast<std::size_t>(right)].center[0] += 0.05;
    expectOne(moved, "texels");
    std::vector<Placement> nudged = all; // 2 texels: within the tolerance
    nudged[static_cast<std::size_t>(right)].center[1] += 2.0 / 1024.0;
    EXPECT_TRUE(mirrorFindings(lint(nudged)).empty());

    std::vector<Placement> range = all;
    range[static_cast<std::size_t>(right)].thetaMax = 100;
    expectOne(range, "theta range [0.0, 100.0]");

    std::vector<Placement> turned = all;
    turned[static_cast<std::size_t>(right)].rotation = 90;
    expectOne(turned, "footprint");
    std::vector<Placement> stretched = all;
    stretched[static_cast<std::size_t>(right)].scale[0] *= 1.6;
    expectOne(stretched, "footprint");

    std::vector<Placement> axis = all;
    axis[static_cast<std::size_t>(right)].axis = {0, 1, 0};
    axis[static_cast<std::size_t>(right)].axisName = "y";
    expectOne(axis, "axis");

    std::vector<Placement> gain = all;
    gain[static_cast<std::size_t>(right)].h = 2.0;
    expectOne(gain, "h, model");

    // An intentionally different pattern is no pair, nor is a placement without a twin.
    std::vector<Placement> other = moved;
    other[static_cast<std::size_t>(right)].pattern = "neck_rings";
    EXPECT_TRUE(mirrorFindings(lint(other)).empty());
    std::vector<Placement> alone = moved;
    alone.erase(alone.begin() + right);
    EXPECT_TRUE(mirrorFindings(lint(alone)).empty());
    // A disabled twin is not linted.
    std::vector<Placement> off = moved;
    off[static_cast<std::size_t>(right)].enabled = false;
    EXPECT_TRUE(mirrorFindings(lint(off)).empty());
}


// --- the model's own UVs (SPEC §8 UV diagnosis): uv_overlap, no_uvs, no_influence on overlap ---

const std::string kModels = std::string(dermis::build::testModelsDir()) + "/";

std::shared_ptr<const Model> loadShared(const std::string& path) {
    auto m = loadGltfFile(path);
    EXPECT_TRUE(m) << path << ": " << (m ? "" : m.error().message);
    return m ? std::make_shared<const Model>(std::move(*m)) : nullptr;
}

/// A crease centred on the UV centroid of triangle `t` of part `part`, driven by `joint`.
Placement creaseOn(const Model& m, std::size_t part, std::size_t t, const std::string& joint) {
    const MeshPart& p = m.parts[part];
    glm::dvec2 c(0.0);
    for (int k = 0; k < 3; ++k) c += glm::dvec2(p.uvs[p.indices[3 * t + k]]) / 3.0;
    Placement q;
    q.id = "crease";
    q.pattern = "crease";
    q.joint = joint;
    q.center = {c.x, c.y};
    q.scale = {0.004, 0.004};
    q.thetaMin = 0;
    q.thetaMax = 90;
    return q;
}

std::vector<LintFinding> findingsOf(const std::vector<LintFinding>& f, const std::string& code) {
    std::vector<LintFinding> out;
    for (const LintFinding& x : f)
        if (x.code == code) out.push_back(x);
    return out;
}

TEST(LintUvTest, TheBarbariansOverlappingTexelsAreNamedAndNoLongerFoolNoInfluence) {
    auto model = loadShared(kModels + "KayKitBarbarian/Barbarian.glb");
    ASSERT_TRUE(model);
    const ModelDerived derived(model);
    const Model& m = *model;
    const int forearm = m.findJoint("lowerarm.r"), upper = m.findJoint("upperarm.r");
    ASSERT_GE(forearm, 0);
    // A right-elbow crease where the first triangle the UV index finds is another region's (the
    // left arm comes first in the file): that triangle has no weight of the right arm, and lint
    // said no_influence there, which was wrong.
    const UvDiagnosis& d = derived.uvDiagnosis();
    std::optional<Placement> crease;
    for (std::size_t pi = 0; pi < m.parts.size() && !crease; ++pi) {
        if (m.parts[pi].node != "Barbarian_ArmRight") continue;
        for (std::size_t t = 0; t < m.parts[pi].indices.size() / 3 && !crease; ++t) {
            const int r = d.triangleRegion[pi][t];
            if (r < 0 || d.regions[static_cast<std::size_t>(r)].jointNode != forearm) continue;
            const Placement c = creaseOn(m, pi, t, "lowerarm.r");
            const auto first = derived.uvLookup().find({c.center[0], c.center[1]});
            if (!first || derived.uvLookup().weightOf(*first, forearm) > 0.01f ||
                derived.uvLookup().weightOf(*first, upper) > 0.01f)
                continue;
            crease = c;
        }
    }
    ASSERT_TRUE(crease) << "no right forearm triangle under another region's";

    Scene s;
    s.model = "barbarian";
    s.uvLayout = UvLayoutMode::Model;
    s.placements = {*crease};
    const auto f = lintScene(s, derived, PatternImages{});
    EXPECT_TRUE(findingsOf(f, "no_influence").empty()) << f.size();
    const auto overlap = findingsOf(f, "uv_overlap");
    ASSERT_EQ(overlap.size(), 1u);
    EXPECT_EQ(overlap[0].placement, 0);
    EXPECT_EQ(overlap[0].severity, LintSeverity::Warning);
    const std::string& said = overlap[0].message;
    EXPECT_NE(said.find("the pattern also shows on"), std::string::npos) << said;
    EXPECT_NE(said.find("Barbarian_ArmLeft (lowerarm.l)"), std::string::npos) << said; // the mirror twin
    ASSERT_NE(said.find("share with"), std::string::npos) << said; // … its own regions
    EXPECT_GT(said.find("Barbarian_ArmRight (lowerarm.r)"), said.find("share with")) << said;
    EXPECT_EQ(said.find("Barbarian_ArmRight (lowerarm.r)"), said.rfind("Barbarian_ArmRight (lowerarm.r)")) << said;
    EXPECT_NE(said.find("uv_layout \"generated\""), std::string::npos) << said;
    // The overlapping texels do not cut the footprint into charts either.
    EXPECT_TRUE(findingsOf(f, "across_seam").empty());
    // Identical with the per-call overload (its own lookup and diagnosis).
    const UvLookup fresh(m);
    const auto g = lintScene(s, m, fresh, PatternImages{});
    ASSERT_EQ(g.size(), f.size());
    for (std::size_t k = 0; k < f.size(); ++k) EXPECT_EQ(g[k].message, f[k].message);

    // uv_layout auto: the height maps go to a generated layout; lint says why, naming regions.
    s.uvLayout = UvLayoutMode::Auto;
    const auto autoFindings = lintScene(s, derived, PatternImages{});
    const auto info = findingsOf(autoFindings, "uv_overlap");
    ASSERT_EQ(info.size(), 1u);
    EXPECT_EQ(info[0].placement, -1);
    EXPECT_EQ(info[0].severity, LintSeverity::Info);
    EXPECT_NE(info[0].message.find("shares texels with"), std::string::npos) << info[0].message;
    EXPECT_NE(info[0].message.find("generated layout"), std::string::npos) << info[0].message;
    // uv_layout generated: nothing about the model's UVs.
    s.uvLayout = UvLayoutMode::Generated;
    EXPECT_TRUE(findingsOf(lintScene(s, derived, PatternImages{}), "uv_overlap").empty());
    // A scene without placements: no finding.
    s.uvLayout = UvLayoutMode::Auto;
    s.placements.clear();
    EXPECT_TRUE(lintScene(s, derived, PatternImages{}).empty());
}

TEST(LintUvTest, CesiumManAndTheDefaultCharacterHaveNoUvFindings) {
    for (const std::string& path :
         {kModels + "CesiumMan/CesiumMan.glb",
          resolveModelPath("builtin:default", "", dermis::build::sourceDir())}) {
        SCOPED_TRACE(path);
        auto model = loadShared(path);
        ASSERT_TRUE(model);
        const ModelDerived derived(model);
        const UvDiagnosis& d = derived.uvDiagnosis();
        // A crease on the largest triangle of each driving joint's region, driven by that joint.
        std::vector<Placement> creases;
        for (std::size_t r = 0; r < d.regions.size(); ++r) {
            const UvRegion& region = d.regions[r];
            if (region.jointNode < 0) continue;
            const MeshPart& p = model->parts[static_cast<std::size_t>(region.partIndex)];
            std::size_t best = 0;
            double bestArea = -1.0;
            for (std::size_t t = 0; t < p.indices.size() / 3; ++t) {
                if (d.triangleRegion[static_cast<std::size_t>(region.partIndex)][t] != static_cast<int>(r)) continue;
                const glm::vec2 a = p.uvs[p.indices[3 * t]], b = p.uvs[p.indices[3 * t + 1]], c = p.uvs[p.indices[3 * t + 2]];
                const double area = std::abs((b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y));
                if (area > bestArea) {
                    bestArea = area;
                    best = t;
                }
            }
            Placement c = creaseOn(*model, static_cast<std::size_t>(region.partIndex), best, region.joint);
            c.id = "crease_" + std::to_string(r);
            creases.push_back(c);
        }
        ASSERT_GT(creases.size(), 10u);
        for (UvLayoutMode mode : {UvLayoutMode::Auto, UvLayoutMode::Model}) {
            Scene s;
            s.uvLayout = mode;
            s.placements = creases;
            for (const LintFinding& x : lintScene(s, derived, PatternImages{}))
                EXPECT_TRUE(x.code != "uv_overlap" && x.code != "no_uvs" && x.code != "no_influence")
                    << x.code << " on " << x.placement << ": " << x.message;
        }
    }
}

TEST(LintUvTest, UvPlacementsOnAModelWithoutUvsAreNamedAndSurfacePlacementsAreNot) {
    auto model = loadShared(kModels + "RiggedFigure/RiggedFigure.glb");
    ASSERT_TRUE(model);
    const ModelDerived derived(model);
    Placement uv;
    uv.id = "elbow";
    uv.pattern = "crease";
    uv.joint = derived.model().nodes[static_cast<std::size_t>(derived.model().joints.at(6))].name;
    Placement surface = uv;
    surface.id = "elbow_surface";
    surface.projection = Projection::Surface;
    Scene s;
    s.placements = {uv, surface};
    const auto f = lintScene(s, derived, PatternImages{});
    const auto noUvs = findingsOf(f, "no_uvs");
    ASSERT_EQ(noUvs.size(), 1u);
    EXPECT_EQ(noUvs[0].placement, -1);
    EXPECT_NE(noUvs[0].message.find("placement 'elbow' uses projection \"uv\""), std::string::npos) << noUvs[0].message;
    EXPECT_EQ(noUvs[0].message.find("elbow_surface"), std::string::npos) << noUvs[0].message;
    EXPECT_NE(noUvs[0].message.find("projection \"surface\""), std::string::npos) << noUvs[0].message;
    // Nothing is measured in UVs the model does not have.
    for (const char* code : {"off_chart", "across_seam", "no_influence", "overlap", "uv_overlap"})
        EXPECT_TRUE(findingsOf(f, code).empty()) << code;
    // Only surface placements: no no_uvs; a range no clip reaches is still found.
    surface.thetaMin = 170;
    surface.thetaMax = 179;
    s.placements = {surface};
    const auto g = lintScene(s, derived, PatternImages{});
    EXPECT_TRUE(findingsOf(g, "no_uvs").empty());
    EXPECT_EQ(findingsOf(g, "unreachable_range").size(), derived.model().clips.empty() ? 0u : 1u);
    EXPECT_EQ(derived.uvDiagnosisBuilds(), 0); // no UV placement in UVs: no diagnosis needed
}

} // namespace
