// InspectTest — the CPU inspection functions of SPEC §6 on the default character and pattern set:
// probeHeights (a texel's value and each placement's part, equal to the CPU bake) and
// clipActivation (t over a clip; never_active, saturated and jump flags on purpose-built
// placements). No GL, no HTTP.
#include "core/activation.hpp"
#include "core/probe.hpp"
#include "io/scene_files.hpp"

#include "DefaultSceneFixture.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace dermis;

namespace {


class InspectTest : public test::DefaultSceneTest {
protected:
};

TEST_F(InspectTest, ProbeEqualsTheCpuBakeAndExplainsIt) {
    FrameOverrides o;
    o.time = 0.75;
    auto plan = planFrame(loaded_->scene, loaded_->model, loaded_->images, loaded_->base, o);
    ASSERT_TRUE(plan) << plan.error().message;
    auto maps = bakeHeightMaps(plan->heights, 1);
    ASSERT_TRUE(maps);
    const int W = plan->heights.width, H = plan->heights.height;
    int explained = 0;
    // At every footprint centre and on a coarse grid: the probe's values are the bake's.
    std::vector<std::pair<double, double>> points;
    for (const BakePlacement& p : plan->heights.placements)
        points.emplace_back(p.footprint.center.x, p.footprint.center.y);
    for (int j = 0; j < 16; ++j)
        for (int i = 0; i < 16; ++i) points.emplace_back((i + 0.3) / 16, (j + 0.6) / 16);
    for (auto [u, v] : points) {
        auto r = probeHeights(plan->heights, u, v);
        ASSERT_TRUE(r) << r.error().message;
        EXPECT_EQ(r->texelX, std::min(W - 1, static_cast<int>(u * W)));
        EXPECT_EQ(r->texelY, std::min(H - 1, static_cast<int>(v * H)));
        EXPECT_NEAR(r->bump, maps->bump.at(r->texelX, r->texelY), 1e-5) << u << " " << v;
        EXPECT_NEAR(r->displacement, maps->displacement.at(r->texelX, r->texelY), 1e-5) << u << " " << v;
        float bump = r->base, disp = 0.0f;
        for (const ProbeContribution& c : r->contributions) {
            ASSERT_GE(c.source, 0);
            ASSERT_LT(static_cast<std::size_t>(c.source), loaded_->scene.placements.size());
            EXPECT_GE(c.L, -1.0f);
            EXPECT_LE(c.L, 1.0f);
            (c.target == Target::Bump ? bump : disp) += c.height;
            if (c.height != 0.0f) ++explained;
        }
        EXPECT_FLOAT_EQ(bump, r->bump);
        EXPECT_FLOAT_EQ(disp, r->displacement);
    }
    EXPECT_GT(explained, 5) << "the default scene at 0.75 s should have active placements";

    for (auto [u, v, field] : {std::tuple{-0.01, 0.5, "u"}, std::tuple{0.5, 1.01, "v"},
                               std::tuple{double(NAN), 0.5, "u"}, std::tuple{0.5, double(INFINITY), "v"}}) {
        auto bad = probeHeights(plan->heights, u, v);
        ASSERT_FALSE(bad);
        EXPECT_EQ(bad.error().field, field);
    }
    auto corner = probeHeights(plan->heights, 1.0, 1.0);
    ASSERT_TRUE(corner);
    EXPECT_EQ(corner->texelX, W - 1);
    EXPECT_EQ(corner->texelY, H - 1);
}

TEST_F(InspectTest, ActivationSamplesTheClipAndFlagsWhatToLookAt) {
    const Model& m = loaded_->model;
    ASSERT_FALSE(m.clips.empty());
    const Clip& clip = m.clips[0];
    auto base = clipActivation(loaded_->scene, m, clip.name, 30.0);
    ASSERT_TRUE(base) << base.error().message;
    ASSERT_GE(base->times.size(), 2u);
    EXPECT_EQ(base->times.front(), 0.0);
    EXPECT_NEAR(base->times.back(), clip.duration, 1e-6);
    EXPECT_NEAR(base->times[1], 1.0 / 30, 1e-9);
    ASSERT_EQ(base->t.size(), loaded_->scene.placements.size());
    for (const auto& ts : base->t) {
        ASSERT_EQ(ts.size(), base->times.size());
        for (double t : ts) {
            EXPECT_GE(t, 0.0);
            EXPECT_LE(t, 1.0);
        }
    }

    // Purpose-built placements on a joint that moves in this clip: find one.
    std::size_t mover = 0;
    double spread = 0.0;
    std::vector<double> thetas;
    for (std::size_t i = 0; i < loaded_->scene.placements.size(); ++i) {
        std::vector<double> th;
        for (double time : base->times) {
            Pose pose;
            pose.animation = clip.name;
            auto local = evaluatePose(m, pose, time);
            ASSERT_TRUE(local);
            th.push_back(*placementAngle(m, *local, loaded_->scene.placements[i], i));
        }
        const auto [lo, hi] = std::minmax_element(th.begin(), th.end());
        if (*hi - *lo > spread) {
            spread = *hi - *lo;
            mover = i;
            thetas = th;
        }
    }
    ASSERT_GT(spread, 10.0) << "no placement's joint moves in " << clip.name;
    const auto [lo, hi] = std::minmax_element(thetas.begin(), thetas.end());
    Scene s = loaded_->scene;
    const Placement src = s.placements[mover];
    s.placements.clear();
    auto add = [&](const std::string& id, double a, double b) {
        Placement p = src;
        p.id = id;
        p.thetaMin = a;
        p.thetaMax = b;
        s.placements.push_back(p);
    };
    add("never", *hi + 10, *hi + 40);             // the range is never entered
    add("pinned", *lo - 40, *lo - 5);             // full from the first frame
    const double mid = 0.5 * (*lo + *hi);
    add("switch", mid - 0.01, mid + 0.01);        // 0 → 1 between two samples
    add("fine", *lo - 1, *hi + 1);                // spans the motion: no flag
    auto a = clipActivation(s, m, clip.name, 30.0);
    ASSERT_TRUE(a) << a.error().message;
    auto flagged = [&](std::size_t i, ActivationFlagKind k) {
        for (const ActivationFlag& f : a->flags)
            if (f.placement == i && f.kind == k) return true;
        return false;
    };
    EXPECT_TRUE(flagged(0, ActivationFlagKind::NeverActive));
    EXPECT_TRUE(flagged(1, ActivationFlagKind::Saturated));
    EXPECT_TRUE(flagged(2, ActivationFlagKind::Jump));
    EXPECT_FALSE(flagged(3, ActivationFlagKind::NeverActive));
    EXPECT_FALSE(flagged(3, ActivationFlagKind::Saturated));
    EXPECT_FALSE(flagged(3, ActivationFlagKind::Jump));
    for (const ActivationFlag& f : a->flags)
        EXPECT_EQ(f.at.has_value(), f.kind != ActivationFlagKind::NeverActive);

    auto unknown = clipActivation(s, m, "no_such_clip", 30);
    ASSERT_FALSE(unknown);
    EXPECT_EQ(unknown.error().code, ErrorCode::NotFound);
    EXPECT_EQ(unknown.error().field, "clip");
    for (double fps : {0.0, -1.0, 241.0, double(NAN)}) {
        auto bad = clipActivation(s, m, clip.name, fps);
        ASSERT_FALSE(bad) << fps;
        EXPECT_EQ(bad.error().field, "fps");
    }
}

} // namespace
