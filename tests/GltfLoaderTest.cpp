// GltfLoaderTest — glTF 2.0 in (server/io/gltf_loader.hpp): the shared models written by others
// (tests/models; the tests fail, never skip, when they are missing), small hand-built files that
// pin each loading rule, and external files (only from the model's folder) and files in memory
// (only resolving to each other). Corrupt input is GltfLoaderDamageTest's; the builders and checks
// both use are in GltfTestBuilder.hpp. Reads the shared models and writes temporary files.
#include "GltfTestBuilder.hpp"

using namespace dermis;
using namespace dermis::test;
using namespace dermis::test::gltf;

// --- the shared models
// ----------------------------------------------------------------------------

TEST(GltfLoaderTest, CesiumMan) {
    auto m = loadShared(kCesiumMan);
    ASSERT_TRUE(m.ok());
    EXPECT_EQ(m->joints.size(), 19u);
    EXPECT_EQ(m->triangleCount(), 4672u);
    EXPECT_TRUE(m->hasUVs());
    ASSERT_GE(m->clips.size(), 1u);
    EXPECT_GT(m->clips[0].duration, 0.0f);
    ASSERT_EQ(m->parts.size(), 1u);
    EXPECT_EQ(m->parts[0].influences.size(), 19u);
    ASSERT_GE(m->parts[0].material, 0);
    const Material& mat = m->materials[static_cast<std::size_t>(m->parts[0].material)];
    ASSERT_GE(mat.baseColorTexture, 0);
    const Image8& img = m->images[static_cast<std::size_t>(mat.baseColorTexture)];
    EXPECT_GT(img.width, 0);
    EXPECT_GT(img.height, 0);
    EXPECT_EQ(img.rgba.size(), static_cast<std::size_t>(img.width) * img.height * 4);
    expectConsistent(*m);
    expectRestReproducesBindAndClipsMove(*m);
}

TEST(GltfLoaderTest, RiggedFigure) {
    auto m = loadShared(kRiggedFigure);
    ASSERT_TRUE(m.ok());
    EXPECT_FALSE(m->hasUVs());
    EXPECT_EQ(m->joints.size(), 19u);
    EXPECT_GT(m->triangleCount(), 0u);
    EXPECT_TRUE(m->images.empty());
    expectConsistent(*m);
    expectRestReproducesBindAndClipsMove(*m);
}

TEST(GltfLoaderTest, KayKitBarbarian) {
    auto m = loadShared(kBarbarian);
    ASSERT_TRUE(m.ok());
    EXPECT_EQ(m->joints.size(), 41u);
    EXPECT_EQ(m->clips.size(), 76u);
    EXPECT_TRUE(m->hasUVs());
    EXPECT_GT(m->parts.size(), 6u);
    // Rigid attachments (hat, cape, weapons, mug): a single influence on a node that is not a
    // skin joint, positions in rest world space.
    int rigid = 0, skinned = 0;
    for (const MeshPart& p : m->parts) {
        const bool isJoint =
            std::find(m->joints.begin(), m->joints.end(), p.influences[0].node) != m->joints.end();
        if (p.influences.size() == 1 && !isJoint) ++rigid;
        if (p.influences.size() == 41) ++skinned;
    }
    EXPECT_GE(rigid, 5);
    EXPECT_GE(skinned, 6);
    for (const char* name : {"Idle", "Walking_A", "Running_A"})
        EXPECT_GE(m->findClip(name), 0);
    EXPECT_GE(m->findJoint("hand.r"), 0);
    ASSERT_EQ(m->images.size(), 1u);
    EXPECT_GT(m->images[0].width, 0);
    expectConsistent(*m);
    expectRestReproducesBindAndClipsMove(*m);
}

