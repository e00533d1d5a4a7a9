// EnvironmentTest — image-based lighting on the CPU (core/environment): the three.js
// equirectangular convention and its inverse, bilinear lookups, validation, the studio
// environment's layout, the split-sum prefiltering (irradiance SH and GGX levels), the DFG table
// against an independent quadrature, and the tone mappers against hand-computed values.
#include "core/environment.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

using namespace dermis;

namespace {

constexpr double kPi = 3.14159265358979323846;

EnvironmentImage constantImage(int w, int h, glm::vec3 value) {
    EnvironmentImage img;
    img.width = w;
    img.height = h;
    img.texels.assign(static_cast<std::size_t>(w) * h, value);
    return img;
}

/// Direction of the centre of texel (i, j), computed here from the convention in the header.
glm::dvec3 centreDirection(int i, int j, int w, int h) {
    const double phi = 2.0 * kPi * ((i + 0.5) / w - 0.5);
    const double theta = kPi * (0.5 - (j + 0.5) / h);
    return {std::cos(theta) * std::cos(phi), std::sin(theta), std::cos(theta) * std::sin(phi)};
}

/// Exact solid angle of a texel of row j.
double rowSolidAngle(int j, int w, int h) {
    return (2.0 * kPi / w) * (std::sin(kPi * (0.5 - static_cast<double>(j) / h)) -
                              std::sin(kPi * (0.5 - static_cast<double>(j + 1) / h)));
}

/// Solid-angle-weighted mean and variance of the red channel.
struct Moments {
    double mean = 0.0, variance = 0.0;
};

Moments moments(const EnvironmentImage& img) {
    double sum = 0.0, sum2 = 0.0, area = 0.0;
    for (int j = 0; j < img.height; ++j)
        for (int i = 0; i < img.width; ++i) {
            const double a = rowSolidAngle(j, img.width, img.height), v = img.at(i, j).r;
            sum += a * v;
            sum2 += a * v * v;
            area += a;
        }
    const double mean = sum / area;
    return {mean, sum2 / area - mean * mean};
}

void expectVecNear(glm::vec3 got, glm::vec3 want, float tol, const std::string& what) {
    EXPECT_NEAR(got.x, want.x, tol) << what;
    EXPECT_NEAR(got.y, want.y, tol) << what;
    EXPECT_NEAR(got.z, want.z, tol) << what;
}

/// The split-sum (scale, bias) at N·V = nDotV, perceptual roughness r, by a midpoint quadrature
/// over the hemisphere of L (not importance sampling): ∫ (1 − Fc, Fc)·D·Vis·N·L dL with the GGX
/// D, the height-correlated Smith Vis and Fc = (1 − V·H)^5.
glm::dvec2 dfgByQuadrature(double nDotV, double r) {
    const double alpha = r * r, a2 = alpha * alpha;
    const glm::dvec3 v(std::sqrt(1.0 - nDotV * nDotV), 0.0, nDotV);
    const int nTheta = 2000, nPhi = 1000; // φ over [0, π], doubled by symmetry
    const double dTheta = 0.5 * kPi / nTheta, dPhi = kPi / nPhi;
    glm::dvec2 sum(0.0);
    for (int a = 0; a < nTheta; ++a) {
        const double theta = (a + 0.5) * dTheta;
        for (int b = 0; b < nPhi; ++b) {
            const double phi = (b + 0.5) * dPhi;
            const glm::dvec3 l(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                               std::cos(theta));
            const glm::dvec3 h = glm::normalize(v + l);
            const double nDotL = l.z, nDotH = h.z, vDotH = glm::dot(v, h);
            const double f = nDotH * nDotH * (a2 - 1.0) + 1.0;
            const double d = a2 / (kPi * f * f);
            const double vis = 0.5 / (nDotL * std::sqrt(nDotV * nDotV * (1.0 - a2) + a2) +
                                      nDotV * std::sqrt(nDotL * nDotL * (1.0 - a2) + a2));
            const double fc = std::pow(1.0 - vDotH, 5.0);
            const double w = d * vis * nDotL * std::sin(theta) * dTheta * dPhi * 2.0;
            sum += glm::dvec2((1.0 - fc) * w, fc * w);
        }
    }
    return sum;
}

} // namespace

