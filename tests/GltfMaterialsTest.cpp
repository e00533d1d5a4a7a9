// GltfMaterialsTest — glTF 2.0 metallic-roughness materials in (server/io/gltf_convert.cpp →
// core/model.hpp Material): the Khronos material models vendored in tests/models/fidelity
// (DamagedHelmet: normal, ORM, emissive; AlphaBlendModeTest: alpha modes; NormalTangentMirrorTest:
// mirrored tangents), and hand-built files for KHR_texture_transform, TEXCOORD_1, COLOR_0,
// KHR_materials_unlit and KHR_materials_emissive_strength. Reads the vendored models.
#include "GltfTestBuilder.hpp"

#include <glm/gtc/matrix_transform.hpp>

using namespace dermis;
using namespace dermis::test;
using namespace dermis::test::gltf;

namespace {

const std::string kFidelity = kModels + "fidelity/";

const Material* materialNamed(const Model& m, const std::string& name) {
    for (const Material& mat : m.materials)
        if (mat.name == name) return &mat;
    return nullptr;
}

} // namespace

TEST(GltfMaterialsTest, DamagedHelmetHasEveryTextureOfItsMaterial) {
    auto m = loadGltfFile(kFidelity + "DamagedHelmet/DamagedHelmet.glb");
    ASSERT_TRUE(m.ok()) << m.error().message;
    ASSERT_EQ(m->materials.size(), 1u);
    const Material& mat = m->materials[0];
    for (int t : {mat.baseColorTexture, mat.metallicRoughnessTexture, mat.normalTexture,
                  mat.occlusionTexture, mat.emissiveTexture}) {
        ASSERT_GE(t, 0);
        ASSERT_LT(static_cast<std::size_t>(t), m->images.size());
        EXPECT_GT(m->images[static_cast<std::size_t>(t)].width, 0);
    }
    EXPECT_EQ(mat.emissiveFactor, glm::vec3(1.0f));
    EXPECT_EQ(mat.metallicFactor, 1.0f);
    EXPECT_EQ(mat.roughnessFactor, 1.0f);
    EXPECT_EQ(mat.alphaMode, AlphaMode::Opaque);
    EXPECT_FALSE(mat.unlit);
    // No TANGENT in the file but a normal map: MikkTSpace tangents generated on load
    // (TangentsTest checks their values).
    for (const MeshPart& p : m->parts) {
        EXPECT_TRUE(p.tangentsGenerated);
        EXPECT_EQ(p.tangents.size(), p.positions.size());
    }
}

TEST(GltfMaterialsTest, AlphaModesAndCutoffs) {
    auto m = loadGltfFile(kFidelity + "AlphaBlendModeTest/AlphaBlendModeTest.glb");
    ASSERT_TRUE(m.ok()) << m.error().message;
    const Material* blend = materialNamed(*m, "MatBlend");
    const Material* c25 = materialNamed(*m, "MatCutoff25");
    const Material* c75 = materialNamed(*m, "MatCutoff75");
    const Material* cdef = materialNamed(*m, "MatCutoffDefault");
    const Material* opaque = materialNamed(*m, "MatOpaque");
    ASSERT_TRUE(blend && c25 && c75 && cdef && opaque);
    EXPECT_EQ(blend->alphaMode, AlphaMode::Blend);
    EXPECT_EQ(c25->alphaMode, AlphaMode::Mask);
    EXPECT_FLOAT_EQ(c25->alphaCutoff, 0.25f);
    EXPECT_FLOAT_EQ(c75->alphaCutoff, 0.75f);
    EXPECT_FLOAT_EQ(cdef->alphaCutoff, 0.5f);
    EXPECT_EQ(opaque->alphaMode, AlphaMode::Opaque);
    EXPECT_TRUE(blend->doubleSided);
    // The file's TANGENTs are read: unit xyz, w ±1.
    std::size_t withTangents = 0;
    for (const MeshPart& p : m->parts) {
        if (p.tangents.empty()) continue;
        ++withTangents;
        ASSERT_EQ(p.tangents.size(), p.positions.size());
        for (const glm::vec4& t : p.tangents) {
            EXPECT_NEAR(glm::length(glm::vec3(t)), 1.0f, 1e-4f);
            EXPECT_EQ(std::abs(t.w), 1.0f);
        }
    }
    EXPECT_GT(withTangents, 0u);
}

