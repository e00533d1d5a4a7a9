// The built-in default character (SPEC §4 "Default"): models/default.glb as the loader sees it —
// size, joints, a closed surface, normalised weights, a non-overlapping UV atlas, clips that keep
// the mesh sane, bends that keep volume — and that the generator (dermis-charactergen) rewrites
// the committed files bit for bit and the Khronos glTF validator finds no error in them.
// Runs the generator and `node tests/gltf-validator/validate.mjs` as subprocesses; the validator
// needs `npm ci --prefix tests/gltf-validator` once (node_modules is not committed).
#include "BuildPaths.hpp"
#include "TestFiles.hpp"

#include "core/model.hpp"
#include "core/rig.hpp"
#include "io/gltf_loader.hpp"

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

const std::string kModelDir = std::string(dermis::build::sourceDir()) + "/models";
const std::string kGlb = kModelDir + "/default.glb";
const std::string kCharts = kModelDir + "/default.charts.json";

const std::vector<std::string> kJointNames = {
    "root",         "pelvis",          "spine_01",
    "spine_02",     "spine_03",        "chest",
    "neck_01",      "neck_02",         "head",
    "clavicle.l",   "upper_arm.l",     "upper_arm_twist.l",
    "forearm.l",    "forearm_twist.l", "hand.l",
    "thumb_01.l",   "thumb_02.l",      "thumb_03.l",
    "index_01.l",   "index_02.l",      "index_03.l",
    "fingers_01.l", "fingers_02.l",    "fingers_03.l",
    "thigh.l",      "thigh_twist.l",   "shin.l",
    "shin_twist.l", "foot.l",          "toes.l",
    "clavicle.r",   "upper_arm.r",     "upper_arm_twist.r",
    "forearm.r",    "forearm_twist.r", "hand.r",
    "thumb_01.r",   "thumb_02.r",      "thumb_03.r",
    "index_01.r",   "index_02.r",      "index_03.r",
    "fingers_01.r", "fingers_02.r",    "fingers_03.r",
    "thigh.r",      "thigh_twist.r",   "shin.r",
    "shin_twist.r", "foot.r",          "toes.r"};

const std::vector<std::string> kClipNames = {"elbow_curl", "squat",     "torso_bend", "torso_twist",
                                             "neck_turn",  "arm_raise", "walk"};

class DefaultCharacterTest : public ::testing::Test {
  protected:
    static void SetUpTestSuite() {
        auto loaded = loadGltfFile(kGlb);
        if (loaded) {
            model_ = new Model(std::move(*loaded));
        } else {
            loadError_ = loaded.error().message;
        }
    }
    static void TearDownTestSuite() {
        delete model_;
        model_ = nullptr;
    }
    void SetUp() override {
        ASSERT_NE(model_, nullptr) << "cannot load " << kGlb << ": " << loadError_;
        ASSERT_EQ(model_->parts.size(), 1u) << "the default character is one skinned mesh";
    }
    static const Model& model() { return *model_; }
    static const MeshPart& part() { return model_->parts[0]; }

    /// Skinned positions (and world matrices) of a pose.
    static std::vector<glm::vec3> posed(const LocalPose& pose,
                                        std::vector<glm::mat4>* world = nullptr) {
        auto w = worldMatrices(model(), pose);
        auto s = skin(model(), w);
        if (world) *world = w;
        return s.at(0).positions;
    }

    /// Rest pose with one joint turned by `deg` about its rest-frame axes (x, then y, then z).
    static LocalPose bent(const std::string& joint, double x, double y = 0, double z = 0) {
        LocalPose pose = restPose(model());
        const int j = model().findJoint(joint);
        EXPECT_GE(j, 0) << joint;
        if (j >= 0) {
            auto& q = pose.rotation[static_cast<std::size_t>(j)];
            q = axisAnglesRotation(q, x, y, z);
        }
        return pose;
    }

  private:
    static Model* model_;
    static std::string loadError_;
};

Model* DefaultCharacterTest::model_ = nullptr;
std::string DefaultCharacterTest::loadError_;

