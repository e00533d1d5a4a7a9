// RigTest — pose math of server/core/rig.hpp and the Model queries of model.hpp on hand-built
// models: linear blend skinning against positions worked out by hand, clip sampling (glTF 2.0
// Appendix C: LINEAR/slerp, STEP, CUBICSPLINE Hermite, clamping), world matrices in any node
// order, unit normals. Pure: no files.
#include "core/rig.hpp"

#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include <cmath>
#include <random>

using namespace dermis;

namespace {

constexpr float kEps = 1e-6f;

#define EXPECT_VEC3_NEAR(a, b, eps)                                                                \
    do {                                                                                           \
        const glm::vec3 a_ = (a), b_ = (b);                                                        \
        EXPECT_NEAR(a_.x, b_.x, eps);                                                              \
        EXPECT_NEAR(a_.y, b_.y, eps);                                                              \
        EXPECT_NEAR(a_.z, b_.z, eps);                                                              \
    } while (0)

/// q and −q are the same rotation.
void expectSameRotation(const glm::quat& a, const glm::quat& b, float eps = 1e-6f) {
    EXPECT_NEAR(std::abs(glm::dot(a, b)), 1.0f, eps)
        << "a = (" << a.w << ", " << a.x << ", " << a.y << ", " << a.z << "), b = (" << b.w << ", "
        << b.x << ", " << b.y << ", " << b.z << ")";
}

glm::quat rotZ(float degrees) {
    return glm::angleAxis(glm::radians(degrees), glm::vec3(0.0f, 0.0f, 1.0f));
}

/// A two-bone chain along +x: "root" at the origin, "elbow" at (1, 0, 0) (child of root), and a
/// strip of vertices skinned to them, all normals +y. Inverse bind matrices are the inverse rest
/// world matrices, so the rest pose is the bind pose.
Model boneChain() {
    Model m;
    m.nodes.resize(2);
    m.nodes[0].name = "root";
    m.nodes[1].name = "elbow";
    m.nodes[1].parent = 0;
    m.nodes[1].translation = {1.0f, 0.0f, 0.0f};
    m.joints = {0, 1};

    MeshPart part;
    part.name = "arm";
    part.positions = {{0.5f, 0.0f, 0.0f},  // on root only
                      {1.5f, 0.0f, 0.0f},  // on elbow only
                      {2.0f, 0.5f, 0.0f},  // on elbow only
                      {1.5f, 0.0f, 0.0f}}; // half root, half elbow
    part.normals.assign(4, glm::vec3(0.0f, 1.0f, 0.0f));
    part.joints = {{0, 0, 0, 0}, {1, 0, 0, 0}, {1, 0, 0, 0}, {0, 1, 0, 0}};
    part.weights = {{1, 0, 0, 0}, {1, 0, 0, 0}, {1, 0, 0, 0}, {0.5f, 0.5f, 0, 0}};
    part.indices = {0, 1, 2, 1, 3, 2};
    part.influences.resize(2);
    part.influences[0].node = 0; // rest world = identity
    part.influences[1].node = 1;
    part.influences[1].inverseBind = glm::translate(glm::mat4(1.0f), {-1.0f, 0.0f, 0.0f});
    m.parts.push_back(part);
    return m;
}

Channel channel(int node, ChannelPath path, Interpolation interp, std::vector<float> times,
                std::vector<float> values) {
    Channel c;
    c.node = node;
    c.path = path;
    c.interpolation = interp;
    c.times = std::move(times);
    c.values = std::move(values);
    return c;
}

/// A model of `n` unrelated nodes with one clip holding `channels`, duration = last key.
Model withClip(std::vector<Channel> channels, std::size_t n = 2) {
    Model m;
    m.nodes.resize(n);
    Clip clip;
    clip.name = "clip";
    for (const Channel& c : channels)
        clip.duration = std::max(clip.duration, c.times.back());
    clip.channels = std::move(channels);
    m.clips.push_back(clip);
    return m;
}

} // namespace

// --- skinning ------------------------------------------------------------------------------------

