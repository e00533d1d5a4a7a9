// SurfacePlacementTest — surface placements (SPEC §8), pure: the formula of
// surfacePlacementHeight at known points (inside, outside the pattern square, beyond depth, back
// facing, rotation through resolvePlacements), the rest-surface map of a hand-built cylinder whose
// UV layout has a seam (positions on the surface, gutters, determinism for any thread count), a
// decal across that seam (heights on both sides that follow the surface: no cut), the same decal
// in two different layouts (the same heights at the same surface points), the bake's
// determinism, planFrame's rest map and its errors (no rest map; no UVs to live in).
#include "core/bake.hpp"
#include "core/frame_plan.hpp"
#include "core/heightmap.hpp"
#include "core/texture_layout.hpp"

#include "SeamCylinder.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace dermis;
using namespace dermis::test::seam_cylinder; // cylinder(), kPi, kRadius, kHeight (SeamCylinder.hpp)

namespace {


/// A 4×4 pattern whose texels hold distinct values (row-major: 0.05·(1 + i + 4j)).
HeightImage rampPattern() {
    HeightImage img(4, 4);
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) img.at(i, j) = 0.05f * static_cast<float>(1 + i + 4 * j);
    return img;
}

/// A smooth bump: 1 at the centre, 0 at the border (cos² profile), 64².
HeightImage bumpPattern() {
    HeightImage img(64, 64);
    for (int j = 0; j < 64; ++j)
        for (int i = 0; i < 64; ++i) {
            const double x = (i + 0.5) / 64 - 0.5, y = (j + 0.5) / 64 - 0.5;
            img.at(i, j) = static_cast<float>(std::pow(std::cos(kPi * x), 2) * std::pow(std::cos(kPi * y), 2));
        }
    return img;
}

/// The analytic bump at pattern coordinate s (what bumpPattern samples).
double bumpAt(glm::dvec2 s) {
    if (s.x < 0 || s.x > 1 || s.y < 0 || s.y > 1) return 0.0;
    return std::pow(std::cos(kPi * (s.x - 0.5)), 2) * std::pow(std::cos(kPi * (s.y - 0.5)), 2);
}

BakePlacement surfaceAt(const HeightImage& pattern, glm::dvec3 c, glm::dvec3 n, glm::dvec3 t,
                        glm::dvec2 size, double depth) {
    BakePlacement p;
    p.pattern = &pattern;
    p.surface = true;
    p.anchorPosition = c;
    p.anchorNormal = n;
    p.anchorTangent = t;
    p.size = size;
    p.depth = depth;
    p.t = 1.0; // L_out = L·h
    p.h = 1.0;
    return p;
}


/// The cylinder's point at angle a (radians) and height y.
glm::dvec3 cylinderPoint(double a, double y) {
    return {kRadius * std::cos(a), y, kRadius * std::sin(a)};
}

/// Another layout of the same cylinder: u and v swapped and squeezed into [0.1, 0.9] × [0.05,
/// 0.95], and the vertex list reversed (a different split and order than the model's).
TextureLayout otherLayout(const Model& m) {
    TextureLayout l = modelTextureLayout(m);
    l.kind = "generated";
    PartLayout& p = l.parts[0];
    const std::size_t n = p.source.size();
    PartLayout q;
    q.source.resize(n);
    q.uvs.resize(n);
    for (std::size_t v = 0; v < n; ++v) {
        const std::size_t from = n - 1 - v;
        q.source[v] = p.source[from];
        q.uvs[v] = glm::vec2(0.1f + 0.8f * p.uvs[from].y, 0.05f + 0.9f * p.uvs[from].x);
    }
    for (std::uint32_t i : p.indices) q.indices.push_back(static_cast<std::uint32_t>(n - 1 - i));
    p = q;
    return l;
}

/// The cylinder point (angle, y) a UV of the model layout stands for.
glm::dvec3 pointOfModelUv(glm::dvec2 uv) {
    return cylinderPoint(2.0 * kPi * uv.x, (1.0 - uv.y) * kHeight);
}

float sampleMap(const HeightImage& m, glm::dvec2 uv) {
    return sampleBilinear(m, uv.x, uv.y);
}

} // namespace

// --- the formula ---------------------------------------------------------------------------------