TEST(GltfLoaderTest, RigidAttachmentsFollowTheirJointInAClip) {
    auto m = loadShared(kBarbarian);
    ASSERT_TRUE(m.ok());
    // Every rigid part moves exactly as its node: posed = world(node) · inverse(rest world) · p.
    const int clip = std::max(0, m->findClip("Walking_A"));
    const LocalPose pose =
        sampleClip(*m, clip, m->clips[static_cast<std::size_t>(clip)].duration / 3);
    const auto world = worldMatrices(*m, pose);
    const auto restWorld = worldMatrices(*m, restPose(*m));
    const auto posed = skin(*m, world);
    int checked = 0;
    for (std::size_t p = 0; p < m->parts.size(); ++p) {
        const MeshPart& part = m->parts[p];
        if (part.influences.size() != 1) continue;
        const auto node = static_cast<std::size_t>(part.influences[0].node);
        const glm::mat4 move = world[node] * glm::inverse(restWorld[node]);
        for (std::size_t v = 0; v < part.positions.size(); v += 7) {
            const glm::vec3 expected(move * glm::vec4(part.positions[v], 1.0f));
            ASSERT_LT(glm::length(posed[p].positions[v] - expected), 1e-4f) << part.name;
        }
        ++checked;
    }
    EXPECT_GT(checked, 0);
}

// --- loading rules on hand-built files ----------------------------------------------------------

TEST(GltfLoaderTest, SkinnedTriangle) {
    SkinnedTriangle t;
    auto m = parseModel(t.b.glb());
    ASSERT_TRUE(m.ok()) << m.error().message;
    expectConsistent(*m);
    ASSERT_EQ(m->nodes.size(), 3u);
    EXPECT_EQ(m->nodes[1].parent, 0);
    EXPECT_EQ(m->nodes[2].parent, 0);
    EXPECT_EQ(m->joints, (std::vector<int>{0, 1}));
    ASSERT_EQ(m->parts.size(), 1u);
    const MeshPart& p = m->parts[0];
    EXPECT_EQ(p.name, "tri");
    EXPECT_EQ(p.indices, (std::vector<std::uint32_t>{0, 1, 2}));
    EXPECT_EQ(p.uvs[1], glm::vec2(1, 0));
    EXPECT_EQ(p.weights[2], glm::vec4(0.5f, 0.5f, 0, 0));
    EXPECT_EQ(p.joints[2], glm::u16vec4(0, 1, 0, 0));
    ASSERT_EQ(p.influences.size(), 2u);
    EXPECT_EQ(p.influences[1].node, 1);
    EXPECT_EQ(p.influences[1].inverseBind, glm::mat4(1.0f));
    ASSERT_EQ(m->materials.size(), 1u);
    EXPECT_EQ(m->materials[0].baseColorFactor, glm::vec4(1, 0.5f, 0.25f, 1));
    EXPECT_EQ(m->materials[0].baseColorTexture, -1);
    ASSERT_EQ(m->clips.size(), 1u);
    EXPECT_EQ(m->clips[0].name, "bend");
    EXPECT_FLOAT_EQ(m->clips[0].duration, 1.0f);
    ASSERT_EQ(m->clips[0].channels.size(), 1u);
    EXPECT_EQ(m->clips[0].channels[0].node, 1);
    EXPECT_EQ(m->clips[0].channels[0].path, ChannelPath::Rotation);
}

