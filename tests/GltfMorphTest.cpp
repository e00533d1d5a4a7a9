// GltfMorphTest — glTF morph targets (glTF 2.0 §3.7.2.2) from file to posed vertices: the loader
// (server/io/gltf_morph.cpp: targets, weights by node or mesh, names from extras.targetNames;
// gltf_animations.cpp: weights channels), the pose math (core/rig.hpp: sampleClip, morphPart,
// skin), the scene's pose.morphs (core/bake.hpp evaluatePose), subdivision and height-map
// layouts carrying the deltas, and the loader's errors naming the field. Hand-built files only.
#include "GltfTestBuilder.hpp"

#include "core/bake.hpp"
#include "core/subdivide.hpp"
#include "core/texture_layout.hpp"

using namespace dermis;
using namespace dermis::test;
using namespace dermis::test::gltf;

namespace {

Model load(const std::vector<std::uint8_t>& glb) {
    auto m = parseModel(glb);
    EXPECT_TRUE(m.ok()) << (m.ok() ? "" : m.error().message);
    return m.ok() ? std::move(*m) : Model{};
}

void expectNear(glm::vec3 a, glm::vec3 b, float tol = 1e-6f) {
    EXPECT_NEAR(a.x, b.x, tol);
    EXPECT_NEAR(a.y, b.y, tol);
    EXPECT_NEAR(a.z, b.z, tol);
}

} // namespace

TEST(GltfMorphTest, LoadsTargetsWeightsAndNames) {
    MorphedTriangle t;
    const Model m = load(t.b.glb());
    expectConsistent(m);
    ASSERT_EQ(m.morphWeights.size(), 2u);
    EXPECT_EQ(m.morphWeights[0].name, "smile");
    EXPECT_EQ(m.morphWeights[1].name, "blink");
    EXPECT_EQ(m.morphWeights[0].rest, 0.25f);
    EXPECT_EQ(m.morphWeights[1].rest, 0.0f);
    EXPECT_EQ(m.morphWeights[0].node, 2);
    ASSERT_EQ(m.parts.size(), 1u);
    const MeshPart& p = m.parts[0];
    ASSERT_EQ(p.morphs.size(), 2u);
    EXPECT_EQ(p.morphs[0].weight, 0);
    EXPECT_EQ(p.morphs[1].weight, 1);
    ASSERT_EQ(p.morphs[0].positions.size(), 3u);
    expectNear(p.morphs[0].positions[2], {0, 0.5f, 0});
    ASSERT_EQ(p.morphs[0].normals.size(), 3u);
    expectNear(p.morphs[0].normals[2], {1, 0, 0});
    EXPECT_TRUE(p.morphs[1].normals.empty());
    expectNear(p.morphs[1].positions[1], {0, 0, 1});
    // The clip channel on weights is loaded (the "face" clip).
    const int face = m.findClip("face");
    ASSERT_GE(face, 0);
    ASSERT_EQ(m.clips[static_cast<std::size_t>(face)].channels.size(), 1u);
    const Channel& ch = m.clips[static_cast<std::size_t>(face)].channels[0];
    EXPECT_EQ(ch.path, ChannelPath::Weights);
    EXPECT_EQ(ch.morphFirst, 0);
    EXPECT_EQ(ch.morphCount, 2);
}

TEST(GltfMorphTest, NodeWeightsOverrideTheMeshAndUnnamedTargetsGetTheMeshName) {
    MorphedTriangle t;
    t.b.doc["nodes"][2]["weights"] = {0.5, 1.0};
    t.b.doc["meshes"][0].erase("extras");
    const Model m = load(t.b.glb());
    ASSERT_EQ(m.morphWeights.size(), 2u);
    EXPECT_EQ(m.morphWeights[0].rest, 0.5f);
    EXPECT_EQ(m.morphWeights[1].rest, 1.0f);
    EXPECT_EQ(m.morphWeights[0].name, "tri#0");
    EXPECT_EQ(m.morphWeights[1].name, "tri#1");
}