TEST(SurfacePlacementTest, FormulaAtKnownPoints) {
    const HeightImage pat = rampPattern();
    // c = origin, n = z, t = x (b = n × t = y), w = 2, h = 1, depth 0.5.
    const BakePlacement p = surfaceAt(pat, {0, 0, 0}, {0, 0, 1}, {1, 0, 0}, {2, 1}, 0.5);
    const glm::dvec3 up(0, 0, 1);
    // The centre: s = (½, ½), the mean of the middle four texels.
    EXPECT_FLOAT_EQ(surfacePlacementHeight(p, {0, 0, 0}, up), sampleBilinear(pat, 0.5, 0.5));
    // Along t: s.x = x/w + ½; along b: s.y = y/h + ½.
    EXPECT_FLOAT_EQ(surfacePlacementHeight(p, {0.5, 0, 0}, up), sampleBilinear(pat, 0.75, 0.5));
    EXPECT_FLOAT_EQ(surfacePlacementHeight(p, {0, -0.25, 0}, up), sampleBilinear(pat, 0.5, 0.25));
    EXPECT_FLOAT_EQ(surfacePlacementHeight(p, {-0.9, 0.4, 0.1}, up), sampleBilinear(pat, 0.05, 0.9));
    // The first pixel of the pattern is at s = (0, 0): the corner −t/2·w − b/2·h.
    EXPECT_FLOAT_EQ(surfacePlacementHeight(p, {-1, -0.5, 0}, up), pat.at(0, 0));
    // Outside the pattern square.
    EXPECT_EQ(surfacePlacementHeight(p, {1.01, 0, 0}, up), 0.0f);
    EXPECT_EQ(surfacePlacementHeight(p, {0, 0.51, 0}, up), 0.0f);
    // Depth: |(p − c)·n| ≤ depth only.
    EXPECT_GT(surfacePlacementHeight(p, {0, 0, 0.49}, up), 0.0f);
    EXPECT_GT(surfacePlacementHeight(p, {0, 0, -0.49}, up), 0.0f);
    EXPECT_EQ(surfacePlacementHeight(p, {0, 0, 0.51}, up), 0.0f);
    EXPECT_EQ(surfacePlacementHeight(p, {0, 0, -0.51}, up), 0.0f);
    // Back-facing (n_p·n ≤ 0) gets nothing; a slanted surface still does.
    EXPECT_EQ(surfacePlacementHeight(p, {0, 0, 0}, {0, 0, -1}), 0.0f);
    EXPECT_EQ(surfacePlacementHeight(p, {0, 0, 0}, {1, 0, 0}), 0.0f);
    EXPECT_GT(surfacePlacementHeight(p, {0, 0, 0}, glm::normalize(glm::dvec3(1, 0, 0.2))), 0.0f);
    // The deformation model applies to L unchanged (eq. 1 at t = 0.5 with h = 2).
    BakePlacement half = p;
    half.t = 0.5;
    half.h = 2.0;
    const float L = sampleBilinear(pat, 0.5, 0.5);
    EXPECT_FLOAT_EQ(surfacePlacementHeight(half, {0, 0, 0}, up),
                    applyDeform(DeformModel::Scale, L, 2.0f, 0.5, deformConstant(DeformModel::Scale, Response::Log2, 0.5)));
}

TEST(SurfacePlacementTest, RotationTurnsThePatternAboutTheAnchorNormal) {
    // resolvePlacements applies `rotation` to the tangent: 90° turns t = x into b = y.
    Model m = cylinder();
    Scene s;
    Placement pl;
    pl.id = "a";
    pl.pattern = "p";
    pl.joint = "root";
    pl.projection = Projection::Surface;
    pl.anchor.position = {0.5, 1.0, 0.0};
    pl.anchor.normal = {1, 0, 0};
    pl.anchor.tangent = {0, 0, 1};
    pl.size = {0.4, 0.2};
    pl.rotation = 90.0;
    s.placements.push_back(pl);
    PatternImages images;
    images["p"] = makePatternImage(rampPattern());
    auto r = resolvePlacements(s, m, restPose(m), images);
    ASSERT_TRUE(r) << r.error().message;
    ASSERT_EQ(r->size(), 1u);
    const BakePlacement& b = (*r)[0];
    EXPECT_TRUE(b.surface);
    EXPECT_NEAR(glm::length(b.anchorTangent - glm::dvec3(0, -1, 0)), 0.0, 1e-12); // R(90°)·t = n × t
    EXPECT_DOUBLE_EQ(b.depth, 0.2); // max(w, h) / 2
    // A step along the old tangent (z) now moves the pattern's v (b' = n × t' = −z), not its u.
    glm::dvec2 st;
    ASSERT_TRUE(SurfaceFrame(b).toPattern({0.5, 1.0, 0.05}, {1, 0, 0}, st));
    EXPECT_NEAR(st.x, 0.5, 1e-12);
    EXPECT_NEAR(st.y, 0.5 - 0.05 / 0.2, 1e-12);
    // Without rotation the same point moves along s.x.
    s.placements[0].rotation = 0.0;
    auto r0 = resolvePlacements(s, m, restPose(m), images);
    ASSERT_TRUE(r0);
    ASSERT_TRUE(SurfaceFrame((*r0)[0]).toPattern({0.5, 1.0, 0.05}, {1, 0, 0}, st));
    EXPECT_NEAR(st.x, 0.5 + 0.05 / 0.4, 1e-12);
    EXPECT_NEAR(st.y, 0.5, 1e-12);
}

