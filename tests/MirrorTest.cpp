// MirrorTest — SPEC §6 Mirror by geometry: on the default character (symmetric by construction)
// every left placement of the default pattern set mirrors to within 2 texels (of a 1024² map) of
// its right counterpart's centre, with the right joint; a pose and its mirror image give a twin the
// same t within 1e-4, on the default character and on CesiumMan (Z-up under a root matrix). Also
// the symmetry planes found and the joint-name conventions. The twin's id and label swap their
// side tokens, its axis is written rounded (on the default character, CesiumMan and the KayKit
// Barbarian), and a twin already in the scene is found (the route's 409). No GL, no HTTP.
#include "core/mirror.hpp"
#include "BuildPaths.hpp"
#include "core/bake.hpp"
#include "io/gltf_loader.hpp"
#include "io/scene_files.hpp"

#include <glm/gtc/quaternion.hpp>
#include <gtest/gtest.h>

#include <random>

using namespace dermis;

namespace {

const std::string kSource = dermis::build::sourceDir();
const std::string kCesium =
    std::string(dermis::build::testModelsDir()) + "/CesiumMan/CesiumMan.glb";
const std::string kBarbarian =
    std::string(dermis::build::testModelsDir()) + "/KayKitBarbarian/Barbarian.glb";

/// A point of `lookup`'s atlas: the first chart hit on a 0.05 grid.
std::array<double, 2> somewhereOnTheAtlas(const UvLookup& lookup) {
    for (double v = 0.05; v < 1.0; v += 0.05)
        for (double u = 0.05; u < 1.0; u += 0.05)
            if (lookup.find({u, v})) return {u, v};
    return {0.5, 0.5};
}

/// Each component 0 exactly or a multiple of 1e-6 at least 1e-6 from 0.
void expectRoundedAxis(const Placement& twin, const std::string& what) {
    for (double c : twin.axis) {
        EXPECT_TRUE(c == 0.0 || std::abs(c) >= 1e-6) << what << ": " << c;
        EXPECT_NEAR(c * 1e6, std::round(c * 1e6), 1e-6) << what << ": " << c;
    }
}

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
        expectRoundedAxis(*twin, left.id);
        EXPECT_EQ(mirrorPlacementId(left.id, twin->joint), rightId);
        // The right counterpart is the twin already there (the route answers 409 naming it).
        const int found = findMirrorTwin(loaded->scene, *twin);
        ASSERT_GE(found, 0) << left.id;
        EXPECT_EQ(loaded->scene.placements[static_cast<std::size_t>(found)].id, rightId);
        Placement moved = *twin;
        moved.center[0] += 10.0 / loaded->scene.heightmapSize[0]; // 10 texels away: no twin
        EXPECT_EQ(findMirrorTwin(loaded->scene, moved), -1) << left.id;
        Placement other = *twin;
        other.target = other.target == Target::Bump ? Target::Displacement : Target::Bump;
        EXPECT_EQ(findMirrorTwin(loaded->scene, other), -1) << left.id;
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
        expectRoundedAxis(*twin, name);
        EXPECT_EQ(mirrorPlacementId(p.id, twin->joint), *swapSides(name)) << name;
        ++mirrored;
    }
    EXPECT_GE(mirrored, 12) << "CesiumMan's paired joints (legs by name, arms by position)";
    EXPECT_EQ(mirrorJointName(*model, "leg_joint_L_3"), "leg_joint_R_3");
}