TEST(GltfLoaderTest, MeshOnPlainNodeIsARigidPartInRestWorldSpace) {
    Builder b;
    const int pos = b.add(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0}, kFloat, "VEC3");
    // Node 1 uses a `matrix`: T(1, 0, 0) · Rz(90°) · S(2), column-major.
    const std::vector<double> matrix = {0, 2, 0, 0, -2, 0, 0, 0, 0, 0, 2, 0, 1, 0, 0, 1};
    b.doc["nodes"] =
        json::array({{{"name", "parent"}, {"translation", {0, 0, 5}}, {"children", {1}}},
                     {{"name", "prop"}, {"matrix", matrix}, {"mesh", 0}}});
    b.doc["meshes"] = json::array({{{"primitives", {{{"attributes", {{"POSITION", pos}}}}}}}});
    auto m = parseModel(b.glb()); // no scenes: every root node
    ASSERT_TRUE(m.ok()) << m.error().message;
    expectConsistent(*m);
    // The matrix is decomposed into TRS.
    const Node& prop = m->nodes[1];
    EXPECT_NEAR(glm::length(prop.translation - glm::vec3(1, 0, 0)), 0.0f, 1e-6f);
    EXPECT_NEAR(glm::length(prop.scale - glm::vec3(2)), 0.0f, 1e-6f);
    const glm::quat rz = glm::angleAxis(glm::radians(90.0f), glm::vec3(0, 0, 1));
    EXPECT_NEAR(std::abs(glm::dot(prop.rotation, rz)), 1.0f, 1e-6f);
    ASSERT_EQ(m->parts.size(), 1u);
    const MeshPart& p = m->parts[0];
    EXPECT_EQ(p.name, "prop"); // unnamed mesh: the node's name
    EXPECT_TRUE(m->joints.empty());
    ASSERT_EQ(p.influences.size(), 1u);
    EXPECT_EQ(p.influences[0].node, 1);
    // Rest world = T(0,0,5)·T(1,0,0)·Rz(90°)·S(2).
    EXPECT_NEAR(glm::length(p.positions[0] - glm::vec3(1, 0, 5)), 0.0f, 1e-5f);
    EXPECT_NEAR(glm::length(p.positions[1] - glm::vec3(1, 2, 5)), 0.0f, 1e-5f);
    EXPECT_NEAR(glm::length(p.positions[2] - glm::vec3(-1, 0, 5)), 0.0f, 1e-5f);
    // No NORMAL: computed (+z locally, still +z after Rz), no UVs.
    EXPECT_NEAR(glm::length(p.normals[0] - glm::vec3(0, 0, 1)), 0.0f, 1e-5f);
    EXPECT_TRUE(p.uvs.empty());
    EXPECT_FALSE(m->hasUVs());
    EXPECT_EQ(p.joints[0], glm::u16vec4(0));
    EXPECT_EQ(p.weights[0], glm::vec4(1, 0, 0, 0));
    // Posing the parent moves the part rigidly.
    LocalPose pose = restPose(*m);
    pose.translation[0] = {0, 0, 6};
    const auto posed = skin(*m, worldMatrices(*m, pose));
    EXPECT_NEAR(glm::length(posed[0].positions[1] - glm::vec3(1, 2, 6)), 0.0f, 1e-5f);
}

TEST(GltfLoaderTest, InterleavedNormalizedAndMultiSetAttributes) {
    Builder b;
    // Interleaved view, stride 16: POSITION (3 floats) + TEXCOORD_0 (2 normalised u16).
    struct Vertex {
        float p[3];
        std::uint16_t uv[2];
    };
    const std::vector<Vertex> verts = {{{0, 0, 0}, {0, 0}},
                                       {{1, 0, 0}, {65535, 0}},
                                       {{0, 1, 0}, {0, 65535}},
                                       {{1, 1, 0}, {32768, 65535}}};
    const int v = b.view(bytesOf(verts), 16);
    const int pos = b.accessor(v, kFloat, "VEC3", 4);
    const int uv = b.accessor(v, kUShort, "VEC2", 4, 12, true);
    const int j0 = b.add(std::vector<std::uint8_t>{0, 0, 0, 0, 1, 7, 0, 0, 0, 0, 0, 0, 0, 1, 0, 1},
                         kUByte, "VEC4");
    // Normalised u8 weights; vertex 1 has joint 7 with weight 0 (ignored); vertex 2 no weight.
    const int w0 =
        b.add(std::vector<std::uint8_t>{255, 0, 0, 0, 128, 0, 127, 0, 0, 0, 0, 0, 10, 20, 30, 40},
              kUByte, "VEC4", true);
    // A second set: vertex 3 gets a fifth weight; the four largest are kept.
    const int j1 = b.add(std::vector<std::uint16_t>(16, 1), kUShort, "VEC4");
    const int w1 =
        b.add(std::vector<float>{0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 50, 0, 0, 0}, kFloat, "VEC4");
    // Triangle strip (0, 1, 2, 3) → (0, 1, 2), (1, 3, 2) (glTF 2.0 §3.7.2.1).
    b.doc["nodes"] = json::array(
        {{{"name", "j0"}, {"children", {1}}}, {{"name", "j1"}}, {{"mesh", 0}, {"skin", 0}}});
    b.doc["scenes"] = json::array({{{"nodes", {0, 2}}}});
    b.doc["skins"] = json::array({{{"joints", {0, 1}}}}); // no inverseBindMatrices: identity
    b.doc["meshes"] = json::array({{{"primitives",
                                     {{{"attributes",
                                        {{"POSITION", pos},
                                         {"TEXCOORD_0", uv},
                                         {"JOINTS_0", j0},
                                         {"WEIGHTS_0", w0},
                                         {"JOINTS_1", j1},
                                         {"WEIGHTS_1", w1}}},
                                       {"mode", 5}}}}}});
    auto m = parseModel(b.glb());
    ASSERT_TRUE(m.ok()) << m.error().message;
    expectConsistent(*m);
    const MeshPart& p = m->parts[0];
    EXPECT_EQ(p.positions[3], glm::vec3(1, 1, 0));
    EXPECT_FLOAT_EQ(p.uvs[1].x, 1.0f);
    EXPECT_FLOAT_EQ(p.uvs[3].x, 32768.0f / 65535.0f);
    EXPECT_EQ(p.indices, (std::vector<std::uint32_t>{0, 1, 2, 1, 3, 2}));
    EXPECT_EQ(p.weights[0], glm::vec4(1, 0, 0, 0));
    EXPECT_NEAR(p.weights[1].x, 128.0f / 255.0f, 1e-6f);
    EXPECT_NEAR(p.weights[1].y, 127.0f / 255.0f, 1e-6f);
    EXPECT_EQ(p.joints[1].x, 1);
    EXPECT_EQ(p.joints[1].y, 0); // slot 3 of the file (joint 0) — joint 7 had no weight
    EXPECT_EQ(p.weights[2], glm::vec4(1, 0, 0, 0)); // no weight at all → influence 0
    EXPECT_EQ(p.joints[2], glm::u16vec4(0));
    // Vertex 3: weights 10, 20, 30, 40 (/255) and 50 → keep 50, 40/255, 30/255, 20/255.
    const float w50 = 50.0f, w40 = 40.0f / 255, w30 = 30.0f / 255, w20 = 20.0f / 255;
    const float sum = w50 + w40 + w30 + w20;
    EXPECT_NEAR(p.weights[3].x, w50 / sum, 1e-6f);
    EXPECT_NEAR(p.weights[3].y, w40 / sum, 1e-6f);
    EXPECT_NEAR(p.weights[3].z, w30 / sum, 1e-6f);
    EXPECT_NEAR(p.weights[3].w, w20 / sum, 1e-6f);
    EXPECT_EQ(p.joints[3], glm::u16vec4(1, 1, 0, 1));
    EXPECT_EQ(p.influences[0].inverseBind, glm::mat4(1.0f));
}