glm::vec3 jointPosition(const std::vector<glm::mat4>& world, int node) {
    return glm::vec3(world[static_cast<std::size_t>(node)][3]);
}

/// Extent along `dir` of the mesh's cross-section by the plane (origin, normal), keeping only
/// the section points within `radius` of origin (one limb, not its neighbours).
double sectionExtent(const std::vector<glm::vec3>& p, const std::vector<std::uint32_t>& idx,
                     glm::vec3 origin, glm::vec3 normal, glm::vec3 dir, float radius) {
    double lo = 1e30, hi = -1e30;
    for (std::size_t t = 0; t + 2 < idx.size(); t += 3)
        for (int e = 0; e < 3; ++e) {
            const glm::vec3 a = p[idx[t + static_cast<std::size_t>(e)]],
                            b = p[idx[t + static_cast<std::size_t>((e + 1) % 3)]];
            const float da = glm::dot(a - origin, normal), db = glm::dot(b - origin, normal);
            if ((da < 0) == (db < 0)) continue;
            const glm::vec3 x = a + (b - a) * (da / (da - db));
            if (glm::length(x - origin) > radius) continue;
            const double s = glm::dot(x - origin, dir);
            lo = std::min(lo, s);
            hi = std::max(hi, s);
        }
    return hi > lo ? hi - lo : 0.0;
}

TEST_F(DefaultCharacterTest, SizeOfThePapersTestModel) {
    const std::size_t tris = model().triangleCount();
    EXPECT_GE(tris, 4000u);
    EXPECT_LE(tris, 4600u);
    EXPECT_GE(model().joints.size(), 45u);
    EXPECT_LE(model().joints.size(), 55u);
    EXPECT_TRUE(model().hasUVs());
    EXPECT_EQ(part().normals.size(), part().positions.size());
    EXPECT_EQ(part().influences.size(), model().joints.size());
}

TEST_F(DefaultCharacterTest, JointsHaveTheExpectedNamesAndHierarchy) {
    for (const std::string& name : kJointNames)
        EXPECT_GE(model().findJoint(name), 0) << name;
    EXPECT_EQ(model().joints.size(), kJointNames.size());
    auto parentName = [&](const std::string& child) {
        const int j = model().findJoint(child);
        if (j < 0) return std::string("?");
        const int p = model().nodes[static_cast<std::size_t>(j)].parent;
        return p < 0 ? std::string() : model().nodes[static_cast<std::size_t>(p)].name;
    };
    EXPECT_EQ(parentName("pelvis"), "root");
    EXPECT_EQ(parentName("head"), "neck_02");
    EXPECT_EQ(parentName("forearm.l"), "upper_arm.l");
    EXPECT_EQ(parentName("upper_arm_twist.l"), "upper_arm.l");
    EXPECT_EQ(parentName("hand.r"), "forearm.r");
    EXPECT_EQ(parentName("shin.r"), "thigh.r");
    EXPECT_EQ(parentName("toes.l"), "foot.l");
    EXPECT_EQ(parentName("thumb_01.l"), "hand.l");
}

TEST_F(DefaultCharacterTest, StandsOnTheGroundFacingPlusZWithYUp) {
    glm::vec3 lo(1e9f), hi(-1e9f);
    for (const auto& p : posed(restPose(model()))) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    EXPECT_NEAR(hi.y - lo.y, 1.75f, 0.05f) << "height";
    EXPECT_NEAR(lo.y, 0.0f, 0.01f) << "feet on y = 0";
    EXPECT_NEAR(hi.x, -lo.x, 0.02f) << "left/right symmetric";
    std::vector<glm::mat4> world;
    posed(restPose(model()), &world);
    // Its left hand at +X, toes ahead of the ankles (+Z), head above the pelvis.
    EXPECT_GT(jointPosition(world, model().findJoint("hand.l")).x, 0.3f);
    EXPECT_LT(jointPosition(world, model().findJoint("hand.r")).x, -0.3f);
    EXPECT_GT(jointPosition(world, model().findJoint("toes.l")).z,
              jointPosition(world, model().findJoint("foot.l")).z + 0.1f);
    EXPECT_GT(jointPosition(world, model().findJoint("head")).y, 1.5f);
}