// --- the equirectangular convention ------------------------------------------------------------

TEST(EnvironmentTest, EquirectUvFollowsThreeJs) {
    // three.js: u = atan(z, x)/(2π) + 0.5, v = asin(y)/π + 0.5.
    expectVecNear(glm::vec3(equirectUv({1, 0, 0}), 0), {0.5f, 0.5f, 0}, 1e-6f, "+X");
    expectVecNear(glm::vec3(equirectUv({0, 0, 1}), 0), {0.75f, 0.5f, 0}, 1e-6f, "+Z");
    expectVecNear(glm::vec3(equirectUv({0, 0, -1}), 0), {0.25f, 0.5f, 0}, 1e-6f, "-Z");
    EXPECT_NEAR(equirectUv({0, 1, 0}).y, 1.0f, 1e-6f) << "up is v_up = 1 (row 0)";
    EXPECT_NEAR(equirectUv({0, -1, 0}).y, 0.0f, 1e-6f) << "down is v_up = 0 (last row)";
    const float uMinusX = equirectUv({-1, 0, 0}).x; // the seam: 0 or 1
    EXPECT_NEAR(std::min(uMinusX, 1.0f - uMinusX), 0.0f, 1e-6f);
    const float s = std::sqrt(0.5f);
    EXPECT_NEAR(equirectUv({s, s, 0}).y, 0.75f, 1e-6f) << "45° up";
}

TEST(EnvironmentTest, EquirectDirectionInvertsEquirectUv) {
    expectVecNear(equirectDirection({0.75f, 0.5f}), {0, 0, 1}, 1e-6f, "+Z");
    expectVecNear(equirectDirection({0.5f, 1.0f}), {0, 1, 0}, 1e-6f, "up");
    expectVecNear(equirectDirection({0.5f, 1.5f}), {0, 1, 0}, 1e-6f, "v_up clamped");
    for (int a = 1; a < 40; ++a)
        for (int b = 1; b < 20; ++b) {
            const glm::vec2 uv(a / 40.0f, b / 20.0f);
            const glm::vec3 d = equirectDirection(uv);
            EXPECT_NEAR(glm::length(d), 1.0f, 1e-6f);
            const glm::vec2 back = equirectUv(d);
            EXPECT_NEAR(back.x, uv.x, 1e-5f) << a << "," << b;
            EXPECT_NEAR(back.y, uv.y, 1e-5f) << a << "," << b;
        }
    const glm::vec3 d = glm::normalize(glm::vec3(-0.3f, 0.4f, -0.8f));
    expectVecNear(equirectDirection(equirectUv(d)), d, 1e-5f, "direction round trip");
}

TEST(EnvironmentTest, SampleEquirectIsBilinearWrapsInUAndClampsRows) {
    EnvironmentImage img = constantImage(4, 2, glm::vec3(0.0f));
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 4; ++i)
            img.texels[static_cast<std::size_t>(j) * 4 + i] = glm::vec3(i, j, 10 * j + i);
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 4; ++i)
            expectVecNear(sampleEquirect(img, glm::vec3(centreDirection(i, j, 4, 2))), img.at(i, j),
                          1e-4f, "texel centre");
    // u = 0 (−X) at row 0's centre lies between the last and the first column: wraps.
    expectVecNear(sampleEquirect(img, equirectDirection({0.0f, 0.75f})),
                  0.5f * (img.at(3, 0) + img.at(0, 0)), 1e-4f, "seam");
    // Straight up (u = 0.5, v_up = 1) clamps to row 0, between columns 1 and 2.
    expectVecNear(sampleEquirect(img, {0, 1, 0}), 0.5f * (img.at(1, 0) + img.at(2, 0)), 1e-4f,
                  "zenith");
    // Half way between the rows' centres (the equator) mixes both rows.
    expectVecNear(sampleEquirect(img, equirectDirection({0.625f, 0.5f})),
                  0.5f * (img.at(2, 0) + img.at(2, 1)), 1e-4f, "equator");
    EXPECT_EQ(sampleEquirect(EnvironmentImage{}, {0, 1, 0}), glm::vec3(0.0f));
    EnvironmentImage broken = img;
    broken.texels.pop_back();
    EXPECT_EQ(sampleEquirect(broken, {0, 1, 0}), glm::vec3(0.0f));
    const float nan = std::numeric_limits<float>::quiet_NaN();
    EXPECT_EQ(sampleEquirect(img, {nan, 0, 1}), glm::vec3(0.0f));
}