TEST(GltfLoaderTest, SparseAccessorsAndZeroFilledAccessors) {
    Builder b;
    // Base positions + a sparse substitution of vertex 2.
    const int pos = b.add(std::vector<float>{0, 0, 0, 1, 0, 0, 9, 9, 9}, kFloat, "VEC3");
    const int sIdx = b.view(bytesOf(std::vector<std::uint16_t>{2, 0}));
    const int sVal = b.view(bytesOf(std::vector<float>{0, 1, 0}));
    b.doc["accessors"][static_cast<std::size_t>(pos)]["sparse"] = {
        {"count", 1},
        {"indices", {{"bufferView", sIdx}, {"componentType", kUShort}}},
        {"values", {{"bufferView", sVal}}}};
    // TEXCOORD_0 without a buffer view: all zeros.
    const int uv = b.accessor(-1, kFloat, "VEC2", 3);
    b.doc["nodes"] = json::array({{{"mesh", 0}}});
    b.doc["meshes"] = json::array(
        {{{"primitives", {{{"attributes", {{"POSITION", pos}, {"TEXCOORD_0", uv}}}}}}}});
    auto m = parseModel(b.glb());
    ASSERT_TRUE(m.ok()) << m.error().message;
    EXPECT_EQ(m->parts[0].positions[2], glm::vec3(0, 1, 0));
    EXPECT_EQ(m->parts[0].uvs[2], glm::vec2(0));
    // A sparse index past the accessor's count is refused.
    const auto sIdxOffset = b.doc["bufferViews"][static_cast<std::size_t>(sIdx)]["byteOffset"];
    b.bin[sIdxOffset.get<std::size_t>()] = 3; // first sparse index: 2 → 3
    auto bad = parseGltf(b.glb(), "");
    ASSERT_FALSE(bad.ok());
    EXPECT_EQ(bad.error().field, "/meshes/0/primitives/0/attributes/POSITION");
}