TEST_F(DefaultCharacterTest, SurfaceIsWatertightAfterWeldingSeams) {
    // Weld seam duplicates by position, then every edge must border exactly two triangles,
    // once in each direction (closed, consistently oriented), and the surface is a sphere.
    std::map<std::tuple<float, float, float>, std::uint32_t> weld;
    std::vector<std::uint32_t> id(part().positions.size());
    for (std::size_t v = 0; v < id.size(); ++v) {
        const glm::vec3 p = part().positions[v];
        id[v] =
            weld.emplace(std::make_tuple(p.x, p.y, p.z), static_cast<std::uint32_t>(weld.size()))
                .first->second;
    }
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
    const auto& idx = part().indices;
    for (std::size_t t = 0; t + 2 < idx.size(); t += 3)
        for (int e = 0; e < 3; ++e) {
            const std::uint32_t a = id[idx[t + static_cast<std::size_t>(e)]];
            const std::uint32_t b = id[idx[t + static_cast<std::size_t>((e + 1) % 3)]];
            ASSERT_NE(a, b) << "degenerate triangle " << t / 3;
            ++directed[{a, b}];
        }
    std::size_t bad = 0;
    for (const auto& [e, n] : directed)
        if (n != 1 || !directed.count({e.second, e.first})) ++bad;
    EXPECT_EQ(bad, 0u) << "edges not shared by exactly two consistently oriented triangles";
    const long v = static_cast<long>(weld.size()), e = static_cast<long>(directed.size() / 2),
               f = static_cast<long>(idx.size() / 3);
    EXPECT_EQ(v - e + f, 2) << "Euler characteristic of a closed genus-0 surface";
}

TEST_F(DefaultCharacterTest, WeightsAreNormalisedWithAtMostFourInfluences) {
    ASSERT_EQ(part().weights.size(), part().positions.size());
    ASSERT_EQ(part().joints.size(), part().positions.size());
    std::set<int> used;
    for (std::size_t v = 0; v < part().weights.size(); ++v) {
        const glm::vec4 w = part().weights[v];
        float sum = 0;
        for (int k = 0; k < 4; ++k) {
            ASSERT_GE(w[k], 0.0f) << "vertex " << v;
            ASSERT_LT(part().joints[v][k], part().influences.size()) << "vertex " << v;
            sum += w[k];
            if (w[k] > 0) used.insert(part().joints[v][k]);
        }
        ASSERT_NEAR(sum, 1.0f, 1e-5f) << "vertex " << v;
    }
    // Every deforming joint moves some skin (root is the only joint with no weight).
    EXPECT_GE(used.size(), model().joints.size() - 1);
}