TEST(GltfMorphTest, WeightsChannelsDriveThePoseLinearAndCubic) {
    MorphedTriangle t;
    Model m = load(t.b.glb());
    const int face = m.findClip("face");
    ASSERT_GE(face, 0);
    EXPECT_EQ(restPose(m).morphWeights, (std::vector<float>{0.25f, 0.0f}));
    EXPECT_EQ(sampleClip(m, face, 0.0f).morphWeights, (std::vector<float>{0.0f, 0.0f}));
    const std::vector<float> mid = sampleClip(m, face, 0.5f).morphWeights;
    ASSERT_EQ(mid.size(), 2u);
    EXPECT_NEAR(mid[0], 0.5f, 1e-6f);
    EXPECT_NEAR(mid[1], 0.25f, 1e-6f);
    // A clip without a weights channel keeps the rest weights.
    EXPECT_EQ(sampleClip(m, m.findClip("bend"), 0.5f).morphWeights, (std::vector<float>{0.25f, 0.0f}));

    // CUBICSPLINE: per key in-tangents, values, out-tangents of both targets (zero tangents: the
    // Hermite blend of the values, ½·(v₀ + v₁) at the middle).
    MorphedTriangle c;
    const int out = c.b.add(std::vector<float>{0, 0, 0, 0, 0, 0, 0, 0, 1, 0.5f, 0, 0}, kFloat, "SCALAR");
    json& smp = c.b.doc["animations"][1]["samplers"][0];
    smp["output"] = out;
    smp["interpolation"] = "CUBICSPLINE";
    m = load(c.b.glb());
    const std::vector<float> cubic = sampleClip(m, m.findClip("face"), 0.5f).morphWeights;
    ASSERT_EQ(cubic.size(), 2u);
    EXPECT_NEAR(cubic[0], 0.5f, 1e-6f);
    EXPECT_NEAR(cubic[1], 0.25f, 1e-6f);
}

TEST(GltfMorphTest, SkinningMorphsFirstInBindSpace) {
    MorphedTriangle t;
    const Model m = load(t.b.glb());
    const std::vector<float> w{1.0f, 1.0f};
    const MorphedPart mp = morphPart(m, m.parts[0], w);
    expectNear(mp.positions[2], {0, 1.5f, 0});
    expectNear(mp.positions[1], {1, 0, 1});
    expectNear(mp.normals[2], glm::normalize(glm::vec3(1, 0, 1)));
    expectNear(mp.normals[0], {0, 0, 1});
    // Rest weights when none are given: 0.25 of "smile".
    expectNear(morphPart(m, m.parts[0], {}).positions[2], {0, 1.125f, 0});

    // Posed by the "bend" clip: morph, then skin — the same as skinning the baked vertices.
    const std::vector<glm::mat4> world = worldMatrices(m, sampleClip(m, m.findClip("bend"), 0.7f));
    const auto a = skin(m, world, w);
    const auto b = skin(bakedMorphs(m, w), world);
    ASSERT_EQ(a.size(), 1u);
    EXPECT_LT(maxDistance(a, b), 1e-6f);
    for (std::size_t v = 0; v < 3; ++v)
        expectNear(a[0].normals[v], b[0].normals[v], 1e-6f);
    // Weight 0 everywhere is the unmorphed mesh.
    Model plain = m;
    plain.parts[0].morphs.clear();
    EXPECT_LT(maxDistance(skin(m, world, {0.0f, 0.0f}), skin(plain, world)), 1e-7f);
    // And the moved vertex really moved.
    EXPECT_GT(maxDistance(a, skin(plain, world)), 0.4f);
}

TEST(GltfMorphTest, PoseMorphsSetWeightsByName) {
    MorphedTriangle t;
    // A second instance of the mesh: its "smile" is set by the same name.
    t.b.doc["nodes"].push_back({{"name", "body2"}, {"mesh", 0}, {"translation", {0, 0, 2}}});
    t.b.doc["nodes"][0]["children"].push_back(3);
    const Model m = load(t.b.glb());
    ASSERT_EQ(m.morphWeights.size(), 4u);
    Pose pose;
    pose.animation = "face";
    pose.time = 0.5;
    pose.morphs["smile"] = 0.8;
    auto local = evaluatePose(m, pose);
    ASSERT_TRUE(local.ok()) << local.error().message;
    ASSERT_EQ(local->morphWeights.size(), 4u);
    EXPECT_FLOAT_EQ(local->morphWeights[0], 0.8f);  // set by name, over the clip
    EXPECT_NEAR(local->morphWeights[1], 0.25f, 1e-6f); // the clip's
    EXPECT_FLOAT_EQ(local->morphWeights[2], 0.8f);  // the other instance's "smile"
    EXPECT_FLOAT_EQ(local->morphWeights[3], 0.0f);  // its blink: rest (the clip drives node 2 only)

    pose.morphs["frown"] = 1.0;
    auto bad = evaluatePose(m, pose);
    ASSERT_FALSE(bad.ok());
    EXPECT_EQ(bad.error().code, ErrorCode::NotFound);
    EXPECT_EQ(bad.error().field, "/pose/morphs/frown");
}

