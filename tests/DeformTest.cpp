// DeformTest — the deformation model of SPEC §2 / paper eq. 1 and 2. Pure.
#include "DeformTestHelpers.hpp"
#include "core/deform.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace dermis;

namespace {
const Response kResponses[] = {Response::Log2, Response::Ln, Response::Linear,
                               Response::Smoothstep};
const DeformModel kModels[] = {DeformModel::Scale, DeformModel::Bias};

Drive drive(double lo, double hi, double h, DeformModel m, Response r) {
    Drive d;
    d.thetaMin = lo;
    d.thetaMax = hi;
    d.h = h;
    d.model = m;
    d.response = r;
    return d;
}
} // namespace

TEST(DeformTest, NormalizedTClampsAndHandlesReversedRanges) {
    EXPECT_DOUBLE_EQ(normalizedT(-10, 0, 120), 0.0);
    EXPECT_DOUBLE_EQ(normalizedT(0, 0, 120), 0.0);
    EXPECT_DOUBLE_EQ(normalizedT(30, 0, 120), 0.25);
    EXPECT_DOUBLE_EQ(normalizedT(120, 0, 120), 1.0);
    EXPECT_DOUBLE_EQ(normalizedT(500, 0, 120), 1.0);
    // Reversed: grows as the angle decreases.
    EXPECT_DOUBLE_EQ(normalizedT(90, 120, 0), 0.25);
    EXPECT_DOUBLE_EQ(normalizedT(130, 120, 0), 0.0);
    EXPECT_DOUBLE_EQ(normalizedT(-5, 120, 0), 1.0);
}

TEST(DeformTest, EndPointsHoldForEveryModelAndResponse) {
    for (DeformModel m : kModels)
        for (Response r : kResponses)
            for (float L : {-1.0f, -0.4f, 0.0f, 0.3f, 1.0f}) {
                const Drive d = drive(10, 70, 1.7, m, r);
                EXPECT_EQ(deformHeight(d, L, 10.0), 0.0f) << toString(m) << toString(r) << L;
                EXPECT_EQ(deformHeight(d, L, -40.0), 0.0f);
                EXPECT_FLOAT_EQ(deformHeight(d, L, 70.0), L * 1.7f);
                EXPECT_FLOAT_EQ(deformHeight(d, L, 95.0), L * 1.7f);
            }
}

TEST(DeformTest, HandComputedValues) {
    // Scale, log2, t = 0.5: L·h·log2(1.5).
    EXPECT_NEAR(deformHeight(drive(0, 100, 2, DeformModel::Scale, Response::Log2), 0.8f, 50),
                0.8 * 2 * 0.5849625007, 1e-6);
    // Bias, log2, t = 0.5: max(h·(L − log2(1.5)), 0).
    EXPECT_NEAR(deformHeight(drive(0, 100, 1, DeformModel::Bias, Response::Log2), 0.9f, 50),
                0.9 - 0.5849625007, 1e-6);
    EXPECT_EQ(deformHeight(drive(0, 100, 1, DeformModel::Bias, Response::Log2), 0.3f, 50), 0.0f);
    // ln, t = 0.25.
    EXPECT_NEAR(deformHeight(drive(0, 100, 1, DeformModel::Scale, Response::Ln), 1.0f, 25),
                std::log(1.25), 1e-6);
    EXPECT_NEAR(deformHeight(drive(0, 100, 3, DeformModel::Bias, Response::Ln), 1.0f, 25),
                3 * (1.0 - std::log(1.75)), 1e-6);
    // linear, t = 0.25.
    EXPECT_NEAR(deformHeight(drive(0, 100, 1, DeformModel::Scale, Response::Linear), -0.6f, 25),
                -0.15, 1e-6);
    EXPECT_NEAR(deformHeight(drive(0, 100, 2, DeformModel::Bias, Response::Linear), 0.9f, 25),
                2 * (0.9 - 0.75), 1e-6);
    // smoothstep, t = 0.25: 0.0625·2.5 = 0.15625.
    EXPECT_NEAR(deformHeight(drive(0, 100, 1, DeformModel::Scale, Response::Smoothstep), 1.0f, 25),
                0.15625, 1e-6);
    EXPECT_NEAR(deformHeight(drive(0, 100, 1, DeformModel::Bias, Response::Smoothstep), 1.0f, 25),
                0.15625, 1e-6);
}