// --- the rest-surface map ------------------------------------------------------------------------

TEST(SurfacePlacementTest, RestSurfaceMapLiesOnTheSurfaceWithGutters) {
    const Model m = cylinder();
    const RestSurfaceMap rest = bakeRestSurface(m, modelTextureLayout(m), 128, 64);
    ASSERT_EQ(rest.width, 128);
    ASSERT_EQ(rest.position.size(), 128u * 64u);
    EXPECT_GT(rest.contentId, 0u);
    std::size_t covered = 0;
    for (int j = 0; j < 64; ++j)
        for (int i = 0; i < 128; ++i) {
            const std::size_t idx = static_cast<std::size_t>(j) * 128 + i;
            ASSERT_EQ(rest.coverage[idx], 1) << i << ", " << j; // the layout fills [0,1]²
            ++covered;
            const glm::dvec2 uv((i + 0.5) / 128, (j + 0.5) / 64);
            const glm::dvec3 expected = pointOfModelUv(uv);
            // On the faceted cylinder: within the chord's sagitta of the analytic point.
            EXPECT_LT(glm::length(glm::dvec3(rest.position[idx]) - expected), 2e-3) << i << ", " << j;
            EXPECT_NEAR(glm::length(glm::dvec3(rest.normal[idx])), 1.0, 1e-6);
        }
    EXPECT_EQ(covered, 128u * 64u);

    // A layout that covers part of the map: gutters of `dilate` texels copy the nearest texel.
    TextureLayout small = modelTextureLayout(m);
    for (glm::vec2& uv : small.parts[0].uvs) uv = glm::vec2(0.25f, 0.25f) + 0.5f * uv;
    const RestSurfaceMap g = bakeRestSurface(m, small, 64, 64, 3);
    auto at = [&](int i, int j) { return static_cast<std::size_t>(j) * 64 + i; };
    EXPECT_EQ(g.coverage[at(32, 32)], 1);
    EXPECT_EQ(g.coverage[at(15, 32)], 2); // one texel left of the chart (which starts at 16)
    EXPECT_EQ(g.coverage[at(13, 32)], 2); // three
    EXPECT_EQ(g.coverage[at(12, 32)], 0); // four: beyond the gutter
    EXPECT_EQ(g.position[at(15, 32)], g.position[at(16, 32)]);
    EXPECT_EQ(g.normal[at(13, 32)], g.normal[at(16, 32)]);
    EXPECT_EQ(g.coverage[at(14, 14)], 2); // diagonal: distance √8 ≤ 3
    EXPECT_EQ(g.position[at(14, 14)], g.position[at(16, 16)]);
    EXPECT_EQ(g.coverage[at(13, 13)], 0); // √18 > 3
    EXPECT_EQ(g.normal[at(2, 2)], glm::vec3(0.0f));
    // Tile bounds hold every covered position of their tile.
    ASSERT_EQ(g.tilesX, 4);
    for (int j = 0; j < 64; ++j)
        for (int i = 0; i < 64; ++i) {
            if (!g.coverage[at(i, j)]) continue;
            const std::size_t t = static_cast<std::size_t>(j / 16) * 4 + i / 16;
            EXPECT_TRUE(glm::all(glm::lessThanEqual(g.tileMin[t], g.position[at(i, j)])));
            EXPECT_TRUE(glm::all(glm::greaterThanEqual(g.tileMax[t], g.position[at(i, j)])));
        }
}