TEST(GltfLoaderTest, StepAndCubicSplineClipsAndSkippedMorphChannels) {
    SkinnedTriangle t;
    const int times = t.b.add(std::vector<float>{0, 2}, kFloat, "SCALAR");
    const int steps = t.b.add(std::vector<float>{1, 1, 1, 2, 2, 2}, kFloat, "VEC3");
    // CUBICSPLINE: per key in-tangent, value, out-tangent.
    const int cubic = t.b.add(
        std::vector<float>{0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 2, 0, 1, 1, 0, 0, 0, 0}, kFloat, "VEC3");
    const int weights = t.b.add(std::vector<float>{0, 1}, kFloat, "SCALAR");
    t.b.doc["animations"].push_back(
        {{"samplers",
          {{{"input", times}, {"output", steps}, {"interpolation", "STEP"}},
           {{"input", times}, {"output", cubic}, {"interpolation", "CUBICSPLINE"}},
           {{"input", times}, {"output", weights}}}},
         {"channels",
          {{{"sampler", 0}, {"target", {{"node", 1}, {"path", "scale"}}}},
           {{"sampler", 1}, {"target", {{"node", 0}, {"path", "translation"}}}},
           {{"sampler", 2}, {"target", {{"node", 2}, {"path", "weights"}}}}}}});
    auto m = parseModel(t.b.glb());
    ASSERT_TRUE(m.ok()) << m.error().message;
    expectConsistent(*m);
    ASSERT_EQ(m->clips.size(), 2u);
    const Clip& c = m->clips[1];
    EXPECT_EQ(c.name, "animation1"); // unnamed
    EXPECT_FLOAT_EQ(c.duration, 2.0f);
    ASSERT_EQ(c.channels.size(), 2u); // the morph "weights" channel is skipped
    EXPECT_EQ(c.channels[0].interpolation, Interpolation::Step);
    EXPECT_EQ(c.channels[1].interpolation, Interpolation::CubicSpline);
    const LocalPose pose = sampleClip(*m, 1, 1.0f);
    EXPECT_EQ(pose.scale[1], glm::vec3(1));
    // Hermite at u = 0.5, td = 2 (see RigTest): (0.75, 0, 0).
    EXPECT_NEAR(glm::length(pose.translation[0] - glm::vec3(0.75f, 0, 0)), 0.0f, 1e-6f);
}

TEST(GltfLoaderTest, EmbeddedBaseColorTextureIsDecodedInStepTwo) {
    TempDir dir;
    const std::vector<std::uint8_t> px = {255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255};
    writeImage(dir / "tex.png", 2, 2, 3, px, OIIO::TypeDesc::UINT8);
    SkinnedTriangle t;
    const int view = t.b.view(readBytes(dir / "tex.png"));
    t.b.doc["images"] = json::array({{{"bufferView", view}, {"mimeType", "image/png"}}});
    t.b.doc["textures"] = json::array({{{"source", 0}}});
    t.b.doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
    auto parsed = parseGltf(t.b.glb(), "");
    ASSERT_TRUE(parsed.ok()) << parsed.error().message;
    // Step 1 captures the encoded bytes only.
    ASSERT_EQ(parsed->images.entries.size(), 1u);
    EXPECT_EQ(parsed->images.entries[0].imageIndex, 0);
    EXPECT_EQ(parsed->images.entries[0].mimeType, "image/png");
    ASSERT_EQ(parsed->model.images.size(), 1u);
    EXPECT_EQ(parsed->model.images[0].width, 0);
    // Step 2 decodes them to RGBA8.
    ASSERT_TRUE(loadGltfResources(*parsed).ok());
    const Image8& img = parsed->model.images[0];
    ASSERT_EQ(img.width, 2);
    ASSERT_EQ(img.height, 2);
    EXPECT_EQ(img.rgba, (std::vector<std::uint8_t>{255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255,
                                                   255, 255, 255, 255}));
    EXPECT_EQ(parsed->model.materials[0].baseColorTexture, 0);

    // A corrupt image fails step 2, naming the image.
    SkinnedTriangle bad;
    const int garbage = bad.b.view(std::vector<std::uint8_t>(64, 0x5a));
    bad.b.doc["images"] = json::array({{{"bufferView", garbage}, {"mimeType", "image/png"}}});
    bad.b.doc["textures"] = json::array({{{"source", 0}}});
    bad.b.doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
    auto p2 = parseGltf(bad.b.glb(), "");
    ASSERT_TRUE(p2.ok()) << p2.error().message;
    auto s = loadGltfResources(*p2);
    ASSERT_FALSE(s.ok());
    EXPECT_EQ(s.error().field, "/images/0");
}