TEST(GltfMorphTest, RigidPartDeltasLiveInItsRestWorldSpace) {
    MorphedTriangle t;
    json& d = t.b.doc;
    // The mesh on a plain node scaled by 2 and moved: a rigid part stored in rest world space.
    d["nodes"][2].erase("skin");
    d["nodes"][2]["scale"] = {2, 2, 2};
    d["nodes"][2]["translation"] = {0, 0, 3};
    d["meshes"][0]["primitives"][0]["attributes"].erase("JOINTS_0");
    d["meshes"][0]["primitives"][0]["attributes"].erase("WEIGHTS_0");
    const Model m = load(t.b.glb());
    expectConsistent(m);
    ASSERT_EQ(m.parts.size(), 1u);
    expectNear(m.parts[0].morphs[0].positions[2], {0, 1.0f, 0});
    const auto posed = skin(m, worldMatrices(m, restPose(m)), {1.0f, 0.0f});
    expectNear(posed[0].positions[2], glm::vec3(0, 2, 3) + glm::vec3(0, 1, 0), 1e-5f);
    expectNear(posed[0].normals[2], glm::normalize(glm::vec3(1, 0, 1)), 1e-5f);
}

TEST(GltfMorphTest, SubdivisionAndLayoutsCarryTheDeltas) {
    MorphedTriangle t;
    const Model m = load(t.b.glb());
    auto sub = subdivideMidpoint(m.parts[0]);
    ASSERT_TRUE(sub.ok());
    ASSERT_EQ(sub->positions.size(), 6u);
    for (const MorphTarget& target : sub->morphs) {
        ASSERT_EQ(target.positions.size(), 6u);
        EXPECT_TRUE(target.normals.empty() || target.normals.size() == 6u);
    }
    // The midpoint of vertices 1 and 2 moves by the mean of their deltas.
    bool found = false;
    for (std::size_t v = 3; v < 6; ++v)
        if (glm::length(sub->positions[v] - glm::vec3(0.5f, 0.5f, 0)) < 1e-6f) {
            expectNear(sub->morphs[0].positions[v], {0, 0.25f, 0});
            expectNear(sub->morphs[1].positions[v], {0, 0, 0.5f});
            found = true;
        }
    EXPECT_TRUE(found);

    // A layout that splits vertex 0 into two copies: each copy keeps its source's deltas.
    TextureLayout layout;
    PartLayout pl;
    pl.source = {0, 1, 2, 0};
    pl.uvs = {{0, 0}, {1, 0}, {0, 1}, {0.5f, 0.5f}};
    pl.indices = {3, 1, 2};
    layout.parts.push_back(pl);
    const Model through = modelThroughLayout(m, layout);
    ASSERT_EQ(through.parts[0].morphs.size(), 2u);
    ASSERT_EQ(through.parts[0].morphs[0].positions.size(), 4u);
    expectNear(through.parts[0].morphs[0].positions[2], {0, 0.5f, 0});
    expectNear(through.parts[0].morphs[1].positions[1], {0, 0, 1});
    expectNear(through.parts[0].morphs[1].positions[3], {0, 0, 0});
}

TEST(GltfMorphTest, ErrorsNameTheField) {
    {   // primitives of one mesh with different target counts
        MorphedTriangle t;
        json prim = t.b.doc["meshes"][0]["primitives"][0];
        prim.erase("targets");
        t.b.doc["meshes"][0]["primitives"].push_back(prim);
        expectFieldError(t.b.glb(), "/meshes/0/primitives/1/targets");
    }
    {   // weights of another length than the targets
        MorphedTriangle t;
        t.b.doc["meshes"][0]["weights"] = {1.0};
        expectFieldError(t.b.glb(), "/meshes/0/weights");
        t.b.doc["meshes"][0]["weights"] = {1.0, 0.0};
        t.b.doc["nodes"][2]["weights"] = {1.0, 0.0, 0.0};
        expectFieldError(t.b.glb(), "/nodes/2/weights");
    }
    {   // a delta accessor with another vertex count
        MorphedTriangle t;
        t.b.doc["accessors"][static_cast<std::size_t>(t.smilePosition)]["count"] = 2;
        expectFieldError(t.b.glb(), "/meshes/0/primitives/0/targets/0/POSITION");
    }
    {   // a weights channel whose output is not keys × targets
        MorphedTriangle t;
        t.b.doc["accessors"][static_cast<std::size_t>(t.faceWeights)]["count"] = 3;
        expectFieldError(t.b.glb(), "/animations/1/samplers/0/output");
    }
}