TEST(GltfMaterialsTest, MirroredTangentsKeepTheirSign) {
    auto m = loadGltfFile(kFidelity + "NormalTangentMirrorTest/NormalTangentMirrorTest.glb");
    ASSERT_TRUE(m.ok()) << m.error().message;
    std::size_t positive = 0, negative = 0;
    for (const MeshPart& p : m->parts)
        for (const glm::vec4& t : p.tangents)
            (t.w > 0.0f ? positive : negative) += 1;
    EXPECT_GT(positive, 0u);
    EXPECT_GT(negative, 0u) << "the mirrored half has w = −1";
    ASSERT_FALSE(m->materials.empty());
    EXPECT_GE(m->materials[0].normalTexture, 0);
    EXPECT_TRUE(m->materials[0].doubleSided);
}

TEST(GltfMaterialsTest, TextureTransformUvSetsColoursAndExtensions) {
    SkinnedTriangle t;
    const std::vector<std::uint8_t> px = {255, 0, 0, 255};
    const int uv1 = t.b.add(std::vector<float>{0.5f, 0.5f, 1, 0.5f, 0.5f, 1}, kFloat, "VEC2");
    const int color =
        t.b.add(std::vector<std::uint8_t>{255, 0, 0, 0, 255, 0, 0, 0, 255}, kUByte, "VEC3");
    t.b.doc["accessors"][static_cast<std::size_t>(color)]["normalized"] = true;
    json& prim = t.b.doc["meshes"][0]["primitives"][0];
    prim["attributes"]["TEXCOORD_1"] = uv1;
    prim["attributes"]["COLOR_0"] = color;
    TempDir dir;
    writeImage(dir / "tex.png", 1, 1, 4, px, OIIO::TypeDesc::UINT8);
    const int view = t.b.view(readBytes(dir / "tex.png"));
    t.b.doc["images"] = json::array({{{"bufferView", view}, {"mimeType", "image/png"}}});
    t.b.doc["textures"] = json::array({{{"source", 0}}});
    json& mat = t.b.doc["materials"][0];
    mat["pbrMetallicRoughness"]["baseColorTexture"] = {
        {"index", 0},
        {"extensions",
         {{"KHR_texture_transform",
           {{"offset", {0, 1}}, {"rotation", 1.57079632679}, {"scale", {0.5, 0.5}}}}}}};
    mat["pbrMetallicRoughness"]["metallicFactor"] = 0.25;
    mat["pbrMetallicRoughness"]["roughnessFactor"] = 0.5;
    mat["normalTexture"] = {{"index", 0}, {"texCoord", 1}, {"scale", 0.75}};
    mat["occlusionTexture"] = {{"index", 0}, {"strength", 0.5}};
    mat["emissiveTexture"] = {{"index", 0}, {"texCoord", 2}}; // TEXCOORD_2: not read
    mat["emissiveFactor"] = {0.5, 0.25, 1};
    mat["extensions"] = {{"KHR_materials_emissive_strength", {{"emissiveStrength", 4}}},
                         {"KHR_materials_unlit", json::object()}};
    mat["alphaMode"] = "MASK";
    mat["alphaCutoff"] = 0.3;
    mat["doubleSided"] = true;
    auto parsed = parseGltf(t.b.glb(), "");
    ASSERT_TRUE(parsed.ok()) << parsed.error().message;
    const Model& m = parsed->model;
    const Material& got = m.materials[0];
    EXPECT_EQ(got.baseColorTexture, 0);
    EXPECT_EQ(got.baseColorUv.offset, glm::vec2(0, 1));
    EXPECT_EQ(got.baseColorUv.scale, glm::vec2(0.5f));
    EXPECT_NEAR(got.baseColorUv.rotation, 1.5707964f, 1e-6f);
    // The extension's example: the lower-left quadrant, rotated clockwise 90°: uv (1, 0) → (0,
    // 0.5), (0, 1) → (0.5, 1).
    const glm::mat3 x = got.baseColorUv.matrix();
    const glm::vec3 a = x * glm::vec3(1, 0, 1), b = x * glm::vec3(0, 1, 1);
    EXPECT_NEAR(a.x, 0.0f, 1e-6f);
    EXPECT_NEAR(a.y, 0.5f, 1e-6f);
    EXPECT_NEAR(b.x, 0.5f, 1e-6f);
    EXPECT_NEAR(b.y, 1.0f, 1e-6f);
    EXPECT_EQ(got.metallicFactor, 0.25f);
    EXPECT_EQ(got.roughnessFactor, 0.5f);
    EXPECT_EQ(got.normalTexture, 0);
    EXPECT_EQ(got.normalUv.texCoord, 1);
    EXPECT_EQ(got.normalScale, 0.75f);
    EXPECT_EQ(got.occlusionStrength, 0.5f);
    EXPECT_EQ(got.emissiveTexture, -1);
    EXPECT_EQ(got.emissiveFactor, glm::vec3(2, 1, 4)); // × emissiveStrength
    EXPECT_TRUE(got.unlit);
    EXPECT_EQ(got.alphaMode, AlphaMode::Mask);
    EXPECT_FLOAT_EQ(got.alphaCutoff, 0.3f);
    EXPECT_TRUE(got.doubleSided);
    ASSERT_EQ(m.parts.size(), 1u);
    ASSERT_EQ(m.parts[0].uvs1.size(), 3u);
    EXPECT_EQ(m.parts[0].uvs1[1], glm::vec2(1, 0.5f));
    ASSERT_EQ(m.parts[0].colors.size(), 3u);
    EXPECT_EQ(m.parts[0].colors[1], glm::vec4(0, 1, 0, 1));
}

