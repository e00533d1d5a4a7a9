// PlacementTest — texture-space placement mapping of SPEC §2 "Conventions". Pure.
#include "core/heightmap.hpp"

#include <gtest/gtest.h>

#include <random>

using namespace dermis;

namespace {
Footprint fp(glm::dvec2 c, glm::dvec2 s, double rot) {
    Footprint f;
    f.center = c;
    f.scale = s;
    f.rotationDeg = rot;
    return f;
}
void expectNear(glm::dvec2 a, glm::dvec2 b, double tol = 1e-12) {
    EXPECT_NEAR(a.x, b.x, tol);
    EXPECT_NEAR(a.y, b.y, tol);
}
} // namespace

TEST(PlacementTest, CentreAndCornersUnrotated) {
    const Footprint f = fp({0.3, 0.6}, {0.2, 0.1}, 0);
    expectNear(f.toPattern({0.3, 0.6}), {0.5, 0.5});
    // s = (0,0), the pattern's first pixel, sits at the footprint's min-u, min-v corner.
    expectNear(f.toUV({0, 0}), {0.2, 0.55});
    expectNear(f.toUV({1, 1}), {0.4, 0.65});
    expectNear(f.toPattern({0.4, 0.6}), {1.0, 0.5});
    expectNear(f.toPattern({0.3, 0.65}), {0.5, 1.0});
}

TEST(PlacementTest, RotationDirection) {
    // R(a) = [[cos a, −sin a], [sin a, cos a]] on (u, v): +90° turns the pattern's +s axis to +v.
    const Footprint f = fp({0.5, 0.5}, {0.2, 0.2}, 90);
    expectNear(f.toUV({1.0, 0.5}), {0.5, 0.6});
    expectNear(f.toUV({0.5, 1.0}), {0.4, 0.5});
    expectNear(f.toPattern({0.5, 0.6}), {1.0, 0.5});
    // The first pixel (s = 0,0) ends up at max-u, min-v.
    expectNear(f.toUV({0, 0}), {0.6, 0.4});
    const Footprint g = fp({0.5, 0.5}, {0.2, 0.2}, 30);
    const glm::dvec2 p = g.toUV({1.0, 0.5});
    expectNear(p, {0.5 + 0.1 * std::cos(glm::radians(30.0)), 0.5 + 0.1 * std::sin(glm::radians(30.0))});
}

TEST(PlacementTest, NonSquareRotated) {
    const Footprint f = fp({0.5, 0.5}, {0.4, 0.1}, 90);
    // Long side (u of the pattern) now runs along v.
    expectNear(f.toPattern({0.5, 0.7}), {1.0, 0.5});
    expectNear(f.toPattern({0.45, 0.5}), {0.5, 1.0});
    const auto [lo, hi] = f.uvBounds();
    expectNear(lo, {0.45, 0.3}, 1e-12);
    expectNear(hi, {0.55, 0.7}, 1e-12);
}

TEST(PlacementTest, ToUVInvertsToPattern) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0, 1), rot(-360, 360), sc(0.01, 0.9);
    for (int k = 0; k < 200; ++k) {
        const Footprint f = fp({u(rng), u(rng)}, {sc(rng), sc(rng)}, rot(rng));
        const glm::dvec2 s(u(rng), u(rng));
        expectNear(f.toPattern(f.toUV(s)), s, 1e-9);
    }
}

TEST(PlacementTest, RotatedBoundsContainTheCorners) {
    const Footprint f = fp({0.5, 0.5}, {0.2, 0.2}, 45);
    const auto [lo, hi] = f.uvBounds();
    const double r = 0.1 * std::sqrt(2.0);
    expectNear(lo, {0.5 - r, 0.5 - r}, 1e-12);
    expectNear(hi, {0.5 + r, 0.5 + r}, 1e-12);
}