TEST_F(DefaultCharacterTest, UvAtlasIsInsideTheUnitSquareWithoutOverlapOrFlips) {
    const auto& uv = part().uvs;
    for (const auto& t : uv) {
        ASSERT_GE(t.x, 0.0f);
        ASSERT_LE(t.x, 1.0f);
        ASSERT_GE(t.y, 0.0f);
        ASSERT_LE(t.y, 1.0f);
    }
    // Every UV triangle has the same orientation (none is flipped) and a non-zero area.
    const auto& idx = part().indices;
    int positive = 0, negative = 0, degenerate = 0;
    for (std::size_t t = 0; t + 2 < idx.size(); t += 3) {
        const glm::dvec2 a(uv[idx[t]]), b(uv[idx[t + 1]]), c(uv[idx[t + 2]]);
        const double area = 0.5 * ((b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y));
        if (area > 1e-12)
            ++positive;
        else if (area < -1e-12)
            ++negative;
        else
            ++degenerate;
    }
    EXPECT_EQ(degenerate, 0);
    EXPECT_TRUE(positive == 0 || negative == 0)
        << positive << " triangles one way, " << negative << " the other";
    // Rasterize at 2048²: no texel centre lies strictly inside two triangles.
    const int n = 2048;
    std::vector<std::uint8_t> cover(static_cast<std::size_t>(n) * n, 0);
    std::size_t overlaps = 0, covered = 0;
    for (std::size_t t = 0; t + 2 < idx.size(); t += 3) {
        const glm::dvec2 a = glm::dvec2(uv[idx[t]]) * double(n),
                         b = glm::dvec2(uv[idx[t + 1]]) * double(n),
                         c = glm::dvec2(uv[idx[t + 2]]) * double(n);
        const double area = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
        const int x0 = std::max(0, int(std::floor(std::min({a.x, b.x, c.x})))),
                  x1 = std::min(n - 1, int(std::ceil(std::max({a.x, b.x, c.x})))),
                  y0 = std::max(0, int(std::floor(std::min({a.y, b.y, c.y})))),
                  y1 = std::min(n - 1, int(std::ceil(std::max({a.y, b.y, c.y}))));
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x) {
                const glm::dvec2 p(x + 0.5, y + 0.5);
                const double w0 = ((b.x - p.x) * (c.y - p.y) - (c.x - p.x) * (b.y - p.y)) / area;
                const double w1 = ((c.x - p.x) * (a.y - p.y) - (a.x - p.x) * (c.y - p.y)) / area;
                const double w2 = 1.0 - w0 - w1;
                if (!(w0 > 1e-9 && w1 > 1e-9 && w2 > 1e-9)) continue;
                auto& cell = cover[static_cast<std::size_t>(y) * n + static_cast<std::size_t>(x)];
                if (cell) ++overlaps;
                cell = 1;
                ++covered;
            }
    }
    EXPECT_EQ(overlaps, 0u) << "texel centres covered by two UV triangles";
    EXPECT_GT(static_cast<double>(covered) / (double(n) * n), 0.4) << "atlas fill";
}

TEST_F(DefaultCharacterTest, ChartsSidecarDescribesTheAtlas) {
    std::ifstream in(kCharts);
    ASSERT_TRUE(in) << "missing " << kCharts;
    const nlohmann::json doc = nlohmann::json::parse(in, nullptr, false);
    ASSERT_FALSE(doc.is_discarded()) << kCharts << " is not JSON";
    EXPECT_EQ(doc.value("format", ""), "dermis.charts/1");
    ASSERT_TRUE(doc.contains("charts") && doc["charts"].is_array());
    std::map<std::string, std::array<double, 4>> charts;
    for (const auto& c : doc["charts"]) {
        const auto b = c.at("bounds").get<std::vector<double>>();
        ASSERT_EQ(b.size(), 4u);
        EXPECT_LT(b[0], b[2]);
        EXPECT_LT(b[1], b[3]);
        EXPECT_GE(b[0], 0.0);
        EXPECT_LE(b[3], 1.0);
        charts[c.at("name").get<std::string>()] = {b[0], b[1], b[2], b[3]};
    }
    for (const char* name : {"torso", "face", "head_back", "arm.l", "arm.r", "leg.l", "leg.r"})
        EXPECT_TRUE(charts.count(name)) << name;
    // Chart boxes are disjoint and every UV lies in one of them.
    for (auto a = charts.begin(); a != charts.end(); ++a)
        for (auto b = std::next(a); b != charts.end(); ++b) {
            const auto &A = a->second, &B = b->second;
            EXPECT_FALSE(A[0] < B[2] && B[0] < A[2] && A[1] < B[3] && B[1] < A[3])
                << a->first << " and " << b->first << " overlap";
        }
    for (const auto& uv : part().uvs) {
        int inside = 0;
        for (const auto& [name, b] : charts)
            if (uv.x >= b[0] - 1e-4 && uv.x <= b[2] + 1e-4 && uv.y >= b[1] - 1e-4 &&
                uv.y <= b[3] + 1e-4)
                ++inside;
        ASSERT_EQ(inside, 1) << "uv (" << uv.x << ", " << uv.y << ")";
    }
    // Pattern sites get room: the torso chart holds a 0.25 × 0.25 square, arms and legs long
    // strips.
    const auto size = [&](const std::string& n) {
        const auto& b = charts.at(n);
        return glm::dvec2(b[2] - b[0], b[3] - b[1]);
    };
    EXPECT_GT(size("torso").x, 0.25);
    EXPECT_GT(size("torso").y, 0.25);
    EXPECT_GT(std::max(size("arm.l").x, size("arm.l").y), 0.2);
    EXPECT_GT(std::max(size("leg.l").x, size("leg.l").y), 0.3);
    // Landmarks name real joints and lie inside their chart.
    ASSERT_TRUE(doc.contains("landmarks"));
    for (const auto& l : doc["landmarks"]) {
        const std::string chart = l.at("chart").get<std::string>();
        ASSERT_TRUE(charts.count(chart)) << l.dump();
        const auto uv = l.at("uv").get<std::vector<double>>();
        const auto& b = charts.at(chart);
        EXPECT_TRUE(uv[0] >= b[0] && uv[0] <= b[2] && uv[1] >= b[1] && uv[1] <= b[3]) << l.dump();
        EXPECT_GE(model().findJoint(l.at("joint").get<std::string>()), 0) << l.dump();
    }
}