TEST(DeformTest, Log2IsContinuousAtBothEnds) {
    const double eps = 1e-7;
    for (DeformModel m : kModels) {
        const Drive d = drive(0, 90, 1.3, m, Response::Log2);
        // Near t = 1 the curve meets L·h (positive L: bias clamps negative values to 0).
        EXPECT_NEAR(deformHeight(d, 0.7f, 90 - eps), 0.7f * 1.3f, 1e-5) << toString(m);
        // Near t = 0 the curve meets 0.
        EXPECT_NEAR(deformHeight(d, 0.7f, eps), 0.0f, 1e-5) << toString(m);
    }
    // Monotone in the angle for a positive height.
    float prev = -1;
    for (int a = 0; a <= 90; ++a) {
        const float v = deformHeight(drive(0, 90, 1, DeformModel::Scale, Response::Log2), 0.5f, a);
        EXPECT_GE(v, prev);
        prev = v;
    }
}

TEST(DeformTest, LnFollowsThePaperToTheLetterAndJumps) {
    // Paper eq. 1 with f = t + 1: just below theta_max the natural log gives 0.693·L·h.
    const Drive d = drive(0, 90, 1, DeformModel::Scale, Response::Ln);
    EXPECT_NEAR(deformHeight(d, 1.0f, 90 - 1e-6), std::log(2.0), 1e-5);
    EXPECT_FLOAT_EQ(deformHeight(d, 1.0f, 90), 1.0f);
}

TEST(DeformTest, BiasMatchesPaperEquation2) {
    // g = (θ − θmax)/(θmin − θmax) + 1 = 2 − t, offset = log(g).
    for (double theta = 1; theta < 80; theta += 7.3) {
        const double g = (theta - 80.0) / (0.0 - 80.0) + 1.0;
        const double expected = std::max(1.5 * (0.8 - std::log2(g)), 0.0);
        EXPECT_NEAR(deformHeight(drive(0, 80, 1.5, DeformModel::Bias, Response::Log2), 0.8f, theta),
                    expected, 1e-6);
        const double f = (theta - 0.0) / (80.0 - 0.0) + 1.0; // eq. 1
        EXPECT_NEAR(deformHeight(drive(0, 80, 1.5, DeformModel::Scale, Response::Log2), 0.8f, theta),
                    0.8 * 1.5 * std::log2(f), 1e-6);
    }
}

TEST(DeformTest, ReversedRangeMirrorsTheForwardOne) {
    for (DeformModel m : kModels)
        for (Response r : kResponses) {
            const Drive fwd = drive(0, 100, 1, m, r), rev = drive(100, 0, 1, m, r);
            for (double a = -10; a <= 110; a += 5)
                EXPECT_FLOAT_EQ(deformHeight(fwd, 0.9f, a), deformHeight(rev, 0.9f, 100 - a));
        }
}

TEST(DeformTest, BiasRevealsMoreAreaAsTGrows) {
    // The bone's shape is fixed; the offset decides how much of it shows.
    const Drive d = drive(0, 100, 1, DeformModel::Bias, Response::Log2);
    int prevCount = -1;
    for (double a = 10; a < 100; a += 10) {
        int count = 0;
        for (float L = 0.0f; L <= 1.0f; L += 0.01f) count += deformHeight(d, L, a) > 0.0f;
        EXPECT_GT(count, prevCount);
        prevCount = count;
    }
}

TEST(DeformTest, NamesRoundTrip) {
    for (Response r : kResponses) EXPECT_EQ(responseFromString(toString(r)), r);
    for (DeformModel m : kModels) EXPECT_EQ(deformModelFromString(toString(m)), m);
    for (Target t : {Target::Bump, Target::Displacement}) EXPECT_EQ(targetFromString(toString(t)), t);
    for (PatternKind k : {PatternKind::Wrinkle, PatternKind::Bulge, PatternKind::Bone})
        EXPECT_EQ(patternKindFromString(toString(k)), k);
    EXPECT_FALSE(responseFromString("log").has_value());
    EXPECT_FALSE(deformModelFromString("Scale").has_value());
    EXPECT_EQ(defaultModel(PatternKind::Bone), DeformModel::Bias);
    EXPECT_EQ(defaultTarget(PatternKind::Bulge), Target::Displacement);
    EXPECT_EQ(defaultTarget(PatternKind::Wrinkle), Target::Bump);
    EXPECT_EQ(defaultModel(PatternKind::Wrinkle), DeformModel::Scale);
}