TEST(RigTest, RestPoseSkinningReproducesBindPositions) {
    const Model m = boneChain();
    const auto posed = skin(m, worldMatrices(m, restPose(m)));
    ASSERT_EQ(posed.size(), 1u);
    ASSERT_EQ(posed[0].positions.size(), m.parts[0].positions.size());
    for (std::size_t v = 0; v < posed[0].positions.size(); ++v) {
        EXPECT_VEC3_NEAR(posed[0].positions[v], m.parts[0].positions[v], kEps);
        EXPECT_VEC3_NEAR(posed[0].normals[v], m.parts[0].normals[v], kEps);
    }
}

TEST(RigTest, ElbowBentNinetyDegreesMovesVerticesAsWorkedOutByHand) {
    const Model m = boneChain();
    LocalPose pose = restPose(m);
    pose.rotation[1] = rotZ(90.0f); // bend the elbow: x → y about (1, 0, 0)
    const auto posed = skin(m, worldMatrices(m, pose));
    const auto& p = posed[0].positions;
    const auto& n = posed[0].normals;
    // Root-only vertex does not move.
    EXPECT_VEC3_NEAR(p[0], glm::vec3(0.5f, 0.0f, 0.0f), kEps);
    // Elbow-only: bind (1.5, 0) is (0.5, 0) from the elbow → rotated (0, 0.5) → (1, 0.5).
    EXPECT_VEC3_NEAR(p[1], glm::vec3(1.0f, 0.5f, 0.0f), kEps);
    // (2, 0.5) is (1, 0.5) from the elbow → rotated (−0.5, 1) → (0.5, 1).
    EXPECT_VEC3_NEAR(p[2], glm::vec3(0.5f, 1.0f, 0.0f), kEps);
    // Half/half: 0.5·(1.5, 0) + 0.5·(1, 0.5) = (1.25, 0.25).
    EXPECT_VEC3_NEAR(p[3], glm::vec3(1.25f, 0.25f, 0.0f), kEps);
    // Normals: root keeps +y; elbow turns +y into −x; the blend of I and Rz(90°) is a rotation by
    // 45° scaled by 1/√2, whose inverse-transpose turns +y by 45°: (−√½, √½).
    EXPECT_VEC3_NEAR(n[0], glm::vec3(0.0f, 1.0f, 0.0f), kEps);
    EXPECT_VEC3_NEAR(n[1], glm::vec3(-1.0f, 0.0f, 0.0f), kEps);
    EXPECT_VEC3_NEAR(n[2], glm::vec3(-1.0f, 0.0f, 0.0f), kEps);
    const float h = std::sqrt(0.5f);
    EXPECT_VEC3_NEAR(n[3], glm::vec3(-h, h, 0.0f), kEps);
}

TEST(RigTest, ParentMotionCarriesTheChild) {
    const Model m = boneChain();
    LocalPose pose = restPose(m);
    pose.rotation[0] = rotZ(90.0f); // the whole arm swings up
    pose.translation[0] = {0.0f, 0.0f, 2.0f};
    const auto posed = skin(m, worldMatrices(m, pose));
    const auto& p = posed[0].positions;
    EXPECT_VEC3_NEAR(p[0], glm::vec3(0.0f, 0.5f, 2.0f), kEps);
    EXPECT_VEC3_NEAR(p[1], glm::vec3(0.0f, 1.5f, 2.0f), kEps);
    EXPECT_VEC3_NEAR(p[2], glm::vec3(-0.5f, 2.0f, 2.0f), kEps);
    EXPECT_VEC3_NEAR(p[3], glm::vec3(0.0f, 1.5f, 2.0f), kEps);
}