TEST_F(DefaultCharacterTest, ClipsArePresentAndKeepTheMeshSane) {
    const auto rest = posed(restPose(model()));
    const auto& idx = part().indices;
    for (const std::string& name : kClipNames) {
        SCOPED_TRACE(name);
        const int c = model().findClip(name);
        ASSERT_GE(c, 0) << "missing clip " << name;
        const Clip& clip = model().clips[static_cast<std::size_t>(c)];
        EXPECT_GE(clip.duration, 1.0f);
        EXPECT_LE(clip.duration, 3.0f);
        int rotations = 0;
        std::set<float> keyTimes;
        for (const Channel& ch : clip.channels) {
            EXPECT_EQ(ch.interpolation, Interpolation::Linear);
            if (ch.path == ChannelPath::Rotation) ++rotations;
            keyTimes.insert(ch.times.begin(), ch.times.end());
        }
        EXPECT_GT(rotations, 0);
        for (float time : keyTimes) {
            const auto p = posed(sampleClip(model(), c, time));
            glm::vec3 lo(1e9f), hi(-1e9f);
            for (const auto& v : p) {
                ASSERT_TRUE(std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z))
                    << "t = " << time;
                lo = glm::min(lo, v);
                hi = glm::max(hi, v);
            }
            EXPECT_GT(lo.y, -0.05f) << "below the floor at t = " << time;
            EXPECT_LT(hi.y, 2.4f) << "t = " << time;
            EXPECT_LT(glm::length(hi - lo), 3.0f) << "t = " << time;
            double most = 0;
            for (std::size_t t = 0; t + 2 < idx.size(); t += 3)
                for (int e = 0; e < 3; ++e) {
                    const std::uint32_t a = idx[t + static_cast<std::size_t>(e)],
                                        b = idx[t + static_cast<std::size_t>((e + 1) % 3)];
                    const double r = glm::length(p[a] - p[b]) / glm::length(rest[a] - rest[b]);
                    most = std::max(most, r);
                }
            // Deep bends fold the inner skin (a crease compresses edges toward zero), so only
            // stretching is bounded: a wrong weight would tear the surface into long spikes.
            EXPECT_LT(most, 4.0) << "t = " << time;
        }
    }
}

/// Thickness across the bend of a limb bent 90° at `joint` (bisector plane through the joint,
/// measured in the bending plane) relative to the straight limb's thickness at rest.
double bendThicknessRatio(const Model& m, const std::vector<glm::vec3>& rest,
                          const std::vector<glm::mat4>& restWorld,
                          const std::vector<glm::vec3>& bentPos,
                          const std::vector<glm::mat4>& bentWorld, const std::string& joint,
                          const std::string& parentJoint, const std::string& childJoint) {
    const int j = m.findJoint(joint), pj = m.findJoint(parentJoint), cj = m.findJoint(childJoint);
    const auto& idx = m.parts[0].indices;
    // Rest: plane across the limb at the joint; thickness along the bend direction.
    const glm::vec3 r0 = jointPosition(restWorld, pj), r1 = jointPosition(restWorld, j),
                    r2 = jointPosition(restWorld, cj);
    const glm::vec3 axisRest = glm::normalize(r2 - r0);
    const glm::vec3 b0 = jointPosition(bentWorld, pj), b1 = jointPosition(bentWorld, j),
                    b2 = jointPosition(bentWorld, cj);
    const glm::vec3 dIn = glm::normalize(b1 - b0), dOut = glm::normalize(b2 - b1);
    const glm::vec3 bisector = glm::normalize(dIn + dOut);
    const glm::vec3 across = glm::normalize(dOut - dIn); // in the bending plane, ⊥ bisector
    // At rest, the same anatomical direction: across the limb, in the bending plane.
    const glm::vec3 bendAxis = glm::normalize(glm::cross(dIn, dOut));
    const glm::vec3 restDir = glm::normalize(glm::cross(bendAxis, axisRest));
    const double restT = sectionExtent(rest, idx, r1, axisRest, restDir, 0.1f);
    const double bentT = sectionExtent(bentPos, idx, b1, bisector, across, 0.1f);
    return restT > 0 ? bentT / restT : 0.0;
}

