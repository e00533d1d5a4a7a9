// HeightmapTest — the CPU height-map reference (SPEC §2 "Height maps") on hand-computed scenes.
// Pure.
#include "core/heightmap.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

using namespace dermis;

namespace {
BakePlacement place(const HeightImage* img, glm::dvec2 c, glm::dvec2 s, double rot, double t,
                    DeformModel m = DeformModel::Scale, Target tg = Target::Bump,
                    Response r = Response::Log2, double h = 1.0) {
    BakePlacement p;
    p.pattern = img;
    p.footprint.center = c;
    p.footprint.scale = s;
    p.footprint.rotationDeg = rot;
    p.t = t;
    p.model = m;
    p.target = tg;
    p.response = r;
    p.h = h;
    return p;
}
BakeSettings size(int w, int h, int threads = 1) {
    BakeSettings s;
    s.width = w;
    s.height = h;
    s.threads = threads;
    return s;
}
} // namespace

TEST(HeightmapTest, FullCoverPlacementCopiesThePatternTexelForTexel) {
    HeightImage pat(8, 8);
    for (int j = 0; j < 8; ++j)
        for (int i = 0; i < 8; ++i) pat.at(i, j) = (i - 3.5f) / 4.0f * (j % 2 ? 1.0f : -0.5f);
    auto maps = bakeHeightMaps({place(&pat, {0.5, 0.5}, {1, 1}, 0, 1.0, DeformModel::Scale,
                                      Target::Bump, Response::Log2, 0.5)},
                               size(8, 8));
    ASSERT_TRUE(maps.ok());
    for (int j = 0; j < 8; ++j)
        for (int i = 0; i < 8; ++i) {
            EXPECT_FLOAT_EQ(maps->bump.at(i, j), pat.at(i, j) * 0.5f);
            EXPECT_EQ(maps->displacement.at(i, j), 0.0f);
        }
}

TEST(HeightmapTest, BilinearUpsamplingByHand) {
    // A 2×2 pattern over a 4×4 map: texel centres at s = 1/8, 3/8, 5/8, 7/8 → pattern x =
    // s·2 − 0.5 = −0.25 (clamped 0), 0.25, 0.75, 1.25 (clamped 1).
    HeightImage pat(2, 2);
    pat.at(0, 0) = pat.at(0, 1) = 0.0f;
    pat.at(1, 0) = pat.at(1, 1) = 1.0f;
    auto maps = bakeHeightMaps({place(&pat, {0.5, 0.5}, {1, 1}, 0, 1.0)}, size(4, 4));
    ASSERT_TRUE(maps.ok());
    const float expected[4] = {0.0f, 0.25f, 0.75f, 1.0f};
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) EXPECT_FLOAT_EQ(maps->bump.at(i, j), expected[i]);
}

TEST(HeightmapTest, FootprintCoversOnlyItsTexels) {
    HeightImage pat(4, 4, 1.0f);
    // Footprint u ∈ [0.25, 0.5], v ∈ [0.5, 1.0] on an 8×4 map: columns 2,3 and rows 2,3.
    auto maps = bakeHeightMaps({place(&pat, {0.375, 0.75}, {0.25, 0.5}, 0, 1.0)}, size(8, 4));
    ASSERT_TRUE(maps.ok());
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 8; ++i) {
            const bool in = (i == 2 || i == 3) && (j == 2 || j == 3);
            EXPECT_EQ(maps->bump.at(i, j), in ? 1.0f : 0.0f) << i << "," << j;
        }
}