// --- validation ---------------------------------------------------------------------------------

TEST(EnvironmentTest, ValidateEnvironmentNamesTheBadField) {
    EXPECT_TRUE(validateEnvironment(constantImage(2, 2, glm::vec3(0.0f))).ok());
    EXPECT_TRUE(validateEnvironment(constantImage(3, 7, glm::vec3(1.0f))).ok()) << "2:1 not needed";
    auto expectError = [](const EnvironmentImage& env, const std::string& field) {
        const Status s = validateEnvironment(env);
        ASSERT_FALSE(s.ok()) << field;
        EXPECT_EQ(s.error().code, ErrorCode::InvalidArgument);
        EXPECT_EQ(s.error().field, field);
        EXPECT_NE(s.error().message.find("dermis::validateEnvironment"), std::string::npos);
    };
    expectError(EnvironmentImage{}, "width");
    expectError(constantImage(1, 4, glm::vec3(1.0f)), "width");
    expectError(constantImage(4, 1, glm::vec3(1.0f)), "height");
    EnvironmentImage env = constantImage(4, 2, glm::vec3(1.0f));
    env.texels.push_back(glm::vec3(1.0f));
    expectError(env, "texels");
    env = constantImage(4, 2, glm::vec3(1.0f));
    env.texels[5].g = std::numeric_limits<float>::quiet_NaN();
    expectError(env, "texels[5]");
    env.texels[5].g = std::numeric_limits<float>::infinity();
    expectError(env, "texels[5]");
    env.texels[5].g = -0.01f;
    expectError(env, "texels[5]");
}

// --- the studio environment
// -----------------------------------------------------------------------

TEST(EnvironmentTest, StudioEnvironmentIsNeutralFiniteAndMidBright) {
    const EnvironmentImage env = studioEnvironment(256);
    EXPECT_EQ(env.width, 256);
    EXPECT_EQ(env.height, 128);
    ASSERT_TRUE(validateEnvironment(env).ok()) << validateEnvironment(env).error().message;
    for (const glm::vec3& t : env.texels) {
        EXPECT_EQ(t.r, t.g);
        EXPECT_EQ(t.r, t.b);
    }
    const Moments m = moments(env);
    EXPECT_GE(m.mean, 0.5);
    EXPECT_LE(m.mean, 1.0);
    const EnvironmentImage small = studioEnvironment(2);
    EXPECT_EQ(small.width, 8) << "width clamped to >= 8";
    EXPECT_EQ(small.height, 4);
}

TEST(EnvironmentTest, StudioEnvironmentIsBrighterAboveThanBelow) {
    const EnvironmentImage env = studioEnvironment(256);
    double above = 0.0, below = 0.0;
    for (int j = 0; j < env.height; ++j)
        for (int i = 0; i < env.width; ++i)
            (j < env.height / 2 ? above : below) +=
                rowSolidAngle(j, env.width, env.height) * env.at(i, j).r;
    EXPECT_GT(above, 3.0 * below);
    EXPECT_NEAR(sampleEquirect(env, {0, 1, 0}).r, 0.85f, 0.01f) << "the dome's top";
    EXPECT_NEAR(sampleEquirect(env, {0, -1, 0}).r, 0.12f, 0.01f) << "the floor's bottom";
}

