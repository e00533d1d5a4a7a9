// NormalMapTest — UV-space normal maps of bump maps: sign conventions (+X = +u, +Y = up in the
// image = decreasing row), central and one-sided differences, strength, 8-bit encoding, errors.
#include "core/normalmap.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

using namespace dermis;

namespace {

/// normalize(−s·dx, s·dy, 1), computed here independently in double.
glm::dvec3 expected(double s, double dx, double dy) {
    const glm::dvec3 v(-s * dx, s * dy, 1.0);
    return v / std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
}

void expectNormal(const NormalImage& n, int i, int j, glm::dvec3 want) {
    const glm::vec3& got = n.at(i, j);
    EXPECT_NEAR(got.x, want.x, 1e-6) << "texel " << i << "," << j;
    EXPECT_NEAR(got.y, want.y, 1e-6) << "texel " << i << "," << j;
    EXPECT_NEAR(got.z, want.z, 1e-6) << "texel " << i << "," << j;
}

HeightImage fromFunction(int w, int h, double (*f)(int, int)) {
    HeightImage img(w, h);
    for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i)
            img.at(i, j) = static_cast<float>(f(i, j));
    return img;
}

} // namespace

TEST(NormalMapTest, FlatMapPointsStraightOut) {
    HeightImage flat(5, 3, 0.7f);
    auto n = normalMapFromBump(flat, 4.0);
    ASSERT_TRUE(n.ok()) << n.error().message;
    ASSERT_EQ(n->width, 5);
    ASSERT_EQ(n->height, 3);
    ASSERT_EQ(n->data.size(), 15u);
    for (const glm::vec3& v : n->data) {
        EXPECT_EQ(v.x, 0.0f);
        EXPECT_EQ(v.y, 0.0f);
        EXPECT_EQ(v.z, 1.0f);
    }
}

TEST(NormalMapTest, RampRisingTowardsPlusUTiltsTowardsMinusU) {
    // H = 0.1·column: every texel (borders included, the ramp is linear) has dH/dcolumn = 0.1.
    auto bump = fromFunction(6, 4, [](int i, int) { return 0.1 * i; });
    auto n = normalMapFromBump(bump, 2.0);
    ASSERT_TRUE(n.ok()) << n.error().message;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 6; ++i) {
            EXPECT_LT(n->at(i, j).x, 0.0f);
            expectNormal(*n, i, j, expected(2.0, 0.1, 0.0)); // (−0.2, 0, 1)/√1.04
        }
    EXPECT_NEAR(n->at(2, 1).x, -0.2 / std::sqrt(1.04), 1e-7);
    EXPECT_NEAR(n->at(2, 1).z, 1.0 / std::sqrt(1.04), 1e-7);
}

TEST(NormalMapTest, RampRisingDownTheImageTiltsUpInTheImage) {
    // H = 0.25·row: height grows towards +v (down in the image), so the normal leans towards
    // −v, which is +Y ("up" in the image, OpenGL convention).
    auto bump = fromFunction(3, 5, [](int, int j) { return 0.25 * j; });
    auto n = normalMapFromBump(bump, 1.0);
    ASSERT_TRUE(n.ok()) << n.error().message;
    for (int j = 0; j < 5; ++j)
        for (int i = 0; i < 3; ++i) {
            EXPECT_GT(n->at(i, j).y, 0.0f);
            expectNormal(*n, i, j, expected(1.0, 0.0, 0.25)); // (0, 0.25, 1)/√1.0625
        }
    // And a ramp rising up the image (towards −v) leans down: n.y < 0.
    auto down = normalMapFromBump(fromFunction(3, 5, [](int, int j) { return -0.25 * j; }), 1.0);
    ASSERT_TRUE(down.ok());
    EXPECT_NEAR(down->at(1, 2).y, -0.25 / std::sqrt(1.0625), 1e-7);
}

