// The built-in pattern library (SPEC §3): the committed manifest and images in patterns/, their
// shapes per kind (wrinkles, bulges, bones), and that the generator reproduces them bit for bit.
// Runs the generator (dermis-patterngen) as a subprocess.
#include "BuildPaths.hpp"
#include "TestFiles.hpp"

#include "core/deform.hpp"
#include "core/heightmap.hpp"
#include "core/scene.hpp"
#include "io/image_io.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace dermis {
namespace {

namespace fs = std::filesystem;

const std::string kLibraryDir = std::string(dermis::build::sourceDir()) + "/patterns";
constexpr float kLsb = 1.0f / 32767.0f; // one step of the 16-bit mapping

PatternManifest loadManifest() {
    std::ifstream in(kLibraryDir + "/manifest.json");
    EXPECT_TRUE(in) << "missing " << kLibraryDir << "/manifest.json";
    nlohmann::json doc = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
    EXPECT_FALSE(doc.is_discarded()) << "manifest.json is not JSON";
    EXPECT_EQ(doc.value("format", ""), "dermis.patterns/1");
    auto m = parsePatternManifest(doc);
    EXPECT_TRUE(m.ok()) << (m.ok() ? "" : m.error().message);
    return m.ok() ? m.value() : PatternManifest{};
}

HeightImage loadPattern(const PatternInfo& p) {
    auto img = readHeightImage(kLibraryDir + "/" + p.file);
    EXPECT_TRUE(img.ok()) << p.id << ": " << (img.ok() ? "" : img.error().message);
    return img.ok() ? img.value() : HeightImage{};
}

/// Connected components (8-neighbourhood) of texels where `inside` holds; each is a list of
/// texel indices. Components smaller than `minSize` texels are dropped.
template <class Pred>
std::vector<std::vector<int>> components(const HeightImage& img, Pred inside, int minSize = 20) {
    const int w = img.width, h = img.height;
    std::vector<char> seen(img.data.size(), 0);
    std::vector<std::vector<int>> out;
    for (int start = 0; start < w * h; ++start) {
        if (seen[start] || !inside(img.data[start])) continue;
        std::vector<int> comp, stack{start};
        seen[start] = 1;
        while (!stack.empty()) {
            int k = stack.back();
            stack.pop_back();
            comp.push_back(k);
            int i = k % w, j = k / w;
            for (int dj = -1; dj <= 1; ++dj)
                for (int di = -1; di <= 1; ++di) {
                    int ii = i + di, jj = j + dj;
                    if (ii < 0 || jj < 0 || ii >= w || jj >= h) continue;
                    int kk = jj * w + ii;
                    if (!seen[kk] && inside(img.data[kk])) {
                        seen[kk] = 1;
                        stack.push_back(kk);
                    }
                }
        }
        if (static_cast<int>(comp.size()) >= minSize) out.push_back(std::move(comp));
    }
    return out;
}

/// Unit principal axis (largest spread) of a set of texels.
std::pair<double, double> principalAxis(const std::vector<int>& texels, int w) {
    double mx = 0, my = 0;
    for (int k : texels) mx += k % w, my += k / w;
    mx /= texels.size();
    my /= texels.size();
    double sxx = 0, syy = 0, sxy = 0;
    for (int k : texels) {
        double dx = k % w - mx, dy = k / w - my;
        sxx += dx * dx, syy += dy * dy, sxy += dx * dy;
    }
    double angle = 0.5 * std::atan2(2 * sxy, sxx - syy);
    return {std::cos(angle), std::sin(angle)};
}

/// Length of a set of texels along an axis (max − min of the projections).
double extentAlong(const std::vector<int>& texels, int w, std::pair<double, double> axis) {
    double lo = 1e9, hi = -1e9;
    for (int k : texels) {
        double t = (k % w) * axis.first + (k / w) * axis.second;
        lo = std::min(lo, t), hi = std::max(hi, t);
    }
    return hi - lo;
}

int countAbove(const HeightImage& img, float level) {
    return static_cast<int>(
        std::count_if(img.data.begin(), img.data.end(), [&](float v) { return v > level; }));
}

class PatternLibraryTest : public ::testing::Test {
protected:
    void SetUp() override {
        manifest_ = loadManifest();
        ASSERT_GE(manifest_.patterns.size(), 8u);
    }
    const PatternInfo& get(const std::string& id) {
        const PatternInfo* p = manifest_.find(id);
        EXPECT_NE(p, nullptr) << id;
        return *p;
    }
    PatternManifest manifest_;
};

TEST_F(PatternLibraryTest, ManifestListsThePapersEightPatternsWithKindDefaults) {
    const std::map<std::string, PatternKind> required = {
        {"stomach_wrinkles", PatternKind::Wrinkle}, {"waist_twist", PatternKind::Wrinkle},
        {"crease", PatternKind::Wrinkle},           {"neck_rings", PatternKind::Wrinkle},
        {"round_bulge", PatternKind::Bulge},        {"elongated_bulge", PatternKind::Bulge},
        {"clavicle", PatternKind::Bone},            {"ribs", PatternKind::Bone},
    };
    for (const auto& [id, kind] : required) {
        const PatternInfo* p = manifest_.find(id);
        ASSERT_NE(p, nullptr) << "missing built-in pattern " << id;
        EXPECT_EQ(p->kind, kind) << id;
    }
    std::set<std::string> ids;
    for (const PatternInfo& p : manifest_.patterns) {
        SCOPED_TRACE(p.id);
        EXPECT_TRUE(ids.insert(p.id).second) << "duplicate id";
        EXPECT_EQ(p.file, p.id + ".png");
        EXPECT_EQ(p.model, defaultModel(p.kind));
        EXPECT_EQ(p.target, defaultTarget(p.kind));
        EXPECT_FALSE(p.joint.empty());
        EXPECT_TRUE(p.axis == "x" || p.axis == "y" || p.axis == "z") << p.axis;
        EXPECT_NE(p.thetaMin, p.thetaMax);
        EXPECT_FALSE(p.description.empty());
    }
}

TEST_F(PatternLibraryTest, EveryImageLoadsInRangeAndFadesToZeroAtItsBorder) {
    for (const PatternInfo& p : manifest_.patterns) {
        SCOPED_TRACE(p.id);
        ASSERT_TRUE(fs::is_regular_file(kLibraryDir + "/" + p.file)) << p.file;
        HeightImage img = loadPattern(p);
        ASSERT_EQ(img.width, 512);
        ASSERT_EQ(img.height, 512);
        float lo = 1, hi = -1;
        for (float v : img.data) {
            ASSERT_TRUE(std::isfinite(v));
            lo = std::min(lo, v), hi = std::max(hi, v);
        }
        EXPECT_GE(lo, -1.0f);
        EXPECT_LE(hi, 1.0f);
        EXPECT_GT(hi - lo, 0.5f) << "pattern is (nearly) empty";
        const int n = img.width;
        for (int k = 0; k < n; ++k) {
            EXPECT_LT(std::abs(img.at(k, 0)), 0.01f) << "top row, column " << k;
            EXPECT_LT(std::abs(img.at(k, n - 1)), 0.01f) << "bottom row, column " << k;
            EXPECT_LT(std::abs(img.at(0, k)), 0.01f) << "left column, row " << k;
            EXPECT_LT(std::abs(img.at(n - 1, k)), 0.01f) << "right column, row " << k;
        }
    }
}

TEST_F(PatternLibraryTest, WrinklesAreTaperedGroovesOfUnequalDepthWithLowRidgesBetween) {
    int wrinkles = 0;
    for (const PatternInfo& p : manifest_.patterns) {
        if (p.kind != PatternKind::Wrinkle) continue;
        ++wrinkles;
        SCOPED_TRACE(p.id);
        HeightImage img = loadPattern(p);
        const float lo = *std::min_element(img.data.begin(), img.data.end());
        const float hi = *std::max_element(img.data.begin(), img.data.end());
        EXPECT_LT(lo, -0.95f) << "the deepest groove should reach about −1";
        EXPECT_GT(hi, 0.03f) << "no ridges of compressed skin between the grooves";
        EXPECT_LT(hi, 0.5f * -lo) << "ridges should stay lower than the grooves are deep";

        // Separate grooves, and they are not all alike: depths differ by more than 20%.
        auto grooves = components(img, [](float v) { return v < -0.15f; });
        ASSERT_GE(grooves.size(), 3u);
        std::vector<float> depths;
        for (const auto& g : grooves) {
            float d = 0;
            for (int k : g) d = std::min(d, img.data[k]);
            depths.push_back(-d);
        }
        float dmax = *std::max_element(depths.begin(), depths.end());
        float dmin = *std::min_element(depths.begin(), depths.end());
        EXPECT_LT(dmin, 0.8f * dmax) << "groove depths are too uniform";

        // Tapered ends: the deepest groove's core (below 60% of its depth) is clearly shorter
        // than the groove itself, i.e. the depth falls off toward the ends.
        std::size_t deepest = static_cast<std::size_t>(
            std::max_element(depths.begin(), depths.end()) - depths.begin());
        std::vector<int> core;
        for (int k : grooves[deepest])
            if (img.data[k] < -0.6f * depths[deepest]) core.push_back(k);
        auto axis = principalAxis(grooves[deepest], img.width);
        double full = extentAlong(grooves[deepest], img.width, axis);
        double inner = extentAlong(core, img.width, axis);
        EXPECT_GT(full, 60.0) << "the deepest groove is too short";
        EXPECT_LT(inner, 0.85 * full) << "the deepest groove does not taper toward its ends";
    }
    EXPECT_GE(wrinkles, 4);
}

TEST_F(PatternLibraryTest, BulgesAreSingleSmoothDomesWithoutFlatTopsOrRings) {
    int bulges = 0;
    for (const PatternInfo& p : manifest_.patterns) {
        if (p.kind != PatternKind::Bulge) continue;
        ++bulges;
        SCOPED_TRACE(p.id);
        HeightImage img = loadPattern(p);
        const int n = img.width;
        auto top = std::max_element(img.data.begin(), img.data.end());
        const float peak = *top;
        const int pk = static_cast<int>(top - img.data.begin());
        const int pi = pk % n, pj = pk / n;
        EXPECT_GE(peak, 0.9f);
        EXPECT_LE(peak, 1.0f);
        EXPECT_LT(std::hypot(pi + 0.5 - n / 2.0, pj + 0.5 - n / 2.0), 0.1 * n)
            << "the maximum is not near the centre";
        EXPECT_GE(*std::min_element(img.data.begin(), img.data.end()), -kLsb);

        // No flat top: the region within 5% of the peak is a small part of the dome (about 3%
        // for a Gaussian, a raised cosine or (1 − r²)³; 10% and more for plateau shapes).
        const int dome = countAbove(img, 0.05f * peak), cap = countAbove(img, 0.95f * peak);
        EXPECT_GT(dome, n * n / 10) << "the dome is too small";
        EXPECT_LT(cap, dome / 20) << "flat top";

        // Monotone falloff along rays from the peak (no rings, no second maximum).
        for (int r = 0; r < 64; ++r) {
            const double a = 2.0 * 3.14159265358979 * r / 64.0;
            float prev = peak;
            for (double t = 1.0; t < n; t += 1.0) {
                double x = pi + 0.5 + t * std::cos(a), y = pj + 0.5 + t * std::sin(a);
                if (x < 0.5 || y < 0.5 || x > n - 0.5 || y > n - 0.5) break;
                float v = sampleBilinear(img, x / n, y / n);
                ASSERT_LE(v, prev + 2 * kLsb) << "rises again along ray " << r << " at " << t;
                prev = std::min(prev, v);
            }
        }
        // Smooth: no texel-to-texel jump larger than a smooth dome of this size has.
        float jump = 0;
        for (int j = 0; j < n; ++j)
            for (int i = 1; i < n; ++i) jump = std::max(jump, std::abs(img.at(i, j) - img.at(i - 1, j)));
        EXPECT_LT(jump, 0.02f);
    }
    EXPECT_GE(bulges, 2);
}

TEST_F(PatternLibraryTest, BulgesAreMirrorSymmetricWhereIntended) {
    HeightImage round = loadPattern(get("round_bulge"));
    HeightImage along = loadPattern(get("elongated_bulge"));
    const int n = round.width;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            ASSERT_NEAR(round.at(i, j), round.at(n - 1 - i, j), kLsb) << i << "," << j;
            ASSERT_NEAR(round.at(i, j), round.at(i, n - 1 - j), kLsb) << i << "," << j;
            ASSERT_NEAR(round.at(i, j), round.at(j, i), kLsb) << i << "," << j;
            ASSERT_NEAR(along.at(i, j), along.at(n - 1 - i, j), kLsb) << i << "," << j;
        }
    // The elongated bulge is longer than it is wide.
    auto extent = [&](bool vertical) {
        int count = 0;
        for (int k = 0; k < n; ++k)
            if ((vertical ? along.at(n / 2, k) : along.at(k, n / 2)) > 0.05f) ++count;
        return count;
    };
    EXPECT_GT(extent(true), 1.4 * extent(false));
}