TEST(HeightmapTest, TargetsModelsAndOverlapsAdd) {
    HeightImage pat(2, 2, 0.9f);
    const double t = 0.5;
    std::vector<BakePlacement> ps = {
        place(&pat, {0.5, 0.5}, {1, 1}, 0, t),                                     // bump, scale
        place(&pat, {0.5, 0.5}, {1, 1}, 0, t, DeformModel::Bias),                  // bump, bias
        place(&pat, {0.5, 0.5}, {1, 1}, 0, t, DeformModel::Scale, Target::Displacement),
        place(&pat, {0.5, 0.5}, {1, 1}, 0, 0.0, DeformModel::Scale, Target::Displacement), // t=0
    };
    auto maps = bakeHeightMaps(ps, size(4, 4));
    ASSERT_TRUE(maps.ok());
    const double g = std::log2(1.5);
    EXPECT_NEAR(maps->bump.at(1, 1), 0.9 * g + (0.9 - g), 1e-6);
    EXPECT_NEAR(maps->displacement.at(2, 3), 0.9 * g, 1e-6);
}

TEST(HeightmapTest, ZeroAngleGivesEmptyMaps) {
    HeightImage pat(3, 3, -0.7f);
    auto maps = bakeHeightMaps({place(&pat, {0.5, 0.5}, {0.5, 0.5}, 10, 0.0)}, size(16, 16));
    ASSERT_TRUE(maps.ok());
    for (float v : maps->bump.data) EXPECT_EQ(v, 0.0f);
}

TEST(HeightmapTest, StaticBaseMapIsAddedToBump) {
    HeightImage base(4, 4, 0.1f);
    base.at(0, 0) = 0.3f;
    HeightImage pat(2, 2, 0.5f);
    BakeSettings s = size(4, 4);
    s.base = &base;
    auto maps = bakeHeightMaps({place(&pat, {0.5, 0.5}, {1, 1}, 0, 1.0)}, s);
    ASSERT_TRUE(maps.ok());
    EXPECT_FLOAT_EQ(maps->bump.at(0, 0), 0.8f);
    EXPECT_FLOAT_EQ(maps->bump.at(3, 2), 0.6f);
    EXPECT_EQ(maps->displacement.at(0, 0), 0.0f);
    // A base of another size is sampled bilinearly at the texel centres.
    HeightImage small(2, 2, 0.0f);
    small.at(1, 0) = small.at(1, 1) = 1.0f;
    s.base = &small;
    auto m2 = bakeHeightMaps({}, s);
    ASSERT_TRUE(m2.ok());
    EXPECT_FLOAT_EQ(m2->bump.at(1, 0), 0.25f);
    EXPECT_FLOAT_EQ(m2->bump.at(3, 3), 1.0f);
}

TEST(HeightmapTest, MatchesThePerPointReferenceAndIsThreadCountIndependent) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(0, 1), sc(0.05, 0.5), rot(-180, 180);
    std::vector<HeightImage> pats;
    for (int k = 0; k < 4; ++k) {
        HeightImage p(5 + 7 * k, 9 + 3 * k);
        for (float& v : p.data) v = static_cast<float>(u(rng) * 2 - 1);
        pats.push_back(std::move(p));
    }
    std::vector<BakePlacement> ps;
    const DeformModel models[] = {DeformModel::Scale, DeformModel::Bias};
    const Response responses[] = {Response::Log2, Response::Ln, Response::Linear,
                                  Response::Smoothstep};
    for (int k = 0; k < 15; ++k)
        ps.push_back(place(&pats[k % 4], {u(rng), u(rng)}, {sc(rng), sc(rng)}, rot(rng),
                           k == 3 ? 1.0 : u(rng), models[k % 2],
                           k % 3 ? Target::Bump : Target::Displacement, responses[k % 4],
                           0.5 + u(rng)));
    const int W = 257, H = 131;
    auto one = bakeHeightMaps(ps, size(W, H, 1));
    ASSERT_TRUE(one.ok());
    // Reference: the per-point definition, summed in document order.
    int nonzero = 0;
    for (int j = 0; j < H; ++j)
        for (int i = 0; i < W; ++i) {
            float b = 0, d = 0;
            for (const BakePlacement& p : ps) {
                const float v = placementHeight(p, {(i + 0.5) / W, (j + 0.5) / H});
                (p.target == Target::Bump ? b : d) += v;
            }
            ASSERT_NEAR(one->bump.at(i, j), b, 1e-5) << i << "," << j;
            ASSERT_NEAR(one->displacement.at(i, j), d, 1e-5) << i << "," << j;
            nonzero += b != 0.0f;
        }
    EXPECT_GT(nonzero, W * H / 10);
    for (int threads : {2, 3, 7, 64}) {
        auto many = bakeHeightMaps(ps, size(W, H, threads));
        ASSERT_TRUE(many.ok());
        EXPECT_EQ(0, std::memcmp(one->bump.data.data(), many->bump.data.data(),
                                 one->bump.data.size() * sizeof(float)))
            << threads;
        EXPECT_EQ(0, std::memcmp(one->displacement.data.data(), many->displacement.data.data(),
                                 one->displacement.data.size() * sizeof(float)))
            << threads;
    }
}