TEST(RigTest, NormalsUseTheInverseTransposeUnderNonUniformScale) {
    Model m = boneChain();
    // A 45° face normal on the root; scale the root 2× along x.
    m.parts[0].normals[0] = glm::normalize(glm::vec3(1.0f, 1.0f, 0.0f));
    LocalPose pose = restPose(m);
    pose.scale[0] = {2.0f, 1.0f, 1.0f};
    const auto posed = skin(m, worldMatrices(m, pose));
    EXPECT_VEC3_NEAR(posed[0].positions[0], glm::vec3(1.0f, 0.0f, 0.0f), kEps);
    // (S⁻¹)ᵀ·(1, 1, 0) = (0.5, 1, 0), normalised — not S·n = (2, 1, 0).
    EXPECT_VEC3_NEAR(posed[0].normals[0], glm::normalize(glm::vec3(0.5f, 1.0f, 0.0f)), kEps);
}

TEST(RigTest, MirroringScaleKeepsNormalsOnTheSurface) {
    Model m = boneChain();
    LocalPose pose = restPose(m);
    pose.scale[0] = {1.0f, -1.0f, 1.0f}; // mirror y: the +y normal must become −y
    const auto posed = skin(m, worldMatrices(m, pose));
    EXPECT_VEC3_NEAR(posed[0].normals[0], glm::vec3(0.0f, -1.0f, 0.0f), kEps);
}

TEST(RigTest, NormalsStayUnitUnderRandomPoses) {
    Model m = boneChain();
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    for (auto& n : m.parts[0].normals)
        n = glm::normalize(glm::vec3(u(rng), u(rng), u(rng)));
    for (int trial = 0; trial < 200; ++trial) {
        LocalPose pose = restPose(m);
        for (std::size_t i = 0; i < m.nodes.size(); ++i) {
            pose.rotation[i] = glm::normalize(glm::quat(u(rng), u(rng), u(rng), u(rng)));
            pose.scale[i] = glm::vec3(1.5f + u(rng), 1.5f + u(rng), 1.5f + u(rng));
            pose.translation[i] = glm::vec3(u(rng), u(rng), u(rng));
        }
        for (const auto& part : skin(m, worldMatrices(m, pose)))
            for (const auto& n : part.normals)
                EXPECT_NEAR(glm::length(n), 1.0f, 1e-5f);
    }
}

TEST(RigTest, VerticesWithoutWeightsFollowInfluenceZeroAndMissingNormalsAreComputed) {
    Model m = boneChain();
    m.parts[0].joints.clear();
    m.parts[0].weights.clear();
    m.parts[0].normals.clear();
    LocalPose pose = restPose(m);
    pose.translation[0] = {0.0f, 0.0f, 1.0f};
    const auto posed = skin(m, worldMatrices(m, pose));
    ASSERT_EQ(posed[0].normals.size(), m.parts[0].positions.size());
    EXPECT_VEC3_NEAR(posed[0].positions[2], glm::vec3(2.0f, 0.5f, 1.0f), kEps);
    // Triangle (0, 1, 2) lies in z = 1, counter-clockwise seen from +z.
    EXPECT_VEC3_NEAR(posed[0].normals[0], glm::vec3(0.0f, 0.0f, 1.0f), kEps);
}

// --- world matrices ----------------------------------------------------------------------------

TEST(RigTest, WorldMatricesDoNotNeedParentsFirst) {
    // Node 0 is a child of node 2, node 1 a child of node 0: children listed before parents.
    Model m;
    m.nodes.resize(3);
    m.nodes[0].parent = 2;
    m.nodes[0].translation = {0.0f, 1.0f, 0.0f};
    m.nodes[1].parent = 0;
    m.nodes[1].translation = {1.0f, 0.0f, 0.0f};
    m.nodes[2].rotation = rotZ(90.0f);
    m.nodes[2].scale = glm::vec3(2.0f);
    const auto world = worldMatrices(m, restPose(m));
    ASSERT_EQ(world.size(), 3u);
    // Node 1's origin: (1, 0, 0) + (0, 1, 0) = (1, 1, 0) in node 2's frame → ·2 → Rz(90°):
    // (2, 2, 0) → (−2, 2, 0).
    EXPECT_VEC3_NEAR(glm::vec3(world[1] * glm::vec4(0, 0, 0, 1)), glm::vec3(-2, 2, 0), kEps);
    EXPECT_VEC3_NEAR(glm::vec3(world[0] * glm::vec4(0, 0, 0, 1)), glm::vec3(-2, 0, 0), kEps);
    // Same as composing by hand, T·R·S per node.
    auto local = [](const Node& n) {
        return glm::translate(glm::mat4(1.0f), n.translation) * glm::mat4_cast(n.rotation) *
               glm::scale(glm::mat4(1.0f), n.scale);
    };
    const glm::mat4 expected = local(m.nodes[2]) * local(m.nodes[0]) * local(m.nodes[1]);
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            EXPECT_NEAR(world[1][c][r], expected[c][r], kEps);
}