TEST_F(PatternLibraryTest, BonesHaveACrestAtOneAndRevealMoreAsTheBiasOffsetDrops) {
    int bones = 0;
    for (const PatternInfo& p : manifest_.patterns) {
        if (p.kind != PatternKind::Bone) continue;
        ++bones;
        SCOPED_TRACE(p.id);
        HeightImage img = loadPattern(p);
        const int n = img.width;
        EXPECT_GE(*std::max_element(img.data.begin(), img.data.end()), 0.99f);
        // Non-negative: under the bias model a negative value would only appear at t = 1.
        EXPECT_GE(*std::min_element(img.data.begin(), img.data.end()), -kLsb);
        // The paper's bias model: max(L − offset, 0) shows more of the bone as the offset drops.
        int prev = 0;
        for (float offset : {0.9f, 0.75f, 0.5f, 0.25f, 0.1f}) {
            int area = countAbove(img, offset);
            EXPECT_GT(area, prev + n / 4) << "offset " << offset;
            prev = area;
        }
        EXPECT_LT(countAbove(img, 0.9f), n * n / 50) << "the crest should be narrow";
    }
    EXPECT_GE(bones, 2);

    HeightImage clav = loadPattern(get("clavicle"));
    EXPECT_EQ(components(clav, [](float v) { return v > 0.3f; }).size(), 1u)
        << "the clavicle should be one continuous ridge";

    HeightImage ribs = loadPattern(get("ribs"));
    EXPECT_GE(components(ribs, [](float v) { return v > 0.3f; }).size(), 4u) << "too few ribs";
    // Fading toward the sternum side (left): much less bone there than at the back (right).
    const int n = ribs.width;
    double left = 0, right = 0;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n / 3; ++i) left += ribs.at(i, j), right += ribs.at(n - 1 - i, j);
    EXPECT_LT(left, 0.5 * right);
}