TEST(HeightmapTest, RejectsBadSizesAndMissingPatterns) {
    HeightImage pat(2, 2, 1.0f);
    EXPECT_EQ(bakeHeightMaps({}, size(0, 16)).error().field, "/heightmap/size");
    EXPECT_EQ(bakeHeightMaps({}, size(16, -1)).error().field, "/heightmap/size");
    EXPECT_EQ(bakeHeightMaps({}, size(kMaxHeightmapSize + 1, 16)).error().field,
              "/heightmap/size");
    auto noPattern = bakeHeightMaps({place(nullptr, {0.5, 0.5}, {1, 1}, 0, 1)}, size(4, 4));
    EXPECT_EQ(noPattern.error().field, "/placements/0/pattern");
    HeightImage empty;
    EXPECT_FALSE(bakeHeightMaps({place(&pat, {0.5, 0.5}, {1, 1}, 0, 1),
                                 place(&empty, {0.5, 0.5}, {1, 1}, 0, 1)},
                                size(4, 4))
                     .ok());
    EXPECT_EQ(bakeHeightMaps({place(&pat, {0.5, 0.5}, {0, 1}, 0, 1)}, size(4, 4)).error().field,
              "/placements/0/scale");
}

TEST(HeightmapTest, BakeIntoReusesStorageAndOverwritesStaleData) {
    HeightImage pat(3, 3, 0.4f);
    const std::vector<BakePlacement> ps = {place(&pat, {0.3, 0.3}, {0.3, 0.2}, 20, 0.7)};
    auto fresh = bakeHeightMaps(ps, size(32, 16, 2));
    ASSERT_TRUE(fresh.ok());
    HeightMaps reused{HeightImage(32, 16, 9.0f), HeightImage(32, 16, -9.0f)};
    const float* storage = reused.bump.data.data();
    ASSERT_TRUE(bakeHeightMapsInto(ps, size(32, 16, 3), reused).ok());
    EXPECT_EQ(reused.bump.data.data(), storage);
    EXPECT_EQ(reused.bump.data, fresh->bump.data);
    EXPECT_EQ(reused.displacement.data, fresh->displacement.data);
    // A size change resizes; a failure leaves the maps as they were.
    ASSERT_TRUE(bakeHeightMapsInto(ps, size(8, 8), reused).ok());
    EXPECT_EQ(reused.bump.width, 8);
    EXPECT_EQ(reused.bump.data.size(), 64u);
    EXPECT_FALSE(bakeHeightMapsInto(ps, size(0, 8), reused).ok());
    EXPECT_EQ(reused.bump.width, 8);
}