TEST(PlacementTest, TexelRectCoversEveryTexelInside) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-0.2, 1.2), rot(-180, 180), sc(0.02, 0.6);
    const int W = 64, H = 48;
    for (int k = 0; k < 60; ++k) {
        const Footprint f = fp({u(rng), u(rng)}, {sc(rng), sc(rng)}, rot(rng));
        const TexelRect r = footprintTexels(f, W, H);
        EXPECT_GE(r.x0, 0);
        EXPECT_LE(r.x1, W);
        EXPECT_GE(r.y0, 0);
        EXPECT_LE(r.y1, H);
        int inside = 0;
        for (int j = 0; j < H; ++j)
            for (int i = 0; i < W; ++i) {
                const glm::dvec2 s = f.toPattern({(i + 0.5) / W, (j + 0.5) / H});
                if (s.x < 0 || s.x > 1 || s.y < 0 || s.y > 1) continue;
                ++inside;
                EXPECT_TRUE(i >= r.x0 && i < r.x1 && j >= r.y0 && j < r.y1) << k;
            }
        // The rectangle is tight: at most its bounds plus a texel of margin each side.
        const auto [lo, hi] = f.uvBounds();
        EXPECT_LE(r.x1 - r.x0, (hi.x - lo.x) * W + 4);
        (void)inside;
    }
}

TEST(PlacementTest, BilinearSamplingTexelCentresAndEdgeClamp) {
    HeightImage img(2, 2);
    img.at(0, 0) = 0.0f;
    img.at(1, 0) = 1.0f;
    img.at(0, 1) = 0.5f;
    img.at(1, 1) = -0.5f;
    EXPECT_FLOAT_EQ(sampleBilinear(img, 0.25, 0.25), 0.0f);
    EXPECT_FLOAT_EQ(sampleBilinear(img, 0.75, 0.25), 1.0f);
    EXPECT_FLOAT_EQ(sampleBilinear(img, 0.25, 0.75), 0.5f);
    EXPECT_FLOAT_EQ(sampleBilinear(img, 0.5, 0.5), 0.25f);
    EXPECT_FLOAT_EQ(sampleBilinear(img, 0.5, 0.25), 0.5f);
    // Clamped to the edge texels.
    EXPECT_FLOAT_EQ(sampleBilinear(img, 0.0, 0.0), 0.0f);
    EXPECT_FLOAT_EQ(sampleBilinear(img, 1.0, 0.0), 1.0f);
    EXPECT_FLOAT_EQ(sampleBilinear(img, 1.0, 1.0), -0.5f);
    EXPECT_FLOAT_EQ(sampleBilinear(img, 0.1, 0.0), 0.0f);
}

TEST(PlacementTest, ContributionIsZeroOutsideAndEdgeClampedInside) {
    HeightImage pat(4, 4, 0.25f);
    pat.at(0, 0) = 1.0f; // first pixel
    BakePlacement p;
    p.pattern = &pat;
    p.footprint = fp({0.5, 0.5}, {0.4, 0.2}, 0);
    p.t = 1.0;
    p.h = 2.0;
    // Just inside the min-u, min-v corner: the first pixel, clamped (not blended with zero).
    EXPECT_FLOAT_EQ(placementHeight(p, {0.3 + 1e-9, 0.4 + 1e-9}), 2.0f);
    // Just outside: nothing.
    EXPECT_EQ(placementHeight(p, {0.3 - 1e-6, 0.45}), 0.0f);
    EXPECT_EQ(placementHeight(p, {0.5, 0.61}), 0.0f);
    EXPECT_FLOAT_EQ(placementHeight(p, {0.5, 0.5}), 0.5f);
    // Rotated by 90°: the first pixel moves to max-u, min-v.
    p.footprint = fp({0.5, 0.5}, {0.2, 0.2}, 90);
    EXPECT_FLOAT_EQ(placementHeight(p, {0.6 - 1e-9, 0.4 + 1e-9}), 2.0f);
    EXPECT_FLOAT_EQ(placementHeight(p, {0.4 + 1e-9, 0.4 + 1e-9}), 0.5f);
}