TEST(SurfacePlacementTest, RestSurfaceMapIsTheSameForAnyThreadCount) {
    const Model m = cylinder();
    TextureLayout small = modelTextureLayout(m);
    for (glm::vec2& uv : small.parts[0].uvs) uv = glm::vec2(0.1f, 0.3f) + glm::vec2(0.6f, 0.5f) * uv;
    const RestSurfaceMap a = bakeRestSurface(m, small, 200, 150, 4, 1);
    for (int threads : {2, 3, 7}) {
        const RestSurfaceMap b = bakeRestSurface(m, small, 200, 150, 4, threads);
        EXPECT_EQ(a.position, b.position) << threads;
        EXPECT_EQ(a.normal, b.normal) << threads;
        EXPECT_EQ(a.coverage, b.coverage) << threads;
        EXPECT_NE(a.contentId, b.contentId); // every bake is new content
    }
    EXPECT_EQ(bakeRestSurface(m, small, 0, 10).contentId, 0u); // bad size: an empty map
}

// --- decals ---------------------------------------------------------------------------------------

TEST(SurfacePlacementTest, ADecalAcrossTheSeamFollowsTheSurfaceOnBothSides) {
    const Model m = cylinder();
    const HeightImage pat = bumpPattern();
    const int W = 512, H = 256;
    const RestSurfaceMap rest = bakeRestSurface(m, modelTextureLayout(m), W, H);
    // On the seam (angle 0, u = 0 ≡ 1) at mid height, t along the angle, 0.6 × 0.5 model units.
    const std::vector<BakePlacement> ps = {
        surfaceAt(pat, cylinderPoint(0.0, 1.0), {1, 0, 0}, {0, 0, 1}, {0.6, 0.5}, 0.3)};
    BakeSettings bs;
    bs.width = W;
    bs.height = H;
    bs.rest = &rest;
    auto maps = bakeHeightMaps(ps, bs);
    ASSERT_TRUE(maps) << maps.error().message;
    const SurfaceFrame f(ps[0]);
    double left = 0.0, right = 0.0, maxErr = 0.0;
    for (int j = 0; j < H; ++j)
        for (int i = 0; i < W; ++i) {
            const glm::dvec2 uv((i + 0.5) / W, (j + 0.5) / H);
            // Expected: the bump at the analytic surface point of this UV (p − c along t, b).
            const glm::dvec3 p = pointOfModelUv(uv);
            const glm::dvec3 d = p - f.c;
            const glm::dvec3 n(std::cos(2 * kPi * uv.x), 0, std::sin(2 * kPi * uv.x));
            double expected = 0.0;
            if (glm::dot(n, f.n) > 0 && std::abs(glm::dot(d, f.n)) <= f.depth)
                expected = bumpAt({glm::dot(d, f.t) * f.invW + 0.5, glm::dot(d, f.b) * f.invH + 0.5});
            const double got = maps->bump.at(i, j);
            maxErr = std::max(maxErr, std::abs(got - expected));
            if (uv.x < 0.05) left = std::max(left, got);
            if (uv.x > 0.95) right = std::max(right, got);
        }
    EXPECT_LT(maxErr, 0.02);
    EXPECT_GT(left, 0.5);  // the decal continues on both sides of the seam:
    EXPECT_GT(right, 0.5); // u just above 0 and just below 1
    // Texels on either side of the seam at one height, one texel apart on the surface, agree
    // to within the bump's slope over a texel.
    for (int j = H / 2 - 20; j < H / 2 + 20; ++j)
        EXPECT_NEAR(maps->bump.at(0, j), maps->bump.at(W - 1, j), 0.02) << j;
    EXPECT_EQ(maps->displacement.at(0, H / 2), 0.0f);
}