TEST(EnvironmentTest, StudioLightsAreWhereTheHeaderSays) {
    const EnvironmentImage env = studioEnvironment(256);
    const glm::vec3 key = glm::normalize(glm::vec3(-0.5f, 0.6f, 0.6f));
    const glm::vec3 fill = glm::normalize(glm::vec3(1.0f, 0.15f, 0.35f));
    const glm::vec3 rim = glm::normalize(glm::vec3(0.25f, 0.45f, -0.85f));
    EXPECT_NEAR(sampleEquirect(env, key).r, 6.0f, 1e-3f);
    EXPECT_NEAR(sampleEquirect(env, fill).r, 1.5f, 1e-3f);
    EXPECT_NEAR(sampleEquirect(env, rim).r, 3.0f, 1e-3f);
    // The key light is the brightest thing, and the solid-angle-weighted centroid of everything
    // brighter than the rim is the key's direction (up, in front of the character, to the left
    // of a camera on +Z).
    glm::dvec3 centroid(0.0);
    float brightest = 0.0f;
    for (int j = 0; j < env.height; ++j)
        for (int i = 0; i < env.width; ++i) {
            brightest = std::max(brightest, env.at(i, j).r);
            if (env.at(i, j).r > 3.5f)
                centroid += rowSolidAngle(j, env.width, env.height) *
                            centreDirection(i, j, env.width, env.height);
        }
    EXPECT_NEAR(brightest, 6.0f, 1e-3f);
    const glm::vec3 c = glm::normalize(glm::vec3(centroid));
    EXPECT_GT(glm::dot(c, key), std::cos(2.0 * kPi / 180.0)) << c.x << " " << c.y << " " << c.z;
    EXPECT_LT(c.x, 0.0f);
    EXPECT_GT(c.y, 0.0f);
    EXPECT_GT(c.z, 0.0f);
}

// --- prefiltering
// ---------------------------------------------------------------------------------

TEST(EnvironmentTest, ConstantEnvironmentGivesConstantIrradianceAndSpecular) {
    const glm::vec3 radiance(0.3f, 0.7f, 1.2f);
    // 90 × 45: box weights that do not divide evenly; 512 × 256: a true downsample at level 0.
    for (const EnvironmentImage& env :
         {constantImage(90, 45, radiance), constantImage(512, 256, radiance)}) {
        const PrefilteredEnvironment pre = prefilterEnvironment(env);
        for (int a = 0; a < 12; ++a)
            for (int b = 0; b <= 6; ++b) {
                const glm::vec3 n = equirectDirection({a / 12.0f, b / 6.0f});
                expectVecNear(evalIrradiance(pre.irradianceSh, n), radiance, 2e-3f, "irradiance");
            }
        ASSERT_EQ(pre.specular.size(), 6u);
        for (std::size_t k = 0; k < pre.specular.size(); ++k)
            for (const glm::vec3& t : pre.specular[k].texels)
                expectVecNear(t, radiance, 1e-4f, "level " + std::to_string(k));
    }
}

TEST(EnvironmentTest, SkyDomeIrradianceIsExact) {
    // Radiance L above the horizon, 0 below: E(n)/π = L·(1 + n·Y)/2, which order-2 SH holds
    // exactly (a hemisphere has no band-2 irradiance).
    const glm::vec3 sky(1.0f, 0.5f, 0.25f);
    EnvironmentImage env = constantImage(256, 128, glm::vec3(0.0f));
    for (int j = 0; j < 64; ++j)
        for (int i = 0; i < 256; ++i)
            env.texels[static_cast<std::size_t>(j) * 256 + i] = sky;
    const PrefilteredEnvironment pre = prefilterEnvironment(env, 1);
    for (int a = 0; a < 8; ++a)
        for (int b = 0; b <= 8; ++b) {
            const glm::vec3 n = equirectDirection({a / 8.0f, b / 8.0f});
            expectVecNear(evalIrradiance(pre.irradianceSh, n), sky * (0.5f * (1.0f + n.y)), 2e-3f,
                          "n.y = " + std::to_string(n.y));
        }
}