TEST(RigTest, WorldMatricesSurviveBrokenHierarchies) {
    // A parent cycle and a parent out of range (invalid models): finite results, no hang.
    Model m;
    m.nodes.resize(3);
    m.nodes[0].parent = 1;
    m.nodes[1].parent = 0;
    m.nodes[2].parent = 42;
    m.nodes[2].translation = {1.0f, 2.0f, 3.0f};
    const auto world = worldMatrices(m, restPose(m));
    ASSERT_EQ(world.size(), 3u);
    EXPECT_VEC3_NEAR(glm::vec3(world[2][3]), glm::vec3(1, 2, 3), kEps);
}

// --- clip sampling ------------------------------------------------------------------------------

TEST(RigTest, LinearTranslationAndClamping) {
    Model m = withClip({channel(1, ChannelPath::Translation, Interpolation::Linear, {0, 1, 2},
                                {0, 0, 0, 2, 0, 0, 2, 4, 0})});
    m.nodes[0].translation = {7, 8, 9};
    EXPECT_FLOAT_EQ(m.clips[0].duration, 2.0f);
    EXPECT_VEC3_NEAR(sampleClip(m, 0, 0.5f).translation[1], glm::vec3(1, 0, 0), kEps);
    EXPECT_VEC3_NEAR(sampleClip(m, 0, 1.0f).translation[1], glm::vec3(2, 0, 0), kEps);
    EXPECT_VEC3_NEAR(sampleClip(m, 0, 1.5f).translation[1], glm::vec3(2, 2, 0), kEps);
    EXPECT_VEC3_NEAR(sampleClip(m, 0, -1.0f).translation[1], glm::vec3(0, 0, 0), kEps);
    EXPECT_VEC3_NEAR(sampleClip(m, 0, 5.0f).translation[1], glm::vec3(2, 4, 0), kEps);
    EXPECT_VEC3_NEAR(sampleClip(m, 0, NAN).translation[1], glm::vec3(0, 0, 0), kEps);
    // A node without a channel keeps its rest TRS.
    const LocalPose pose = sampleClip(m, 0, 0.5f);
    EXPECT_VEC3_NEAR(pose.translation[0], glm::vec3(7, 8, 9), kEps);
    expectSameRotation(pose.rotation[1], glm::quat(1, 0, 0, 0));
    EXPECT_VEC3_NEAR(pose.scale[1], glm::vec3(1), kEps);
}

TEST(RigTest, ChannelStartingLateHoldsItsFirstKey) {
    // glTF: before a channel's first key its first value holds (even after clip time 0).
    Model m = withClip(
        {channel(0, ChannelPath::Translation, Interpolation::Linear, {1, 2}, {1, 0, 0, 3, 0, 0}),
         channel(1, ChannelPath::Translation, Interpolation::Linear, {0, 4}, {0, 0, 0, 0, 0, 0})});
    EXPECT_VEC3_NEAR(sampleClip(m, 0, 0.25f).translation[0], glm::vec3(1, 0, 0), kEps);
    EXPECT_VEC3_NEAR(sampleClip(m, 0, 1.5f).translation[0], glm::vec3(2, 0, 0), kEps);
    EXPECT_VEC3_NEAR(sampleClip(m, 0, 3.0f).translation[0], glm::vec3(3, 0, 0), kEps);
}