TEST(GltfMaterialsTest, BadMaterialValuesNameTheirField) {
    struct Case {
        const char* what;
        json patch;
        std::string field;
    };
    const std::vector<Case> cases = {
        {"alpha mode", {{"alphaMode", "GLASS"}}, "/materials/0/alphaMode"},
        {"emissive factor", {{"emissiveFactor", {1, 1, 1e39}}}, "/materials/0/emissiveFactor"},
        {"emissive strength",
         {{"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", -1}}}}}},
         "/materials/0/extensions/KHR_materials_emissive_strength/emissiveStrength"},
        {"transform offset",
         {{"pbrMetallicRoughness",
           {{"baseColorTexture",
             {{"index", 0}, {"extensions", {{"KHR_texture_transform", {{"offset", {1}}}}}}}}}}},
         "/materials/0/pbrMetallicRoughness/baseColorTexture/extensions/KHR_texture_transform/"
         "offset"},
    };
    for (const Case& c : cases) {
        SkinnedTriangle t;
        TempDir dir;
        writeImage(dir / "tex.png", 1, 1, 4, std::vector<std::uint8_t>{1, 2, 3, 4},
                   OIIO::TypeDesc::UINT8);
        const int view = t.b.view(readBytes(dir / "tex.png"));
        t.b.doc["images"] = json::array({{{"bufferView", view}, {"mimeType", "image/png"}}});
        t.b.doc["textures"] = json::array({{{"source", 0}}});
        t.b.doc["materials"][0].merge_patch(c.patch);
        auto parsed = parseGltf(t.b.glb(), "");
        ASSERT_FALSE(parsed.ok()) << c.what;
        EXPECT_EQ(parsed.error().field, c.field) << c.what << ": " << parsed.error().message;
    }
}

TEST(GltfMaterialsTest, RigidTangentsFollowTheNodeAndAMirrorFlipsTheirSign) {
    SkinnedTriangle t;
    const int tangent =
        t.b.add(std::vector<float>{1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1}, kFloat, "VEC4");
    json& d = t.b.doc;
    d["meshes"][0]["primitives"][0]["attributes"]["TANGENT"] = tangent;
    d["meshes"][0]["primitives"][0]["attributes"].erase("JOINTS_0");
    d["meshes"][0]["primitives"][0]["attributes"].erase("WEIGHTS_0");
    d["nodes"][2].erase("skin");
    d["nodes"][2]["scale"] = {-1, 1, 1}; // a mirror
    auto parsed = parseGltf(t.b.glb(), "");
    ASSERT_TRUE(parsed.ok()) << parsed.error().message;
    const MeshPart& p = parsed->model.parts[0];
    ASSERT_EQ(p.tangents.size(), 3u);
    EXPECT_NEAR(p.tangents[0].x, -1.0f, 1e-6f);
    EXPECT_EQ(p.tangents[0].w, -1.0f);
}