TEST(EnvironmentTest, PolynomialEnvironmentIrradianceFollowsTheConvolutionFactors) {
    // Radiance 1 + (band 1) + (band 2) in every basis function: E(n)/π keeps band 0, scales band
    // 1 by 2/3 and band 2 by 1/4 (Â_l / π), whatever the axis (the basis order is checked too).
    auto band1 = [](glm::dvec3 d) { return 0.10 * d.x + 0.12 * d.y - 0.08 * d.z; };
    auto band2 = [](glm::dvec3 d) {
        return 0.10 * d.x * d.y - 0.07 * d.y * d.z + 0.05 * (3.0 * d.z * d.z - 1.0) +
               0.09 * d.x * d.z + 0.06 * (d.x * d.x - d.y * d.y);
    };
    EnvironmentImage env = constantImage(256, 128, glm::vec3(0.0f));
    for (int j = 0; j < 128; ++j)
        for (int i = 0; i < 256; ++i) {
            const glm::dvec3 d = centreDirection(i, j, 256, 128);
            const double l = 1.0 + band1(d) + band2(d);
            env.texels[static_cast<std::size_t>(j) * 256 + i] =
                glm::vec3(glm::dvec3(l, 2.0 * l, 0.5 * l));
        }
    const PrefilteredEnvironment pre = prefilterEnvironment(env, 1);
    for (int a = 0; a < 12; ++a)
        for (int b = 0; b <= 6; ++b) {
            const glm::vec3 n = equirectDirection({a / 12.0f, b / 6.0f});
            const glm::dvec3 dn(n);
            const double e = 1.0 + 2.0 / 3.0 * band1(dn) + 0.25 * band2(dn);
            expectVecNear(evalIrradiance(pre.irradianceSh, n),
                          glm::vec3(glm::dvec3(e, 2.0 * e, 0.5 * e)), 1e-3f,
                          std::to_string(a) + "," + std::to_string(b));
        }
}

TEST(EnvironmentTest, SpecularLevelsMatchABruteForceConvolution) {
    // Each texel of level k against the GGX kernel D(h)·(N·L) summed over every source texel by
    // solid angle (N = V = R): the filtered importance sampling stays close to it.
    const EnvironmentImage env = studioEnvironment(256);
    const PrefilteredEnvironment pre = prefilterEnvironment(env);
    std::vector<glm::dvec3> dirs;
    std::vector<double> weights;
    for (int j = 0; j < env.height; ++j)
        for (int i = 0; i < env.width; ++i) {
            dirs.push_back(centreDirection(i, j, env.width, env.height));
            weights.push_back(rowSolidAngle(j, env.width, env.height));
        }
    const double tolerance[6] = {0.0, 0.05, 0.025, 0.02, 0.02, 0.02};
    for (int k = 1; k < 6; ++k) {
        const EnvironmentImage& level = pre.specular[k];
        const double alpha = (k / 5.0) * (k / 5.0), a2 = alpha * alpha;
        const int step = level.width >= 32 ? 5 : 1; // a subset of the larger levels
        for (int t = 0; t < level.width * level.height; t += step) {
            const int i = t % level.width, j = t / level.width;
            const glm::dvec3 n = centreDirection(i, j, level.width, level.height);
            double sum = 0.0, wsum = 0.0;
            for (std::size_t q = 0; q < dirs.size(); ++q) {
                const double nDotL = glm::dot(n, dirs[q]);
                if (nDotL <= 0.0) continue;
                const double nDotH = glm::dot(n, glm::normalize(n + dirs[q]));
                const double f = nDotH * nDotH * (a2 - 1.0) + 1.0;
                const double w = a2 / (kPi * f * f) * nDotL * weights[q];
                sum += w * env.texels[q].r;
                wsum += w;
            }
            const double want = sum / wsum;
            EXPECT_NEAR(level.at(i, j).r, want, tolerance[k] * want)
                << "level " << k << " texel " << i << "," << j;
        }
    }
}