TEST(MirrorTest, BarbarianTwinsAreNamedRoundedAndFoundAgain) {
    auto model = loadGltfFile(kBarbarian);
    ASSERT_TRUE(model) << model.error().message;
    const SymmetryPlane plane = symmetryPlane(*model);
    const UvLookup lookup(*model);
    std::mt19937 rng(13);
    Scene scene;
    scene.model = "barbarian";
    int mirrored = 0;
    for (const char* joint : {"upperarm.l", "lowerarm.l", "upperleg.l", "lowerleg.l", "foot.r"}) {
        Placement p;
        p.id = std::string(joint) == "foot.r" ? "Foot.R" : std::string("bulge_") + joint;
        p.label = std::string(joint) == "foot.r" ? "Right foot" : "left arm or leg";
        p.pattern = "round_bulge";
        p.joint = joint;
        p.axis = {0.0, 0.0, 1.0}; // z: mirrors to −z on this rig (up to float noise)
        p.axisName = "z";
        p.center = somewhereOnTheAtlas(lookup);
        auto twin = mirrorPlacement(p, *model, lookup, plane);
        ASSERT_TRUE(twin) << joint << ": " << twin.error().message;
        EXPECT_EQ(twin->joint, mirrorJointName(*model, joint));
        expectSameT(*model, p, *twin, plane.axis, rng);
        expectRoundedAxis(*twin, joint);
        EXPECT_EQ(twin->label, *swapSides(p.label)) << joint;
        const std::string id = mirrorPlacementId(p.id, twin->joint);
        EXPECT_EQ(id, *swapSides(p.id)) << joint;
        // Put the twin in the scene: mirroring the same placement again finds it.
        scene.placements = {p, *twin};
        scene.placements[1].id = id;
        EXPECT_EQ(findMirrorTwin(scene, *twin), 1) << joint;
        ++mirrored;
    }
    EXPECT_EQ(mirrored, 5);
}

TEST(MirrorTest, SideTokensSwapInIdsAndLabels) {
    const std::pair<const char*, const char*> swaps[] = {
        {"elbow_l", "elbow_r"},       {"elbow_L", "elbow_R"},         {"forearm.l", "forearm.r"},
        {"Knee.R", "Knee.L"},         {"Left", "Right"},              {"right", "left"},
        {"LeftArm", "RightArm"},      {"ArmLeft", "ArmRight"},        {"mixamorig:LeftHand", "mixamorig:RightHand"},
        {"LEFT_ARM", "RIGHT_ARM"},    {"L_arm", "R_arm"},             {"leg_joint_L_1", "leg_joint_R_1"},
        {"elbow L", "elbow R"},       {"elbow (L)", "elbow (R)"},     {"left knee, L", "right knee, R"},
        {"left_to_right", "right_to_left"}, {"l", "r"},               {"biceps-l", "biceps-r"},
    };
    for (auto [from, to] : swaps) {
        const auto swapped = swapSides(from);
        ASSERT_TRUE(swapped) << from;
        EXPECT_EQ(*swapped, to) << from;
        EXPECT_EQ(*swapSides(to), from) << to;
    }
    for (const char* none : {"stomach", "p0", "cleft", "Leftover", "roll", "R&D", "l'arm", "elbowL", "spine_02", ""})
        EXPECT_FALSE(swapSides(none)) << none;
    EXPECT_EQ(sideOf("forearm.r"), 'r');
    EXPECT_EQ(sideOf("mixamorig:LeftArm"), 'l');
    EXPECT_EQ(sideOf("spine_02"), 0);

    // Ids: sides swapped, else the twin joint's side, else "_twin".
    EXPECT_EQ(mirrorPlacementId("elbow_l", "forearm.r"), "elbow_r");
    EXPECT_EQ(mirrorPlacementId("Elbow.L", "forearm.r"), "Elbow.R");
    EXPECT_EQ(mirrorPlacementId("p0", "forearm.r"), "p0_r");
    EXPECT_EQ(mirrorPlacementId("p0", "mixamorig:LeftArm"), "p0_l");
    EXPECT_EQ(mirrorPlacementId("stomach", "spine_02"), "stomach_twin");

    // Labels: side words swapped, else " (mirror)"; never over the label limit.
    EXPECT_EQ(mirrorLabel("elbow L"), "elbow R");
    EXPECT_EQ(mirrorLabel("Left biceps"), "Right biceps");
    EXPECT_EQ(mirrorLabel("crease (l)"), "crease (r)");
    EXPECT_EQ(mirrorLabel("stomach"), "stomach (mirror)");
    EXPECT_EQ(mirrorLabel(""), "");
    const std::string longLabel(kMaxLabelLength, 'x');
    EXPECT_EQ(mirrorLabel(longLabel), std::string(kMaxLabelLength - 9, 'x') + " (mirror)");
    std::string accents;
    for (std::size_t k = 0; k < kMaxLabelLength / 2; ++k) accents += "\xc3\xa9"; // é: 2 bytes each
    const std::string cut = mirrorLabel(accents);
    EXPECT_LE(cut.size(), kMaxLabelLength);
    EXPECT_EQ(cut.substr(cut.size() - 9), " (mirror)");
    EXPECT_EQ((cut.size() - 9) % 2, 0u) << "cut at a character boundary";
}

} // namespace