// --- The fast bake against a slow, straightforward reference ----------------------------------
//
// slowReferenceBake is the per-texel definition written out (the implementation the fast path
// replaced): every texel centre p = ((i+0.5)/W, (j+0.5)/H) visits every placement in document
// order, maps p to s = R(−rotation)·(p − center)/scale + 0.5 (SPEC §2 "Conventions"), samples
// the pattern bilinearly with clamping inside s ∈ [0,1]², and adds L_out of paper eq. 1
// (scale: L·h·gain(t)) or eq. 2 (bias: max(h·(L − offset(t)), 0)), L·h at t ≥ 1, 0 at t ≤ 0.
namespace {

double slowBilinear(const HeightImage& img, double su, double sv) {
    const double x = su * img.width - 0.5, y = sv * img.height - 0.5;
    const double x0f = std::floor(x), y0f = std::floor(y);
    const double fx = x - x0f, fy = y - y0f;
    auto cl = [](double v, int n) { return static_cast<int>(std::clamp(v, 0.0, double(n - 1))); };
    const int x0 = cl(x0f, img.width), x1 = cl(x0f + 1, img.width);
    const int y0 = cl(y0f, img.height), y1 = cl(y0f + 1, img.height);
    const double top = img.at(x0, y0) * (1 - fx) + img.at(x1, y0) * fx;
    const double bottom = img.at(x0, y1) * (1 - fx) + img.at(x1, y1) * fx;
    return top * (1 - fy) + bottom * fy;
}

HeightMaps slowReferenceBake(const std::vector<BakePlacement>& ps, int W, int H,
                             const HeightImage* base) {
    HeightMaps m{HeightImage(W, H), HeightImage(W, H)};
    for (int j = 0; j < H; ++j)
        for (int i = 0; i < W; ++i) {
            const double u = (i + 0.5) / W, v = (j + 0.5) / H;
            float b = base ? static_cast<float>(slowBilinear(*base, u, v)) : 0.0f, d = 0.0f;
            for (const BakePlacement& p : ps) {
                const double a = glm::radians(p.footprint.rotationDeg);
                const double du = u - p.footprint.center.x, dv = v - p.footprint.center.y;
                const double su = (std::cos(a) * du + std::sin(a) * dv) / p.footprint.scale.x + 0.5;
                const double sv = (-std::sin(a) * du + std::cos(a) * dv) / p.footprint.scale.y + 0.5;
                if (su < 0 || su > 1 || sv < 0 || sv > 1 || p.t <= 0) continue;
                const double L = slowBilinear(*p.pattern, su, sv);
                double out;
                if (p.t >= 1) out = L * p.h;
                else if (p.model == DeformModel::Scale)
                    out = L * p.h * responseGain(p.response, p.t); // eq. 1
                else
                    out = std::max(p.h * (L - responseOffset(p.response, p.t)), 0.0); // eq. 2
                (p.target == Target::Bump ? b : d) += static_cast<float>(out);
            }
            m.bump.at(i, j) = b;
            m.displacement.at(i, j) = d;
        }
    return m;
}

HeightImage randomPattern(int w, int h, std::mt19937& rng) {
    std::uniform_real_distribution<double> u(-1, 1);
    HeightImage p(w, h);
    for (float& v : p.data) v = static_cast<float>(u(rng));
    return p;
}

} // namespace