TEST(SurfacePlacementTest, TheSameDecalGivesTheSameHeightsInAnotherLayout) {
    const Model m = cylinder();
    const HeightImage pat = bumpPattern();
    const TextureLayout a = modelTextureLayout(m), b = otherLayout(m);
    const int W = 512, H = 512;
    const RestSurfaceMap ra = bakeRestSurface(m, a, W, H), rb = bakeRestSurface(m, b, W, H);
    const std::vector<BakePlacement> ps = {
        surfaceAt(pat, cylinderPoint(0.3, 0.8), {std::cos(0.3), 0, std::sin(0.3)}, {0, 1, 0}, {0.5, 0.7}, 0.3),
        surfaceAt(pat, cylinderPoint(-0.2, 1.4), {std::cos(-0.2), 0, std::sin(-0.2)},
                  {-std::sin(-0.2), 0, std::cos(-0.2)}, {0.4, 0.3}, 0.2)};
    BakeSettings bs;
    bs.width = W;
    bs.height = H;
    bs.rest = &ra;
    auto ma = bakeHeightMaps(ps, bs);
    bs.rest = &rb;
    auto mb = bakeHeightMaps(ps, bs);
    ASSERT_TRUE(ma && mb);
    // Surface points away from the cylinder's caps: their UV in each layout, the maps sampled
    // there.
    double maxDiff = 0.0, peak = 0.0;
    for (int k = 0; k < 4000; ++k) {
        const double u = std::fmod(k * 0.6180339887, 1.0), v = 0.05 + 0.9 * std::fmod(k * 0.7548776662, 1.0);
        const glm::dvec2 uvA(u, v), uvB(0.1 + 0.8 * v, 0.05 + 0.9 * u);
        const float ha = sampleMap(ma->bump, uvA), hb = sampleMap(mb->bump, uvB);
        maxDiff = std::max(maxDiff, static_cast<double>(std::abs(ha - hb)));
        peak = std::max(peak, static_cast<double>(ha));
    }
    EXPECT_GT(peak, 0.8);
    EXPECT_LT(maxDiff, 0.03); // bilinear reconstruction of the same function on two grids
}

TEST(SurfacePlacementTest, BakeIsDeterministicAndNeedsARestMap) {
    const Model m = cylinder();
    const HeightImage pat = bumpPattern();
    const RestSurfaceMap rest = bakeRestSurface(m, modelTextureLayout(m), 300, 200);
    std::vector<BakePlacement> ps;
    for (int k = 0; k < 5; ++k) {
        const double a = 0.7 * k;
        BakePlacement p = surfaceAt(pat, cylinderPoint(a, 0.4 + 0.3 * k), {std::cos(a), 0, std::sin(a)},
                                    {0, 1, 0}, {0.5, 0.4}, 0.25);
        p.target = k % 2 ? Target::Displacement : Target::Bump;
        p.t = 0.2 * (k + 1);
        ps.push_back(p);
    }
    BakePlacement uvOne; // a UV placement mixed in (document order is kept)
    uvOne.pattern = &pat;
    uvOne.footprint.center = {0.4, 0.5};
    uvOne.footprint.scale = {0.3, 0.3};
    uvOne.t = 1.0;
    ps.insert(ps.begin() + 2, uvOne);
    BakeSettings bs;
    bs.width = 300;
    bs.height = 200;
    bs.rest = &rest;
    bs.threads = 1;
    auto one = bakeHeightMaps(ps, bs);
    ASSERT_TRUE(one) << one.error().message;
    for (int threads : {2, 5}) {
        bs.threads = threads;
        auto many = bakeHeightMaps(ps, bs);
        ASSERT_TRUE(many);
        EXPECT_EQ(one->bump.data, many->bump.data) << threads;
        EXPECT_EQ(one->displacement.data, many->displacement.data) << threads;
    }
    // Every texel is the per-texel definition summed in document order.
    for (int j = 0; j < 200; j += 7)
        for (int i = 0; i < 300; i += 5) {
            const std::size_t idx = static_cast<std::size_t>(j) * 300 + i;
            float bump = 0.0f, disp = 0.0f;
            for (const BakePlacement& p : ps) {
                const float v = p.surface ? surfacePlacementHeight(p, glm::dvec3(rest.position[idx]),
                                                                   glm::dvec3(rest.normal[idx]))
                                          : placementHeight(p, {(i + 0.5) / 300, (j + 0.5) / 200});
                (p.target == Target::Bump ? bump : disp) += v;
            }
            EXPECT_NEAR(one->bump.at(i, j), bump, 1e-5) << i << ", " << j;
            EXPECT_NEAR(one->displacement.at(i, j), disp, 1e-5) << i << ", " << j;
        }
    // Without a rest map (or one of another size) a surface placement cannot bake.
    bs.rest = nullptr;
    auto none = bakeHeightMaps(ps, bs);
    ASSERT_FALSE(none);
    EXPECT_EQ(none.error().field, "/placements/0/projection");
    const RestSurfaceMap other = bakeRestSurface(m, modelTextureLayout(m), 100, 100);
    bs.rest = &other;
    EXPECT_FALSE(bakeHeightMaps(ps, bs));
}

