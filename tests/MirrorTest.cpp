// MirrorTest — SPEC §6 Mirror by geometry: on the default character (symmetric by construction)
// every left placement of the default pattern set mirrors to within 2 texels (of a 1024² map) of
// its right counterpart's centre, with the right joint; a pose and its mirror image give a twin the
// same t within 1e-4, on the default character and on CesiumMan (Z-up under a root matrix). Also
// the symmetry planes found and the joint-name conventions. No GL, no HTTP.
#include "core/mirror.hpp"
#include "core/bake.hpp"
#include "io/gltf_loader.hpp"
#include "io/scene_files.hpp"

#include <glm/gtc/quaternion.hpp>
#include <gtest/gtest.h>

#include <random>

using namespace dermis;

namespace {

const std::string kSource = DERMIS_SOURCE_DIR;
const std::string kCesium = std::string(DERMIS_SHARED_DIR) + "/models/CesiumMan/CesiumMan.glb";

/// For a random delta Δ of joint j and its mirror image for twin t, θ of p and of its twin.
void expectSameT(const Model& m, const Placement& p, const Placement& twin, int planeAxis,
                 std::mt19937& rng) {
    const int j = m.findJoint(p.joint), t = m.findJoint(twin.joint);
    ASSERT_GE(j, 0);
    ASSERT_GE(t, 0);
    const glm::quat qj = restWorldRotation(m, j), qt = restWorldRotation(m, t); // float, as a pose is
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    for (int k = 0; k < 20; ++k) {
        const glm::vec3 axis = glm::normalize(glm::vec3(u(rng), u(rng), u(rng)) + glm::vec3(1e-3f));
        const glm::quat delta = glm::angleAxis(1.4f * u(rng), axis);
        const glm::quat restJ = m.nodes[static_cast<std::size_t>(j)].rotation;
        const glm::quat restT = m.nodes[static_cast<std::size_t>(t)].rotation;
        const glm::quat deltaT = mirrorDelta(qj, qt, delta, planeAxis);
        const double theta = jointAngle(restJ, restJ * delta, glm::vec3(glm::dvec3(p.axis[0], p.axis[1], p.axis[2])));
        const double thetaT = jointAngle(restT, restT * deltaT,
                                         glm::vec3(glm::dvec3(twin.axis[0], twin.axis[1], twin.axis[2])));
        const double tA = normalizedT(theta, p.thetaMin, p.thetaMax);
        const double tB = normalizedT(thetaT, twin.thetaMin, twin.thetaMax);
        EXPECT_NEAR(tA, tB, 1e-4) << p.id << " θ " << theta << " vs " << thetaT << " axis "
                                  << twin.axis[0] << " " << twin.axis[1] << " " << twin.axis[2];
    }
}

TEST(MirrorTest, JointNamesPairByConvention) {
    auto loaded = loadSceneFile(kSource + "/models/default.scene.json");
    ASSERT_TRUE(loaded);
    const Model& m = loaded->model;
    EXPECT_EQ(mirrorJointName(m, "forearm.l"), "forearm.r");
    EXPECT_EQ(mirrorJointName(m, "forearm.r"), "forearm.l");
    EXPECT_EQ(mirrorJointName(m, "shin.l"), "shin.r");
    EXPECT_EQ(mirrorJointName(m, "spine_02"), "");
    EXPECT_EQ(mirrorJointName(m, "nope.l"), "");
}

TEST(MirrorTest, LeftPlacementsOfTheDefaultSetLandOnTheirRightTwins) {
    auto loaded = loadSceneFile(kSource + "/models/default.scene.json");
    ASSERT_TRUE(loaded) << loaded.error().message;
    const Model& m = loaded->model;
    const SymmetryPlane plane = symmetryPlane(m);
    EXPECT_EQ(plane.axis, 0) << "the default character is symmetric across x";
    EXPECT_LT(plane.error, 0.02f); // mean reflected-vertex to nearest-vertex distance (body ≈ 1.8)
    const UvLookup lookup(m);
    std::mt19937 rng(7);
    int pairs = 0;
    for (const Placement& left : loaded->scene.placements) {
        if (left.id.size() < 2 || left.id.compare(left.id.size() - 2, 2, "_l") != 0) continue;
        const std::string rightId = left.id.substr(0, left.id.size() - 2) + "_r";
        const Placement* right = nullptr;
        for (const Placement& p : loaded->scene.placements)
            if (p.id == rightId) right = &p;
        ASSERT_NE(right, nullptr) << rightId;
        auto twin = mirrorPlacement(left, m, lookup, plane);
        ASSERT_TRUE(twin) << left.id << ": " << twin.error().message;
        const double du = (twin->center[0] - right->center[0]) * 1024.0;
        const double dv = (twin->center[1] - right->center[1]) * 1024.0;
        EXPECT_LE(std::hypot(du, dv), 2.0) << left.id << " → (" << twin->center[0] << ", "
                                           << twin->center[1] << "), " << rightId << " is at ("
                                           << right->center[0] << ", " << right->center[1] << ")";
        EXPECT_EQ(twin->joint, right->joint) << left.id;
        EXPECT_EQ(twin->pattern, left.pattern);
        expectSameT(m, left, *twin, plane.axis, rng);
        ++pairs;
    }
    EXPECT_GE(pairs, 6);
}

TEST(MirrorTest, CesiumManMirrorsAcrossItsOwnPlaneAndKeepsT) {
    auto model = loadGltfFile(kCesium);
    ASSERT_TRUE(model) << model.error().message;
    const SymmetryPlane plane = symmetryPlane(*model);
    const UvLookup lookup(*model);
    std::mt19937 rng(11);
    int mirrored = 0;
    for (int n : model->joints) {
        const std::string name = model->nodes[static_cast<std::size_t>(n)].name;
        if (name.find("_L") == std::string::npos && name.find("_R") == std::string::npos) continue;
        Placement p;
        p.id = name;
        p.pattern = "crease";
        p.joint = name;
        const glm::dvec3 a = glm::normalize(glm::dvec3(0.3, 0.8, -0.52)); // parseScene normalises
        p.axis = {a.x, a.y, a.z};
        p.axisName.clear();
        p.thetaMin = -10;
        p.thetaMax = 70;
        // Any point on the atlas will do for the t check: the centre of some chart.
        p.center = {0.5, 0.5};
        for (double v = 0.05; v < 1.0 && !lookup.find({p.center[0], p.center[1]}); v += 0.05)
            for (double u = 0.05; u < 1.0; u += 0.05)
                if (lookup.find({u, v})) {
                    p.center = {u, v};
                    break;
                }
        auto twin = mirrorPlacement(p, *model, lookup, plane);
        ASSERT_TRUE(twin) << name << ": " << twin.error().message;
        EXPECT_NE(twin->joint, name);
        expectSameT(*model, p, *twin, plane.axis, rng);
        ++mirrored;
    }
    EXPECT_GE(mirrored, 12) << "CesiumMan's paired joints (legs by name, arms by position)";
    EXPECT_EQ(mirrorJointName(*model, "leg_joint_L_3"), "leg_joint_R_3");
}

} // namespace
