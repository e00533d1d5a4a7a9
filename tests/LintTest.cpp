// LintTest — the UV → surface lookup and the scene lint of SPEC §6, on the default character and
// purpose-built scenes: a footprint hanging off a UV chart, two overlapping footprints on one
// target, a θ range no clip reaches, a driver joint with no influence under the footprint, mirror
// pairs made asymmetric; the default elbow crease gets none of these and the default set's left /
// right pairs are symmetric. No GL, no HTTP.
#include "core/lint.hpp"
#include "io/scene_files.hpp"

#include "DefaultSceneFixture.hpp"

#include <gtest/gtest.h>

#include <cmath>

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

} // namespace