// --- planFrame ------------------------------------------------------------------------------------

namespace {

Scene cylinderScene() {
    Scene s;
    s.model = "cylinder";
    Placement pl;
    pl.id = "seam";
    pl.pattern = "bump";
    pl.joint = "root";
    pl.thetaMin = -1;
    pl.thetaMax = 0; // t = 1 at rest
    pl.projection = Projection::Surface;
    pl.anchor.position = {0.5, 1.0, 0.0};
    pl.anchor.normal = {1, 0, 0};
    pl.anchor.tangent = {0, 0, 1};
    pl.size = {0.6, 0.5};
    s.placements.push_back(pl);
    s.heightmapSize = {128, 64};
    return s;
}

} // namespace

TEST(SurfacePlacementTest, PlanFrameCarriesTheLayoutAndARestMap) {
    const Model m = cylinder();
    PatternImages images;
    images["bump"] = makePatternImage(bumpPattern());
    auto plan = planFrame(cylinderScene(), m, images, nullptr);
    ASSERT_TRUE(plan) << plan.error().message;
    EXPECT_EQ(plan->heights.layout, nullptr); // none given: the model's own UVs
    ASSERT_TRUE(plan->heights.rest);
    EXPECT_EQ(plan->heights.rest->width, 128);
    EXPECT_EQ(plan->heights.rest->height, 64);
    auto maps = bakeHeightMaps(plan->heights);
    ASSERT_TRUE(maps) << maps.error().message;
    EXPECT_GT(maps->bump.at(0, 32), 0.5f);

    // A layout and a rest map given by the caller are used as they are.
    FrameOverrides o;
    o.layout = std::make_shared<const TextureLayout>(otherLayout(m));
    o.rest = std::make_shared<const RestSurfaceMap>(bakeRestSurface(m, *o.layout, 128, 64));
    auto given = planFrame(cylinderScene(), m, images, nullptr, o);
    ASSERT_TRUE(given);
    EXPECT_EQ(given->heights.layout, o.layout);
    EXPECT_EQ(given->heights.rest, o.rest);
    // One of another size is not: a new one is baked at the map size.
    o.rest = std::make_shared<const RestSurfaceMap>(bakeRestSurface(m, *o.layout, 64, 64));
    auto rebaked = planFrame(cylinderScene(), m, images, nullptr, o);
    ASSERT_TRUE(rebaked);
    EXPECT_NE(rebaked->heights.rest, o.rest);
    EXPECT_EQ(rebaked->heights.rest->width, 128);

    // UV placements alone need no rest map.
    Scene uv = cylinderScene();
    uv.placements[0].projection = Projection::Uv;
    auto uvPlan = planFrame(uv, m, images, nullptr);
    ASSERT_TRUE(uvPlan);
    EXPECT_EQ(uvPlan->heights.rest, nullptr);
}

TEST(SurfacePlacementTest, ModelsWithoutUvsTakeSurfacePlacementsOnlyInALayoutWithUvs) {
    Model noUv = cylinder();
    noUv.parts[0].uvs.clear();
    PatternImages images;
    images["bump"] = makePatternImage(bumpPattern());
    // With the model's own (missing) UVs a surface placement has no map to live in.
    auto plan = planFrame(cylinderScene(), noUv, images, nullptr);
    ASSERT_FALSE(plan);
    EXPECT_EQ(plan.error().field, "/uv_layout");
    EXPECT_NE(plan.error().message.find("generated"), std::string::npos) << plan.error().message;
    // A layout from elsewhere (here: the UVs of the model's twin) makes it work.
    FrameOverrides o;
    o.layout = std::make_shared<const TextureLayout>(modelTextureLayout(cylinder()));
    auto withLayout = planFrame(cylinderScene(), noUv, images, nullptr, o);
    ASSERT_TRUE(withLayout) << withLayout.error().message;
    auto maps = bakeHeightMaps(withLayout->heights);
    ASSERT_TRUE(maps);
    EXPECT_GT(maps->bump.at(0, 32), 0.5f);
    // UV placements on a model without UVs still fail as before (no layout given).
    Scene uv = cylinderScene();
    uv.placements[0].projection = Projection::Uv;
    auto uvPlan = planFrame(uv, noUv, images, nullptr);
    ASSERT_FALSE(uvPlan);
    EXPECT_EQ(uvPlan.error().field, "/placements/0");
}