TEST(HeightmapTest, FastBakeMatchesTheSlowPerTexelReference) {
    std::mt19937 rng(1234);
    std::uniform_real_distribution<double> u01(0, 1), sc(0.02, 0.6), rot(-360, 360);
    std::vector<HeightImage> pats;
    // From a single texel to patterns larger than the map (minified and magnified sampling).
    for (auto [w, h] : {std::pair{1, 1}, {2, 3}, {7, 5}, {64, 64}, {300, 97}, {512, 512}})
        pats.push_back(randomPattern(w, h, rng));
    const HeightImage base = randomPattern(45, 61, rng);
    const DeformModel models[] = {DeformModel::Scale, DeformModel::Bias};
    const Response responses[] = {Response::Log2, Response::Ln, Response::Linear,
                                  Response::Smoothstep};
    const double exactRotations[] = {0, 90, -90, 180, 45, 270, 360, -0.0};
    for (int round = 0; round < 6; ++round) {
        std::vector<BakePlacement> ps;
        for (int k = 0; k < 40; ++k) {
            const double rotation = k % 3 == 0 ? exactRotations[k % 8] : rot(rng);
            glm::dvec2 center{u01(rng) * 1.4 - 0.2, u01(rng) * 1.4 - 0.2}; // some off the map
            glm::dvec2 scale{sc(rng), sc(rng)};
            if (k % 11 == 5) scale = {1e-4, 3e-4};  // smaller than a texel
            if (k % 13 == 7) scale = {2.5, 1.7};    // larger than the map
            if (k % 17 == 3) scale = {0.5, 0.004};  // a sliver
            double t = u01(rng);
            if (k % 7 == 0) t = 1.0;
            if (k % 9 == 4) t = 0.0; // activation 0: contributes nothing
            ps.push_back(place(&pats[static_cast<std::size_t>(k) % pats.size()], center, scale,
                               rotation, t, models[k % 2],
                               k % 3 == 1 ? Target::Displacement : Target::Bump,
                               responses[k % 4], 0.25 + 1.5 * u01(rng)));
        }
        const int W = 96 + 37 * round, H = 64 + 23 * round;
        BakeSettings s = size(W, H, 1);
        const bool withBase = round % 2 == 1;
        if (withBase) s.base = &base;
        auto fast = bakeHeightMaps(ps, s);
        ASSERT_TRUE(fast.ok());
        const HeightMaps slow = slowReferenceBake(ps, W, H, withBase ? &base : nullptr);
        int covered = 0;
        for (int j = 0; j < H; ++j)
            for (int i = 0; i < W; ++i) {
                for (auto [f, r] : {std::pair{&fast->bump, &slow.bump},
                                    std::pair{&fast->displacement, &slow.displacement}}) {
                    const float want = r->at(i, j);
                    ASSERT_NEAR(f->at(i, j), want, 2e-5 * (1.0 + std::abs(want)))
                        << "round " << round << " texel " << i << "," << j;
                }
                covered += slow.displacement.at(i, j) != 0.0f;
            }
        EXPECT_GT(covered, W * H / 20) << round;
        // Thread count changes nothing, to the bit.
        s.threads = 3;
        auto split = bakeHeightMaps(ps, s);
        ASSERT_TRUE(split.ok());
        EXPECT_EQ(split->bump.data, fast->bump.data) << round;
        EXPECT_EQ(split->displacement.data, fast->displacement.data) << round;
    }
}

TEST(HeightmapTest, FootprintEdgesFollowTheDefinitionExactly) {
    // A constant pattern at t = 1 adds exactly h = 1 per covering placement, so each texel holds
    // the number of footprints that contain its centre: any texel the fast span walk adds or
    // misses at a footprint's edge changes an integer.
    std::mt19937 rng(77);
    std::uniform_real_distribution<double> u01(0, 1), sc(0.01, 0.4), rot(-180, 180);
    const HeightImage one(5, 4, 1.0f);
    std::vector<BakePlacement> ps;
    for (int k = 0; k < 60; ++k)
        ps.push_back(place(&one, {u01(rng), u01(rng)}, {sc(rng), sc(rng)},
                           k % 4 == 0 ? 90.0 * (k % 5) : rot(rng), 1.0));
    // Footprints whose edges pass exactly through texel centres (0.25 = 16/64 texels).
    ps.push_back(place(&one, {0.5, 0.5}, {0.25, 0.25}, 0, 1.0));
    ps.push_back(place(&one, {0.5, 0.5}, {0.25, 0.125}, 90, 1.0));
    const int W = 64, H = 64;
    auto fast = bakeHeightMaps(ps, size(W, H, 2));
    ASSERT_TRUE(fast.ok());
    const HeightMaps slow = slowReferenceBake(ps, W, H, nullptr);
    for (int j = 0; j < H; ++j)
        for (int i = 0; i < W; ++i)
            ASSERT_EQ(fast->bump.at(i, j), slow.bump.at(i, j)) << i << "," << j;
}