TEST_F(PatternLibraryTest, GeneratorReproducesTheCommittedFilesByteForByte) {
    test::TempDir tmp;
    std::string cmd = std::string("\"") + dermis::build::patterngenExe() + "\" --out \"" +
                      tmp.str() + "\" > \"" + (tmp / "log.txt") + "\" 2>&1";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << test::readBytes(tmp / "log.txt").size();
    fs::remove(tmp / "log.txt");

    std::set<std::string> generated;
    for (const auto& e : fs::directory_iterator(tmp.str())) generated.insert(e.path().filename());
    std::set<std::string> expected = {"manifest.json", "contact-sheet.png"};
    for (const PatternInfo& p : manifest_.patterns) expected.insert(p.file);
    EXPECT_EQ(generated, expected);

    for (const std::string& name : generated) {
        SCOPED_TRACE(name);
        auto committed = test::readBytes(kLibraryDir + "/" + name);
        auto fresh = test::readBytes(tmp / name);
        ASSERT_FALSE(committed.empty()) << "not committed in patterns/ (run the `patterns` target)";
        EXPECT_TRUE(committed == fresh)
            << "differs from the committed file; regenerate with the `patterns` target";
    }
    // The contact sheet is an image too.
    auto sheet = decodeImage8(test::readBytes(kLibraryDir + "/contact-sheet.png"));
    ASSERT_TRUE(sheet.ok());
    EXPECT_GT(sheet->width, 512);
}