TEST(EnvironmentTest, LevelSizesHalveDownToEightByFour) {
    const EnvironmentImage env = studioEnvironment(256);
    const PrefilteredEnvironment pre = prefilterEnvironment(env);
    const int widths[6] = {128, 64, 32, 16, 8, 8};
    ASSERT_EQ(pre.specular.size(), 6u);
    for (int k = 0; k < 6; ++k) {
        EXPECT_EQ(pre.specular[k].width, widths[k]) << k;
        EXPECT_EQ(pre.specular[k].height, std::max(4, widths[k] / 2)) << k;
        EXPECT_TRUE(validateEnvironment(pre.specular[k]).ok()) << k;
    }
    EXPECT_EQ(prefilterEnvironment(env, 1).specular.size(), 1u);
    EXPECT_EQ(prefilterEnvironment(env, 0).specular.size(), 1u) << "levels clamped to >= 1";
    const PrefilteredEnvironment wide = prefilterEnvironment(env, 3, 200);
    ASSERT_EQ(wide.specular.size(), 3u);
    EXPECT_EQ(wide.specular[2].width, 50);
    EXPECT_EQ(wide.specular[2].height, 25);
}

TEST(EnvironmentTest, MirrorLevelIsTheSourceAreaAveraged) {
    const EnvironmentImage env = studioEnvironment(256);
    const PrefilteredEnvironment pre = prefilterEnvironment(env, 2);
    const EnvironmentImage& mirror = pre.specular[0];
    EXPECT_NEAR(moments(mirror).mean, moments(env).mean, 1e-5);
    // A 2:1 downsample: each texel the solid-angle-weighted mean of its 2 × 2 source texels.
    for (int j : {0, 17, 40, 63})
        for (int i : {0, 50, 127}) {
            double sum = 0.0, area = 0.0;
            for (int sj = 2 * j; sj < 2 * j + 2; ++sj)
                for (int si = 2 * i; si < 2 * i + 2; ++si) {
                    sum += rowSolidAngle(sj, 256, 128) * env.at(si, sj).r;
                    area += rowSolidAngle(sj, 256, 128);
                }
            EXPECT_NEAR(mirror.at(i, j).r, sum / area, 1e-5) << i << "," << j;
        }
}

TEST(EnvironmentTest, SpecularLevelsGetBlurrierAndKeepTheMean) {
    const EnvironmentImage env = studioEnvironment(256);
    const PrefilteredEnvironment pre = prefilterEnvironment(env);
    const double mean = moments(env).mean;
    double lastVariance = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < pre.specular.size(); ++k) {
        const Moments m = moments(pre.specular[k]);
        EXPECT_NEAR(m.mean, mean, 0.02 * mean) << "level " << k;
        EXPECT_LT(m.variance, lastVariance) << "level " << k;
        lastVariance = m.variance;
    }
    // The key light spreads out: its peak falls with roughness, the far side brightens.
    const glm::vec3 key = glm::normalize(glm::vec3(-0.5f, 0.6f, 0.6f));
    for (std::size_t k = 1; k < pre.specular.size(); ++k) {
        EXPECT_LT(sampleEquirect(pre.specular[k], key).r,
                  sampleEquirect(pre.specular[k - 1], key).r)
            << k;
        EXPECT_GT(sampleEquirect(pre.specular[k], -key).r,
                  sampleEquirect(pre.specular[k - 1], -key).r)
            << k;
    }
}

TEST(EnvironmentTest, StudioIrradianceComesFromTheKeyAndTheDome) {
    const PrefilteredEnvironment pre = prefilterEnvironment(studioEnvironment(256));
    const glm::vec3 key = glm::normalize(glm::vec3(-0.5f, 0.6f, 0.6f));
    const float towards = evalIrradiance(pre.irradianceSh, key).r;
    EXPECT_GT(towards, 2.0f * evalIrradiance(pre.irradianceSh, -key).r);
    EXPECT_GT(evalIrradiance(pre.irradianceSh, {0, 1, 0}).r,
              evalIrradiance(pre.irradianceSh, {0, -1, 0}).r);
    EXPECT_GT(evalIrradiance(pre.irradianceSh, {-1, 0, 0}).r,
              evalIrradiance(pre.irradianceSh, {1, 0, 0}).r)
        << "the key (left) outweighs the fill (right)";
    // A white Lambert surface facing the key reads bright but not blown out.
    EXPECT_GT(towards, 0.8f);
    EXPECT_LT(towards, 2.5f);
}