TEST_F(DefaultCharacterTest, NinetyDegreeElbowAndKneeBendsKeepVolume) {
    std::vector<glm::mat4> restWorld;
    const auto rest = posed(restPose(model()), &restWorld);
    struct Case {
        const char* joint;
        const char* parent;
        const char* child;
    };
    for (const Case& c :
         {Case{"forearm.l", "upper_arm.l", "hand.l"}, Case{"forearm.r", "upper_arm.r", "hand.r"},
          Case{"shin.l", "thigh.l", "foot.l"}, Case{"shin.r", "thigh.r", "foot.r"}}) {
        SCOPED_TRACE(c.joint);
        std::vector<glm::mat4> world;
        const auto p = posed(bent(c.joint, 90.0), &world);
        // The bend really adds 90° to the rest angle between the two bones.
        auto angle = [&](const std::vector<glm::mat4>& w) {
            const glm::vec3 a = jointPosition(w, model().findJoint(c.parent)),
                            j = jointPosition(w, model().findJoint(c.joint)),
                            b = jointPosition(w, model().findJoint(c.child));
            return glm::degrees(std::acos(glm::dot(glm::normalize(j - a), glm::normalize(b - j))));
        };
        EXPECT_NEAR(angle(world) - angle(restWorld), 90.0, 1.0);
        const double ratio =
            bendThicknessRatio(model(), rest, restWorld, p, world, c.joint, c.parent, c.child);
        std::printf("%s: thickness across the 90° bend / rest thickness = %.2f\n", c.joint, ratio);
        EXPECT_GT(ratio, 0.5) << "the joint collapses at a 90° bend";
        EXPECT_LT(ratio, 2.0) << "the joint balloons at a 90° bend";
    }
}

TEST_F(DefaultCharacterTest, ForearmTwistAvoidsCandyWrapper) {
    // Hand turned 90° about the forearm axis with the twist joint carrying half: the forearm's
    // cross-section near the wrist keeps most of its rest extent.
    std::vector<glm::mat4> restWorld, world;
    const auto rest = posed(restPose(model()), &restWorld);
    LocalPose pose = bent("hand.l", 0, 90.0);
    const int tw = model().findJoint("forearm_twist.l");
    pose.rotation[static_cast<std::size_t>(tw)] =
        axisAnglesRotation(pose.rotation[static_cast<std::size_t>(tw)], 0, 45.0, 0);
    const auto p = posed(pose, &world);
    const glm::vec3 elbow = jointPosition(restWorld, model().findJoint("forearm.l"));
    const glm::vec3 wrist = jointPosition(restWorld, model().findJoint("hand.l"));
    const glm::vec3 axis = glm::normalize(wrist - elbow);
    const glm::vec3 o = glm::mix(elbow, wrist, 0.8f);
    const glm::vec3 side = glm::normalize(glm::cross(axis, glm::vec3(0, 0, 1)));
    for (const glm::vec3 dir : {glm::vec3(0, 0, 1), side}) {
        const double restT = sectionExtent(rest, part().indices, o, axis, dir, 0.08f);
        double bentMax = 0;
        // The section turns with the twist: take the largest extent over directions.
        for (int k = 0; k < 36; ++k) {
            const float a = glm::radians(5.0f * static_cast<float>(k));
            const glm::vec3 d = std::cos(a) * glm::vec3(0, 0, 1) + std::sin(a) * side;
            bentMax = std::max(bentMax, sectionExtent(p, part().indices, o, axis, d, 0.08f));
        }
        EXPECT_GT(bentMax, 0.5 * restT);
    }
}