TEST(GltfLoaderTest, ExternalFilesOnlyFromTheModelsFolder) {
    TempDir dir;
    SkinnedTriangle t;
    std::filesystem::create_directories(dir / "model");
    writeBytes(dir / "model/tri.bin", t.b.bin);
    writeBytes(dir / "secret.bin", t.b.bin);
    auto gltf = [&](const std::string& uri) {
        json d = t.b.doc;
        d["buffers"] = json::array({{{"byteLength", t.b.bin.size()}, {"uri", uri}}});
        return d.dump(1);
    };
    writeText(dir / "model/ok.gltf", gltf("tri.bin"));
    auto ok = loadGltfFile(dir / "model/ok.gltf");
    ASSERT_TRUE(ok.ok()) << ok.error().message;
    EXPECT_EQ(ok->triangleCount(), 1u);

    for (const std::string& uri : {std::string("../secret.bin"), dir / "secret.bin",
                                   std::string("%2e%2e/secret.bin"), std::string("missing.bin")}) {
        writeText(dir / "model/bad.gltf", gltf(uri));
        auto bad = loadGltfFile(dir / "model/bad.gltf");
        EXPECT_FALSE(bad.ok()) << uri;
    }
    // From memory without a folder: no file access at all.
    const std::string text = gltf("tri.bin");
    EXPECT_FALSE(parseGltf(std::vector<std::uint8_t>(text.begin(), text.end()), "").ok());
    EXPECT_TRUE(parseGltf(std::vector<std::uint8_t>(text.begin(), text.end()), dir / "model").ok());

    auto missing = loadGltfFile(dir / "nope.glb");
    ASSERT_FALSE(missing.ok());
    EXPECT_EQ(missing.error().code, ErrorCode::NotFound);
}

TEST(GltfLoaderTest, FilesInMemoryResolveOnlyToEachOther) {
    TempDir dir;
    SkinnedTriangle t;
    const std::vector<std::uint8_t> px = {255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255};
    writeImage(dir / "tex.png", 2, 2, 3, px, OIIO::TypeDesc::UINT8);
    writeBytes(dir / "secret.bin", t.b.bin); // on disk beside the process: must never be read
    auto gltf = [&](const std::string& bufferUri, const std::string& imageUri) {
        json d = t.b.doc;
        d["buffers"] = json::array({{{"byteLength", t.b.bin.size()}, {"uri", bufferUri}}});
        d["images"] = json::array({{{"uri", imageUri}}});
        d["textures"] = json::array({{{"source", 0}}});
        d["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
        const std::string text = d.dump(1);
        return std::vector<std::uint8_t>(text.begin(), text.end());
    };
    GltfFiles files = {{"my model.gltf", gltf("tri%20data.bin", "tex.png")},
                       {"tri data.bin", t.b.bin},
                       {"tex.png", readBytes(dir / "tex.png")}};
    auto ok = loadGltfFromFiles(files, "my model.gltf");
    ASSERT_TRUE(ok) << ok.error().message;
    EXPECT_EQ(ok->triangleCount(), 1u);
    ASSERT_EQ(ok->images.size(), 1u);
    EXPECT_EQ(ok->images[0].width, 2); // step two ran: the texture is decoded

    for (const std::string& uri :
         {std::string("../secret.bin"), dir / "secret.bin", std::string("%2e%2e/secret.bin"),
          std::string("sub/tri data.bin"), std::string("missing.bin"), std::string("./../tri data.bin")}) {
        GltfFiles bad = files;
        bad["bad.gltf"] = gltf(uri, "tex.png");
        auto r = loadGltfFromFiles(bad, "bad.gltf");
        ASSERT_FALSE(r) << uri;
        EXPECT_EQ(r.error().code, ErrorCode::Parse) << uri;
        EXPECT_NE(r.error().message.find("bad.gltf"), std::string::npos) << r.error().message;
    }
    auto noMain = loadGltfFromFiles(files, "other.gltf");
    ASSERT_FALSE(noMain);
    EXPECT_EQ(noMain.error().code, ErrorCode::NotFound);
    EXPECT_EQ(noMain.error().field, "other.gltf");
}