TEST(RigTest, LinearRotationIsSlerpAlongTheShortArc) {
    const glm::quat q90 = rotZ(90.0f);
    // Key values [x, y, z, w]; the second key is −Rz(90°), the same rotation.
    Model m = withClip({channel(0, ChannelPath::Rotation, Interpolation::Linear, {0, 1},
                                {0, 0, 0, 1, -q90.x, -q90.y, -q90.z, -q90.w}),
                        channel(1, ChannelPath::Rotation, Interpolation::Linear, {0, 1},
                                {0, 0, 0, 1, q90.x, q90.y, q90.z, q90.w})});
    for (float t : {0.25f, 0.5f, 0.75f}) {
        const LocalPose pose = sampleClip(m, 0, t);
        expectSameRotation(pose.rotation[0], rotZ(90.0f * t));
        expectSameRotation(pose.rotation[1], rotZ(90.0f * t));
        EXPECT_NEAR(glm::length(pose.rotation[0]), 1.0f, 1e-6f);
    }
    // Slerp, not nlerp: a quarter of the way is 22.5° exactly, where nlerp gives ≈ 26.6°.
    const glm::quat q = sampleClip(m, 0, 0.25f).rotation[1];
    EXPECT_NEAR(glm::degrees(glm::angle(q)), 22.5f, 1e-3f);
}

TEST(RigTest, StepHoldsEachKeyUntilTheNext) {
    Model m = withClip({channel(0, ChannelPath::Scale, Interpolation::Step, {0, 1, 2},
                                {1, 1, 1, 2, 2, 2, 3, 3, 3})});
    EXPECT_VEC3_NEAR(sampleClip(m, 0, 0.0f).scale[0], glm::vec3(1), kEps);
    EXPECT_VEC3_NEAR(sampleClip(m, 0, 0.99f).scale[0], glm::vec3(1), kEps);
    EXPECT_VEC3_NEAR(sampleClip(m, 0, 1.0f).scale[0], glm::vec3(2), kEps);
    EXPECT_VEC3_NEAR(sampleClip(m, 0, 1.5f).scale[0], glm::vec3(2), kEps);
    EXPECT_VEC3_NEAR(sampleClip(m, 0, 2.0f).scale[0], glm::vec3(3), kEps);
    EXPECT_VEC3_NEAR(sampleClip(m, 0, 9.0f).scale[0], glm::vec3(3), kEps);
    EXPECT_VEC3_NEAR(sampleClip(m, 0, -9.0f).scale[0], glm::vec3(1), kEps);
}

TEST(RigTest, CubicSplineIsTheHermiteOfAppendixC) {
    // Two keys at t = 0 and t = 2 (td = 2). Per key: in-tangent a, value v, out-tangent b.
    //   key 0: a = (9, 9, 9) (unused), v = (0, 0, 0), b = (1, 0, 0)
    //   key 1: a = (0, 2, 0),           v = (1, 1, 0), b = (9, 9, 9) (unused)
    // p(u) = h00·v0 + td·h10·b0 + h01·v1 + td·h11·a1.
    Model m = withClip({channel(0, ChannelPath::Translation, Interpolation::CubicSpline, {0, 2},
                                {9, 9, 9, 0, 0, 0, 1, 0, 0, 0, 2, 0, 1, 1, 0, 9, 9, 9})});
    // u = 0.5: h00 = 0.5, h10 = 0.125, h01 = 0.5, h11 = −0.125
    //   x = 2·0.125·1 + 0.5·1 = 0.75;  y = 0.5·1 + 2·(−0.125)·2 = 0
    EXPECT_VEC3_NEAR(sampleClip(m, 0, 1.0f).translation[0], glm::vec3(0.75f, 0.0f, 0.0f), kEps);
    // u = 0.25: h10 = 0.140625, h01 = 0.15625, h11 = −0.046875
    //   x = 2·0.140625 + 0.15625 = 0.4375;  y = 0.15625 − 2·0.046875·2 = −0.03125
    EXPECT_VEC3_NEAR(sampleClip(m, 0, 0.5f).translation[0], glm::vec3(0.4375f, -0.03125f, 0.0f),
                     kEps);
    // Outside the keys: the values, never the tangents.
    EXPECT_VEC3_NEAR(sampleClip(m, 0, -1.0f).translation[0], glm::vec3(0, 0, 0), kEps);
    EXPECT_VEC3_NEAR(sampleClip(m, 0, 2.0f).translation[0], glm::vec3(1, 1, 0), kEps);
    EXPECT_VEC3_NEAR(sampleClip(m, 0, 3.0f).translation[0], glm::vec3(1, 1, 0), kEps);
}