TEST_F(DefaultCharacterTest, GeneratorReproducesTheCommittedFiles) {
    test::TempDir dir;
    const std::string cmd = std::string("\"") + dermis::build::charactergenExe() +
                            "\" --quiet --out \"" + dir.str() + "\"";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    for (const char* name : {"default.glb", "default.charts.json"}) {
        const auto fresh = test::readBytes(dir / name);
        const auto committed = test::readBytes(kModelDir + "/" + name);
        ASSERT_FALSE(fresh.empty()) << name;
        EXPECT_TRUE(fresh == committed)
            << name
            << " differs from the committed file; run `cmake --build <dir> --target character`";
    }
}

TEST_F(DefaultCharacterTest, KhronosValidatorReportsNoErrors) {
    const std::string validatorDir =
        std::string(dermis::build::sourceDir()) + "/tests/gltf-validator";
    ASSERT_TRUE(fs::exists(validatorDir + "/node_modules/gltf-validator"))
        << "the Khronos glTF validator is not installed: run `npm ci --prefix " << validatorDir
        << "`";
    test::TempDir dir;
    const std::string report = dir / "report.txt";
    const std::string cmd =
        "node \"" + validatorDir + "/validate.mjs\" \"" + kGlb + "\" > \"" + report + "\" 2>&1";
    const int rc = std::system(cmd.c_str());
    std::ifstream in(report);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_EQ(rc, 0) << "validator failed (is node installed?):\n" << text;
    EXPECT_NE(text.find("errors 0,"), std::string::npos) << text;
}

TEST_F(DefaultCharacterTest, ClipsStayWithinPlausibleJointRanges) {
    // Anatomical limits (degrees) about each joint's local axes (x bend, y twist, z side), in the
    // joint frames of the generator: flexion is +x on both sides. Joints not listed: ±90°.
    struct Limit {
        const char* prefix;
        double x0, x1, y, z;
    };
    const Limit limits[] = {
        {"forearm.", -5, 150, 90, 10},     {"shin.", -5, 150, 10, 10},
        {"thigh.", -40, 130, 45, 60},      {"spine_", -35, 45, 45, 35},
        {"chest", -35, 45, 45, 35},        {"neck_", -60, 60, 80, 45},
        {"upper_arm.", -90, 180, 90, 180}, {"clavicle.", -30, 30, 30, 45},
    };
    for (const Clip& clip : model().clips) {
        const int c = model().findClip(clip.name);
        std::set<float> keyTimes;
        for (const Channel& ch : clip.channels)
            keyTimes.insert(ch.times.begin(), ch.times.end());
        for (float t : keyTimes) {
            const LocalPose pose = sampleClip(model(), c, t);
            for (int j : model().joints) {
                const Node& n = model().nodes[static_cast<std::size_t>(j)];
                double x0 = -90, x1 = 90, y = 90, z = 90;
                for (const Limit& l : limits)
                    if (n.name.rfind(l.prefix, 0) == 0) x0 = l.x0, x1 = l.x1, y = l.y, z = l.z;
                const glm::quat q = pose.rotation[static_cast<std::size_t>(j)];
                const double ax = jointAngle(n.rotation, q, {1, 0, 0});
                const double ay = jointAngle(n.rotation, q, {0, 1, 0});
                const double az = jointAngle(n.rotation, q, {0, 0, 1});
                EXPECT_TRUE(ax >= x0 && ax <= x1)
                    << clip.name << " t=" << t << " " << n.name << " x=" << ax;
                EXPECT_LE(std::abs(ay), y) << clip.name << " t=" << t << " " << n.name;
                EXPECT_LE(std::abs(az), z) << clip.name << " t=" << t << " " << n.name;
            }
        }
    }
}

} // namespace
} // namespace dermis