TEST(EnvironmentTest, PrefilterOfAnInvalidEnvironmentIsEmpty) {
    EnvironmentImage env = constantImage(8, 4, glm::vec3(1.0f));
    env.texels[3].r = std::numeric_limits<float>::quiet_NaN();
    const PrefilteredEnvironment pre = prefilterEnvironment(env);
    EXPECT_TRUE(pre.specular.empty());
    for (const glm::vec3& c : pre.irradianceSh)
        EXPECT_EQ(c, glm::vec3(0.0f));
}

TEST(EnvironmentTest, EvalIrradianceClampsRingingAtZero) {
    std::array<glm::vec3, 9> sh{};
    sh[1] = glm::vec3(1.0f); // 0.488603·y alone: negative below the horizon
    EXPECT_NEAR(evalIrradiance(sh, {0, 1, 0}).r, 0.488603f, 1e-5f);
    EXPECT_EQ(evalIrradiance(sh, {0, -1, 0}), glm::vec3(0.0f));
}

// --- the DFG table
// --------------------------------------------------------------------------------

TEST(EnvironmentTest, BrdfLutHasTheRequestedLayout) {
    EXPECT_EQ(brdfLut(32).size(), 32u * 32u);
    EXPECT_EQ(brdfLut(5, 16).size(), 25u);
    EXPECT_TRUE(brdfLut(0).empty());
    EXPECT_TRUE(brdfLut(2000).empty());
    EXPECT_TRUE(brdfLut(8, 0).empty());
}

TEST(EnvironmentTest, BrdfLutConservesEnergyAndFollowsFresnel) {
    const int n = 32;
    const std::vector<glm::vec2> lut = brdfLut(n);
    auto at = [&](int i, int j) { return lut[static_cast<std::size_t>(j) * n + i]; };
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const glm::vec2 e = at(i, j);
            ASSERT_TRUE(std::isfinite(e.x) && std::isfinite(e.y));
            EXPECT_GE(e.x, 0.0f);
            EXPECT_GE(e.y, 0.0f);
            EXPECT_LE(e.x + e.y, 1.0f + 2e-3f) << "N·V index " << i << ", roughness index " << j;
        }
    // Near-mirror (roughness 1/64): all light reflects, Schlick's Fresnel splits it:
    // bias = (1 − N·V)^5.
    for (int i = 0; i < n; ++i) {
        const double nDotV = (i + 0.5) / n;
        EXPECT_NEAR(at(i, 0).x + at(i, 0).y, 1.0f, 5e-3f) << i;
        EXPECT_NEAR(at(i, 0).y, std::pow(1.0 - nDotV, 5.0), 5e-3) << i;
    }
    EXPECT_NEAR(at(n - 1, 0).x, 1.0f, 1e-3f) << "N·V ≈ 1, roughness ≈ 0";
    EXPECT_NEAR(at(n - 1, 0).y, 0.0f, 1e-3f);
    for (int j = 1; j < n; ++j) {
        // At grazing view the Fresnel term (bias) falls and scale rises as roughness spreads
        // the half vectors away from V.
        EXPECT_LE(at(0, j).y, at(0, j - 1).y + 1e-4f) << j;
        EXPECT_GE(at(0, j).x, at(0, j - 1).x - 1e-4f) << j;
        // Away from grazing, single scattering loses energy as roughness rises.
        for (int i = n / 4; i < n; ++i)
            EXPECT_LE(at(i, j).x + at(i, j).y, at(i, j - 1).x + at(i, j - 1).y + 1e-3f)
                << i << "," << j;
    }
}