TEST_F(PatternLibraryTest, GeneratorHonoursSizeAndRejectsBadArguments) {
    test::TempDir tmp;
    std::string exe = std::string("\"") + dermis::build::patterngenExe() + "\"";
    std::string quiet = " > /dev/null 2>&1";
    ASSERT_EQ(std::system((exe + " --out \"" + tmp.str() + "\" --size 64" + quiet).c_str()), 0);
    for (const PatternInfo& p : manifest_.patterns) {
        SCOPED_TRACE(p.id);
        auto img = readHeightImage(tmp / p.file);
        ASSERT_TRUE(img.ok());
        EXPECT_EQ(img->width, 64);
        EXPECT_EQ(img->height, 64);
        for (int k = 0; k < 64; ++k) {
            EXPECT_LT(std::abs(img->at(k, 0)), 0.01f);
            EXPECT_LT(std::abs(img->at(0, k)), 0.01f);
        }
    }
    EXPECT_NE(std::system((exe + " --out \"" + tmp.str() + "\" --size 5" + quiet).c_str()), 0);
    EXPECT_NE(std::system((exe + " --out \"" + tmp.str() + "\" --size abc" + quiet).c_str()), 0);
    EXPECT_NE(std::system((exe + quiet).c_str()), 0);
}

} // namespace
} // namespace dermis