TEST(RigTest, CubicSplineRotationsAreRenormalised) {
    // Zero tangents: at u = 0.5 the spline is the plain average of the two keys, which is not
    // unit; normalised it is Rz(45°).
    const glm::quat q = rotZ(90.0f);
    Model m = withClip({channel(0, ChannelPath::Rotation, Interpolation::CubicSpline, {0, 1},
                                {0, 0, 0, 0, 0,   0,   0,   1,   0, 0, 0, 0,     // key 0
                                 0, 0, 0, 0, q.x, q.y, q.z, q.w, 0, 0, 0, 0})}); // key 1
    const glm::quat r = sampleClip(m, 0, 0.5f).rotation[0];
    EXPECT_NEAR(glm::length(r), 1.0f, 1e-6f);
    expectSameRotation(r, rotZ(45.0f));
}

TEST(RigTest, InconsistentChannelsAreIgnored) {
    // Too few values, a node out of range: sampled as rest, no out-of-bounds read.
    Model m = withClip(
        {channel(0, ChannelPath::Translation, Interpolation::Linear, {0, 1}, {1, 2}),
         channel(5, ChannelPath::Translation, Interpolation::Linear, {0, 1}, {1, 1, 1, 2, 2, 2})});
    const LocalPose pose = sampleClip(m, 0, 0.5f);
    EXPECT_VEC3_NEAR(pose.translation[0], glm::vec3(0), kEps);
}

// --- model queries and normals ------------------------------------------------------------------

TEST(RigTest, ModelQueries) {
    Model m = boneChain();
    m.nodes.push_back(Node{"prop", 1});
    m.clips.push_back(Clip{"Walk", 1.0f, {}});
    m.clips.push_back(Clip{"Run", 1.0f, {}});
    EXPECT_EQ(m.findJoint("elbow"), 1);
    EXPECT_EQ(m.findJoint("prop"), -1); // a node, not a joint
    EXPECT_EQ(m.findJoint("nope"), -1);
    EXPECT_EQ(m.findClip("Run"), 1);
    EXPECT_EQ(m.findClip("run"), -1);
    EXPECT_EQ(m.triangleCount(), 2u);
    EXPECT_FALSE(m.hasUVs());
    m.parts[0].uvs.assign(m.parts[0].positions.size(), glm::vec2(0.5f));
    EXPECT_TRUE(m.hasUVs());
    m.parts.push_back(m.parts[0]);
    m.parts[1].uvs.clear();
    EXPECT_FALSE(m.hasUVs());
    EXPECT_FALSE(Model().hasUVs());
}

TEST(RigTest, ComputedNormalsAreAreaWeighted) {
    // Vertex 0 is shared by a big triangle facing +z and a small one facing +x.
    const std::vector<glm::vec3> p = {{0, 0, 0},  {2, 0, 0}, {0, 2, 0},
                                      {0, 0, -1}, {0, 1, 0}, {5, 5, 5}};
    const std::vector<std::uint32_t> idx = {0, 1, 2, 0, 3, 4};
    const auto n = computeNormals(p, idx);
    ASSERT_EQ(n.size(), p.size());
    // Face normals (unnormalised): (0, 0, 4) and (1·1, 0, 0) = (1, 0, 0).
    EXPECT_VEC3_NEAR(n[0], glm::normalize(glm::vec3(1, 0, 4)), kEps);
    EXPECT_VEC3_NEAR(n[1], glm::vec3(0, 0, 1), kEps);
    EXPECT_VEC3_NEAR(n[3], glm::vec3(1, 0, 0), kEps);
    EXPECT_VEC3_NEAR(n[5], glm::vec3(0, 0, 1), kEps); // on no triangle
}