TEST(NormalMapTest, DomeNormalsPointAwayFromItsCentre) {
    // A hill centred on texel (4, 4): left of it n.x < 0, right n.x > 0, above it (smaller
    // rows) n.y > 0, below n.y < 0; the top is flat.
    auto bump = fromFunction(9, 9, [](int i, int j) {
        return std::exp(-((i - 4.0) * (i - 4.0) + (j - 4.0) * (j - 4.0)) / 8.0);
    });
    auto n = normalMapFromBump(bump, 3.0);
    ASSERT_TRUE(n.ok());
    EXPECT_LT(n->at(2, 4).x, 0.0f);
    EXPECT_GT(n->at(6, 4).x, 0.0f);
    EXPECT_GT(n->at(4, 2).y, 0.0f);
    EXPECT_LT(n->at(4, 6).y, 0.0f);
    EXPECT_NEAR(n->at(2, 4).y, 0.0f, 1e-7);
    EXPECT_NEAR(n->at(4, 2).x, 0.0f, 1e-7);
    expectNormal(*n, 4, 4, {0.0, 0.0, 1.0});
}

TEST(NormalMapTest, CentralDifferencesInsideOneSidedAtBorders) {
    // Columns 0, 1, 4, 9 (H = i²): dH/di = 1 (one-sided), 2, 4 (central), 5 (one-sided).
    auto bumpU = fromFunction(4, 2, [](int i, int) { return double(i * i); });
    auto nu = normalMapFromBump(bumpU, 0.5);
    ASSERT_TRUE(nu.ok());
    const double du[] = {1.0, 2.0, 4.0, 5.0};
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 4; ++i)
            expectNormal(*nu, i, j, expected(0.5, du[i], 0.0));
    // The same along rows (and the +Y sign for each).
    auto bumpV = fromFunction(2, 4, [](int, int j) { return double(j * j); });
    auto nv = normalMapFromBump(bumpV, 0.5);
    ASSERT_TRUE(nv.ok());
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 2; ++i)
            expectNormal(*nv, i, j, expected(0.5, 0.0, du[j]));
}

TEST(NormalMapTest, BothSlopesAtOnce) {
    auto bump = fromFunction(4, 3, [](int i, int j) { return 0.3 * i - 0.2 * j; });
    auto n = normalMapFromBump(bump, 1.5);
    ASSERT_TRUE(n.ok());
    for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 4; ++i)
            expectNormal(*n, i, j, expected(1.5, 0.3, -0.2));
    EXPECT_LT(n->at(1, 1).x, 0.0f); // rises towards +u
    EXPECT_LT(n->at(1, 1).y, 0.0f); // rises towards −v (up the image): leans down
}

TEST(NormalMapTest, OneTexelWideAxesHaveNoSlope) {
    auto row = normalMapFromBump(fromFunction(3, 1, [](int i, int) { return 0.5 * i; }), 1.0);
    ASSERT_TRUE(row.ok());
    expectNormal(*row, 1, 0, expected(1.0, 0.5, 0.0));
    auto single = normalMapFromBump(HeightImage(1, 1, 3.0f), 10.0);
    ASSERT_TRUE(single.ok());
    expectNormal(*single, 0, 0, {0.0, 0.0, 1.0});
}

TEST(NormalMapTest, ZeroStrengthIsFlatAndStrengthScalesSlopes) {
    auto bump = fromFunction(7, 5, [](int i, int j) { return std::sin(i * 1.3) + 0.5 * j * j; });
    auto flat = normalMapFromBump(bump, 0.0);
    ASSERT_TRUE(flat.ok());
    for (const glm::vec3& v : flat->data) {
        EXPECT_EQ(v.x, 0.0f);
        EXPECT_EQ(v.y, 0.0f);
        EXPECT_EQ(v.z, 1.0f);
    }
    auto weak = normalMapFromBump(bump, 0.1), strong = normalMapFromBump(bump, 10.0);
    ASSERT_TRUE(weak.ok() && strong.ok());
    // Steeper with more strength: z shrinks wherever there is a slope.
    EXPECT_LT(strong->at(3, 2).z, weak->at(3, 2).z);
    for (const glm::vec3& v : strong->data)
        EXPECT_NEAR(glm::length(v), 1.0f, 1e-6f);
}

