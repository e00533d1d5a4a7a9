// ProposeTest — SPEC §8 proposals and transfer in the core: joint roles across naming
// conventions (body_map), principal strains (motion), and on the real characters — CesiumMan,
// the KayKit Barbarian, RiggedFigure (whose clip moves no elbow or knee: synthetic bends) and the
// default character — a crease at each elbow and knee on the flexion side, driven by that joint,
// fully on where the clips bend it most and off at the rest pose, twins that are mirror images,
// deterministic; the default set transferred onto CesiumMan and the Barbarian lands on the
// matching body parts. No GL, no HTTP.
#include "core/propose.hpp"
#include "BuildPaths.hpp"
#include "core/body_map.hpp"
#include "core/deform.hpp"
#include "core/model_derived.hpp"
#include "core/motion.hpp"
#include "core/surface_query.hpp"
#include "core/transfer.hpp"
#include "io/gltf_loader.hpp"
#include "io/scene_files.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>

using namespace dermis;

namespace {

const std::string kSource = dermis::build::sourceDir();
const std::string kModels = std::string(dermis::build::testModelsDir()) + "/";

std::shared_ptr<const Model> load(const std::string& path) {
    auto m = loadGltfFile(path);
    EXPECT_TRUE(m) << path << ": " << (m ? "" : m.error().message);
    return m ? std::make_shared<const Model>(std::move(*m)) : nullptr;
}

const std::vector<std::string>& characters() {
    static const std::vector<std::string> paths = {
        kSource + "/models/default.glb", kModels + "CesiumMan/CesiumMan.glb",
        kModels + "KayKitBarbarian/Barbarian.glb", kModels + "RiggedFigure/RiggedFigure.glb"};
    return paths;
}

/// The anchor of surface placement `p` in rest world space.
glm::dvec3 anchorWorld(const Model& m, const RestSkin& rest, const Placement& p) {
    const glm::dvec3 c(p.anchor.position[0], p.anchor.position[1], p.anchor.position[2]);
    const auto at = nearestSurfacePoint(m, bindPositions(m), c);
    EXPECT_TRUE(at);
    return at ? glm::dvec3(restSkinningAt(m, rest, *at) * glm::dvec4(c, 1.0)) : c;
}

double thetaOf(const Model& m, const LocalPose& pose, int node, const Placement& p) {
    return jointAngle(m.nodes[static_cast<std::size_t>(node)].rotation, pose.rotation[static_cast<std::size_t>(node)],
                      glm::normalize(glm::vec3(p.axis[0], p.axis[1], p.axis[2])));
}

TEST(ProposeTest, RolesFromNamesAcrossConventions) {
    const std::pair<const char*, JointRole> cases[] = {
        {"mixamorig:LeftForeArm", JointRole::Elbow}, {"lowerarm_l", JointRole::Elbow},
        {"forearm.L", JointRole::Elbow},             {"CC_Base_L_Forearm", JointRole::Elbow},
        {"leftLowerArm", JointRole::Elbow},          {"mixamorig:LeftArm", JointRole::Shoulder},
        {"upperarm_r", JointRole::Shoulder},         {"upper_arm.R", JointRole::Shoulder},
        {"LeftShoulder", JointRole::Clavicle},       {"clavicle_l", JointRole::Clavicle},
        {"mixamorig:LeftUpLeg", JointRole::Hip},     {"thigh.L", JointRole::Hip},
        {"leftUpperLeg", JointRole::Hip},            {"mixamorig:LeftLeg", JointRole::Knee},
        {"calf_r", JointRole::Knee},                 {"CC_Base_R_Calf", JointRole::Knee},
        {"shin.l", JointRole::Knee},                 {"foot_l", JointRole::Ankle},
        {"LeftToeBase", JointRole::Toe},             {"upperarm_twist_01_l", JointRole::Twist},
        {"spine_02", JointRole::Spine},              {"upperChest", JointRole::Spine},
        {"neck_01", JointRole::Neck},                {"Hips", JointRole::Pelvis},
        {"LeftHandIndex1", JointRole::Finger},       {"hand.l", JointRole::Wrist},
        {"kneeIK.l", JointRole::Other},              {"leg_joint_L_2", JointRole::Other},
        {"Skeleton_arm_joint_L__3_", JointRole::Other}};
    for (const auto& [name, role] : cases)
        EXPECT_EQ(roleWord(roleFromName(name)), roleWord(role)) << name;
}

TEST(ProposeTest, PrincipalStretchesOfATriangle) {
    // Squashed to half along x, stretched by 1.5 along y.
    const TriangleStrain s = triangleStrain({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 0}, {0.5, 0, 0}, {0, 1.5, 0});
    EXPECT_NEAR(s.minStretch, 0.5, 1e-12);
    EXPECT_NEAR(s.maxStretch, 1.5, 1e-12);
    EXPECT_NEAR(std::abs(s.minDirection.x), 1.0, 1e-9);
    // A rigid turn changes nothing.
    const TriangleStrain r = triangleStrain({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 0}, {0, 1, 0}, {-1, 0, 0});
    EXPECT_NEAR(r.minStretch, 1.0, 1e-12);
    EXPECT_NEAR(r.maxStretch, 1.0, 1e-12);
}

TEST(ProposeTest, ACreaseAtEachElbowAndKneeOnEveryCharacter) {
    for (const std::string& path : characters()) {
        SCOPED_TRACE(path);
        auto model = load(path);
        ASSERT_TRUE(model);
        ModelDerived d(model);
        const Model& m = *model;
        const BodyMap& body = d.bodyMap();
        const std::vector<Proposal>& props = d.proposals();
        ASSERT_FALSE(props.empty());
        for (const JointRole role : {JointRole::Elbow, JointRole::Knee})
            for (const char side : {'l', 'r'}) {
                const int j = body.find(role, side);
                SCOPED_TRACE(std::string(roleWord(role)) + " " + side);
                ASSERT_GE(j, 0);
                const Proposal* crease = nullptr;
                for (const Proposal& p : props)
                    if (p.kind == "crease" && p.placement.joint == m.nodes[static_cast<std::size_t>(j)].name) crease = &p;
                ASSERT_NE(crease, nullptr);
                const Placement& p = crease->placement;
                EXPECT_EQ(p.projection, Projection::Surface);
                EXPECT_EQ(p.label, std::string(side == 'l' ? "left " : "right ") + std::string(roleWord(role)) + " crease");
                // Flexion side: bending the joint to θmax brings its child towards the crease.
                const int child = boneChild(m, body, j);
                ASSERT_GE(child, 0);
                const glm::dvec3 a = anchorWorld(m, d.restSkin(), p);
                const auto bent = worldMatrices(m, bendPose(m, j, glm::dvec3(p.axis[0], p.axis[1], p.axis[2]), p.thetaMax));
                const double before = glm::length(restJointPosition(d.restSkin(), child) - a);
                const double after = glm::length(glm::dvec3(bent[static_cast<std::size_t>(child)][3]) - a);
                EXPECT_LT(after, before - 0.05 * before) << "the crease is not on the concave side";
                // Off at the rest (neutral) pose.
                EXPECT_LE(normalizedT(thetaOf(m, restPose(m), j, p), p.thetaMin, p.thetaMax), 0.1);
                // On (≥ 0.8) in the clip where the joint bends most; at the synthetic bend where no clip bends it.
                if (crease->why.synthetic) {
                    EXPECT_GE(normalizedT(thetaOf(m, bendPose(m, j, glm::dvec3(p.axis[0], p.axis[1], p.axis[2]), crease->why.peak), j, p),
                                          p.thetaMin, p.thetaMax), 0.8);
                    continue;
                }
                double bestTheta = -1e9, bestT = 0.0;
                for (std::size_t c = 0; c < m.clips.size(); ++c) {
                    double clipTheta = -1e9, clipT = 0.0;
                    for (double t = 0.0; t <= m.clips[c].duration + 1e-9; t += 1.0 / 30.0) {
                        const double th = thetaOf(m, sampleClip(m, static_cast<int>(c), static_cast<float>(t)), j, p);
                        clipTheta = std::max(clipTheta, th);
                        clipT = std::max(clipT, normalizedT(th, p.thetaMin, p.thetaMax));
                    }
                    if (clipTheta > bestTheta) {
                        bestTheta = clipTheta;
                        bestT = clipT;
                    }
                }
                EXPECT_GE(bestT, 0.8) << "peak θ " << bestTheta << " vs θmax " << p.thetaMax;
            }
    }
}

TEST(ProposeTest, TwinsAreMirrorImagesWithOneRange) {
    for (const std::string& path : characters()) {
        SCOPED_TRACE(path);
        auto model = load(path);
        ASSERT_TRUE(model);
        ModelDerived d(model);
        const std::vector<Proposal>& props = d.proposals();
        const double texel = glm::length(d.restSkin().bounds.max - d.restSkin().bounds.min) / 1024.0;
        int pairs = 0;
        for (const Proposal& left : props) {
            if (left.placement.label.rfind("left ", 0) != 0) continue;
            const Proposal* right = nullptr;
            for (const Proposal& r : props)
                if (r.placement.id == left.twin) right = &r;
            ASSERT_NE(right, nullptr) << left.placement.id << " has no twin";
            EXPECT_EQ(right->twin, left.placement.id);
            EXPECT_EQ(right->placement.label, "right " + left.placement.label.substr(5));
            auto mirrored = mirrorPlacement(left.placement, *model, d.uvLookup(), d.symmetryPlane(), d.restSkin());
            ASSERT_TRUE(mirrored) << mirrored.error().message;
            EXPECT_EQ(mirrored->joint, right->placement.joint);
            EXPECT_LE(surfaceAnchorDistance(*mirrored, right->placement), 2.0 * texel) << left.placement.id;
            EXPECT_EQ(left.placement.thetaMin, right->placement.thetaMin);
            EXPECT_EQ(left.placement.thetaMax, right->placement.thetaMax);
            ++pairs;
        }
        EXPECT_GE(pairs, 4); // elbows and knees at least
    }
}

TEST(ProposeTest, Deterministic) {
    auto model = load(kModels + "CesiumMan/CesiumMan.glb");
    ASSERT_TRUE(model);
    ModelDerived a(model), b(model);
    ASSERT_EQ(a.proposals().size(), b.proposals().size());
    for (std::size_t i = 0; i < a.proposals().size(); ++i) {
        EXPECT_EQ(a.proposals()[i].placement.id, b.proposals()[i].placement.id);
        EXPECT_EQ(a.proposals()[i].placement.anchor.position, b.proposals()[i].placement.anchor.position);
        EXPECT_EQ(a.proposals()[i].placement.axis, b.proposals()[i].placement.axis);
    }
    EXPECT_EQ(a.proposalBuilds(), 1);
}

TEST(ProposeTest, TheDefaultSetTransfersOntoOtherCharacters) {
    auto source = load(kSource + "/models/default.glb");
    ASSERT_TRUE(source);
    auto scene = loadSceneFile(kSource + "/models/default.scene.json");
    ASSERT_TRUE(scene) << scene.error().message;
    ModelDerived from(source);
    const TransferModel src{*source, from.restSkin(), from.bodyMap(), &from.uvLookup(), source.get()};
    for (const std::string path : {kModels + "CesiumMan/CesiumMan.glb", kModels + "KayKitBarbarian/Barbarian.glb"}) {
        SCOPED_TRACE(path);
        auto model = load(path);
        ASSERT_TRUE(model);
        ModelDerived to(model);
        const TransferModel dst{*model, to.restSkin(), to.bodyMap(), nullptr, nullptr};
        const TransferResult r = transferPlacements(scene->scene.placements, src, dst);
        // Every placement whose joint has a match is mapped; what is not has no match.
        for (const auto& u : r.unmapped) {
            EXPECT_EQ(u.field, "joint") << u.from << ": " << u.reason;
            for (const Placement& p : scene->scene.placements)
                if (p.id == u.from) EXPECT_EQ(matchJoint(src, dst, p.joint), "") << p.joint;
        }
        EXPECT_GE(r.mapped.size(), scene->scene.placements.size() - 1);
        const SymmetryPlane& plane = to.symmetryPlane();
        for (const auto& m : r.mapped) {
            SCOPED_TRACE(m.from);
            const Placement& p = m.placement;
            EXPECT_EQ(p.projection, Projection::Surface);
            const int j = model->findJoint(p.joint);
            ASSERT_GE(j, 0);
            // Within a bone length of the driver joint (the longer of the bones into and out of it).
            const glm::dvec3 a = anchorWorld(*model, to.restSkin(), p);
            const glm::dvec3 jp = restJointPosition(to.restSkin(), j);
            const int parent = boneParent(*model, to.bodyMap(), j), child = boneChild(*model, to.bodyMap(), j);
            double bone = 0.0;
            if (parent >= 0) bone = std::max(bone, glm::length(jp - restJointPosition(to.restSkin(), parent)));
            if (child >= 0) bone = std::max(bone, glm::length(restJointPosition(to.restSkin(), child) - jp));
            EXPECT_LE(glm::length(a - jp), bone) << p.joint;
            // On the same side as the driver joint.
            const JointInfo* info = to.bodyMap().info(j);
            ASSERT_NE(info, nullptr);
            if (info->side != 0) {
                const double s = a[plane.axis] - plane.offset;
                EXPECT_EQ(s > 0 ? 'l' : 'r', info->side) << p.joint;
            }
        }
    }
}

} // namespace