TEST(EnvironmentTest, BrdfLutMatchesAnIndependentQuadrature) {
    // 256 Hammersley samples: within ≈ 0.01 of the integral, ≈ 0.02 towards grazing view.
    const int n = 32;
    const std::vector<glm::vec2> lut = brdfLut(n);
    const struct {
        int i, j;
        double tolerance;
    } points[] = {{15, 15, 0.01}, {24, 25, 0.01}, {31, 31, 0.01}, {6, 20, 0.02}};
    for (const auto& p : points) {
        const glm::dvec2 want = dfgByQuadrature((p.i + 0.5) / n, (p.j + 0.5) / n);
        const glm::vec2 got = lut[static_cast<std::size_t>(p.j) * n + p.i];
        EXPECT_NEAR(got.x, want.x, p.tolerance) << p.i << "," << p.j;
        EXPECT_NEAR(got.y, want.y, p.tolerance) << p.i << "," << p.j;
    }
}

// --- tone mapping
// ---------------------------------------------------------------------------------

TEST(EnvironmentTest, PbrNeutralKeepsMidtonesAndCompressesHighlights) {
    expectVecNear(toneMapPbrNeutral(glm::vec3(0.0f)), glm::vec3(0.0f), 0.0f, "black");
    // Below 0.08 the toe 6.25x²; from 0.08 to startCompression + 0.04 = 0.8 minus the 0.04 offset.
    expectVecNear(toneMapPbrNeutral(glm::vec3(0.04f)), glm::vec3(0.01f), 1e-6f, "toe");
    expectVecNear(toneMapPbrNeutral(glm::vec3(0.5f)), glm::vec3(0.46f), 1e-6f, "mid grey");
    expectVecNear(toneMapPbrNeutral({0.5f, 0.3f, 0.2f}), {0.46f, 0.26f, 0.16f}, 1e-6f, "colour");
    // 1.0: c = 0.96, peak 0.96 ≥ 0.76, d = 0.24, newPeak = 1 − 0.0576/0.44 = 0.8690909 (by hand).
    expectVecNear(toneMapPbrNeutral(glm::vec3(1.0f)), glm::vec3(0.8690909f), 1e-5f, "white");
    float last = -1.0f;
    for (int k = 0; k <= 2000; ++k) {
        const float out = toneMapPbrNeutral(glm::vec3(k * 0.01f)).r;
        EXPECT_GE(out, last) << k;
        EXPECT_LT(out, 1.0f) << k;
        last = out;
    }
    EXPECT_GT(toneMapPbrNeutral(glm::vec3(1000.0f)).r, 0.99f);
    // A bright colour is desaturated towards white: the channels' ratio rises.
    const glm::vec3 bright = toneMapPbrNeutral({4.0f, 1.0f, 0.5f});
    EXPECT_LT(bright.r, 1.0f);
    EXPECT_GT(bright.b / bright.r, (0.5f - 0.04f) / (4.0f - 0.04f));
}

TEST(EnvironmentTest, AcesFilmicMatchesThreeJs) {
    expectVecNear(toneMapAcesFilmic(glm::vec3(0.0f)), glm::vec3(0.0f), 0.0f, "black");
    // Grey 1.0 by hand: v = 1/0.6 = 1.6666667 (the input matrix's rows sum to 1);
    // a = v(v + 0.0245786) − 0.000090537 = 2.8186516, b = v(0.983729v + 0.432951) + 0.238081
    // = 3.6922466, a/b = 0.7633974; the output matrix's rows sum to 1, 1, 0.99999.
    expectVecNear(toneMapAcesFilmic(glm::vec3(1.0f)), {0.763397f, 0.763397f, 0.763390f}, 2e-5f,
                  "white");
    float last = -1.0f;
    for (int k = 0; k <= 2000; ++k) {
        const float out = toneMapAcesFilmic(glm::vec3(k * 0.01f)).g;
        EXPECT_GE(out, last) << k;
        EXPECT_LE(out, 1.0f) << k;
        last = out;
    }
    EXPECT_EQ(toneMapAcesFilmic(glm::vec3(100.0f)), glm::vec3(1.0f)) << "clamped";
}