TEST(NormalMapTest, HugeStrengthStaysFiniteAndUnit) {
    auto bump = fromFunction(3, 3, [](int i, int j) { return 1e30 * i + 2e30 * j; });
    for (double s : {1e10, 1e300, std::numeric_limits<double>::max()}) {
        auto n = normalMapFromBump(bump, s);
        ASSERT_TRUE(n.ok()) << s;
        for (const glm::vec3& v : n->data) {
            ASSERT_TRUE(std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z)) << s;
            EXPECT_NEAR(glm::length(v), 1.0f, 1e-6f) << s;
        }
        // (−1, 2, ~0)/√5: in the surface plane.
        EXPECT_NEAR(n->at(1, 1).x, -1.0 / std::sqrt(5.0), 1e-6) << s;
        EXPECT_NEAR(n->at(1, 1).y, 2.0 / std::sqrt(5.0), 1e-6) << s;
    }
}

TEST(NormalMapTest, RejectsBadInput) {
    auto expectInvalid = [](const Result<NormalImage>& r, const std::string& field) {
        ASSERT_FALSE(r.ok()) << field;
        EXPECT_EQ(r.error().code, ErrorCode::InvalidArgument);
        EXPECT_EQ(r.error().field, field);
        EXPECT_NE(r.error().message.find("dermis::normalMapFromBump"), std::string::npos)
            << r.error().message;
    };
    expectInvalid(normalMapFromBump(HeightImage(), 1.0), "bump");
    expectInvalid(normalMapFromBump(HeightImage(0, 4), 1.0), "bump");
    HeightImage inconsistent(3, 3);
    inconsistent.data.pop_back();
    expectInvalid(normalMapFromBump(inconsistent, 1.0), "bump");
    HeightImage ok(2, 2, 0.5f);
    expectInvalid(normalMapFromBump(ok, -0.1), "strength");
    expectInvalid(normalMapFromBump(ok, std::nan("")), "strength");
    expectInvalid(normalMapFromBump(ok, INFINITY), "strength");
    HeightImage nanHeight(2, 2);
    nanHeight.at(1, 1) = std::nanf("");
    expectInvalid(normalMapFromBump(nanHeight, 1.0), "bump.data[3]");
    EXPECT_TRUE(normalMapFromBump(ok, 0.0).ok());
}

TEST(NormalMapTest, EncodesAsHalfPlusHalf) {
    NormalImage n;
    n.width = 2;
    n.height = 2;
    n.data = {{0, 0, 1}, {-1, 0, 0}, {0.6f, -1.0f, 0.0f}, {2.0f, std::nanf(""), -3.0f}};
    Image8 img = encodeNormalMap8(n);
    ASSERT_EQ(img.width, 2);
    ASSERT_EQ(img.height, 2);
    const std::vector<std::uint8_t> want = {
        128, 128, 255, 255, // flat
        0,   128, 128, 255, // −u
        204, 0,   128, 255, // 0.8·255 = 204, −1 → 0
        255, 128, 0,   255, // clamped, NaN → 128, clamped
    };
    EXPECT_EQ(img.rgba, want);
    NormalImage bad;
    bad.width = 2;
    bad.height = 1;
    bad.data.resize(1);
    Image8 empty = encodeNormalMap8(bad);
    EXPECT_EQ(empty.width, 0);
    EXPECT_EQ(empty.height, 0);
    EXPECT_TRUE(empty.rgba.empty());
}

TEST(NormalMapTest, EncodedRampMatchesItsNormals) {
    // End to end: a ramp towards +u gives red < 128, green 128, blue just under 255.
    auto n = normalMapFromBump(fromFunction(4, 4, [](int i, int) { return 0.5 * i; }), 1.0);
    ASSERT_TRUE(n.ok());
    Image8 img = encodeNormalMap8(*n);
    ASSERT_EQ(img.rgba.size(), 64u);
    // (−0.5, 0, 1)/√1.25 = (−0.4472, 0, 0.8944) → (70.48, 127.5, 241.5) → 70, 128, 242.
    for (std::size_t k = 0; k < 16; ++k) {
        EXPECT_EQ(img.rgba[k * 4 + 0], 70);
        EXPECT_EQ(img.rgba[k * 4 + 1], 128);
        EXPECT_EQ(img.rgba[k * 4 + 2], 242);
        EXPECT_EQ(img.rgba[k * 4 + 3], 255);
    }
}
