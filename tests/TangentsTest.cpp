// TangentsTest — MikkTSpace tangent frames (core/tangents.hpp) and their use by the glTF loader:
//   * a flat quad: +u is the tangent, the bitangent w·(n × t) points to the image's up; a mirrored
//     UV mapping flips w; tangents are unit and perpendicular to the normal;
//   * a strip whose two halves mirror each other across shared vertices: the seam's vertices are
//     split, every per-vertex array (joints, weights, colours, morph deltas) copied with them;
//   * the two vendored Khronos models whose files carry TANGENT (baked by MikkTSpace in their
//     authoring tools): tangents generated from their positions, normals and UVs agree with the
//     file's (mean direction within 0.5°, the same sign);
//   * the loader generates them for a normal-mapped primitive without TANGENT (DamagedHelmet),
//     not for one without a normal map (CesiumMan); errors name the missing input.
#include "BuildPaths.hpp"

#include "core/tangents.hpp"
#include "io/gltf_loader.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <string>

using namespace dermis;

namespace {

const std::string kModels = dermis::build::testModelsDir();

/// An n×1 strip of quads in the z = 0 plane (normal +z), x from 0 to n, y from 0 to 1, with glTF
/// UVs (v down): u = uOf(x), v = 1 − y.
MeshPart strip(int n, float (*uOf)(float)) {
    MeshPart p;
    for (int x = 0; x <= n; ++x)
        for (int y = 0; y <= 1; ++y) {
            p.positions.emplace_back(float(x), float(y), 0.0f);
            p.normals.emplace_back(0.0f, 0.0f, 1.0f);
            p.uvs.emplace_back(uOf(float(x)), 1.0f - float(y));
        }
    for (int x = 0; x < n; ++x) {
        const std::uint32_t a = 2 * x, b = 2 * x + 2, c = 2 * x + 3, d = 2 * x + 1; // CCW from +z
        p.indices.insert(p.indices.end(), {a, b, c, a, c, d});
    }
    return p;
}

float identityU(float x) { return x / 4.0f; }
float mirroredU(float x) { return 1.0f - x / 4.0f; }
float foldedU(float x) { return std::abs(x - 2.0f) / 2.0f; } // mirrored about x = 2

void expectFrame(const MeshPart& p, std::size_t v, glm::vec3 t, float w) {
    ASSERT_LT(v, p.tangents.size());
    EXPECT_NEAR(glm::length(glm::vec3(p.tangents[v]) - t), 0.0f, 1e-5f) << "vertex " << v;
    EXPECT_EQ(p.tangents[v].w, w) << "vertex " << v;
}

/// Mean angle (degrees) between two tangent sets and the share of equal signs.
std::pair<double, double> agreement(const std::vector<glm::vec4>& a, const std::vector<glm::vec4>& b) {
    double angle = 0.0;
    std::size_t same = 0;
    for (std::size_t v = 0; v < a.size(); ++v) {
        angle += std::acos(std::clamp(double(glm::dot(glm::vec3(a[v]), glm::vec3(b[v]))), -1.0, 1.0));
        same += a[v].w == b[v].w;
    }
    return {angle / double(a.size()) * 180.0 / 3.14159265358979, double(same) / double(a.size())};
}

} // namespace

TEST(TangentsTest, AFlatQuadsTangentIsPlusUAndItsBitangentTheImagesUp) {
    MeshPart p = strip(4, identityU);
    ASSERT_TRUE(generateTangents(p));
    ASSERT_EQ(p.tangents.size(), p.positions.size());
    for (std::size_t v = 0; v < p.positions.size(); ++v) expectFrame(p, v, {1, 0, 0}, 1.0f);

    MeshPart m = strip(4, mirroredU); // u grows towards −x: t = −x; the image's up is still +y
    ASSERT_TRUE(generateTangents(m));
    for (std::size_t v = 0; v < m.positions.size(); ++v) {
        expectFrame(m, v, {-1, 0, 0}, -1.0f);
        const glm::vec3 b = m.tangents[v].w * glm::cross(m.normals[v], glm::vec3(m.tangents[v]));
        EXPECT_NEAR(b.y, 1.0f, 1e-5f);
    }
}

TEST(TangentsTest, ATiltedNormalGetsAPerpendicularTangent) {
    MeshPart p = strip(2, identityU);
    for (glm::vec3& n : p.normals) n = glm::normalize(glm::vec3(0.3f, 0.2f, 1.0f));
    ASSERT_TRUE(generateTangents(p));
    for (std::size_t v = 0; v < p.positions.size(); ++v) {
        EXPECT_NEAR(glm::length(glm::vec3(p.tangents[v])), 1.0f, 1e-5f);
        EXPECT_NEAR(glm::dot(glm::vec3(p.tangents[v]), p.normals[v]), 0.0f, 1e-5f);
        EXPECT_GT(p.tangents[v].x, 0.9f);
    }
}

TEST(TangentsTest, AMirrorSeamThroughSharedVerticesSplitsThem) {
    MeshPart p = strip(4, foldedU);
    const std::size_t before = p.positions.size(); // 10
    p.colors.assign(before, glm::vec4(1.0f));
    p.joints.assign(before, glm::u16vec4(0));
    p.weights.assign(before, glm::vec4(1, 0, 0, 0));
    for (std::size_t v = 0; v < before; ++v) p.joints[v].x = static_cast<std::uint16_t>(v);
    MorphTarget target;
    target.weight = 0;
    for (std::size_t v = 0; v < before; ++v) target.positions.emplace_back(0.0f, 0.0f, float(v));
    p.morphs = {target};
    ASSERT_TRUE(generateTangents(p));
    // The two vertices on x = 2 take part in both halves: each gets one copy.
    ASSERT_EQ(p.positions.size(), before + 2);
    EXPECT_EQ(p.normals.size(), p.positions.size());
    EXPECT_EQ(p.uvs.size(), p.positions.size());
    EXPECT_EQ(p.colors.size(), p.positions.size());
    EXPECT_EQ(p.weights.size(), p.positions.size());
    EXPECT_EQ(p.morphs[0].positions.size(), p.positions.size());
    EXPECT_TRUE(p.morphs[0].tangents.empty());
    for (std::size_t k = before; k < p.positions.size(); ++k) {
        const std::size_t original = p.joints[k].x; // the copy carries its source's attributes
        EXPECT_EQ(p.positions[k], p.positions[original]);
        EXPECT_EQ(p.morphs[0].positions[k].z, float(original));
        EXPECT_EQ(p.positions[k].x, 2.0f);
    }
    // Every triangle now sees one frame: left half u grows towards −x, right half towards +x.
    for (std::size_t c = 0; c < p.indices.size(); ++c) {
        const std::size_t tri = c / 3;
        const bool left = tri < 4;
        const glm::vec4 t = p.tangents[p.indices[c]];
        EXPECT_EQ(t.x, left ? -1.0f : 1.0f) << "corner " << c;
        EXPECT_EQ(t.w, left ? -1.0f : 1.0f) << "corner " << c;
    }
}

TEST(TangentsTest, GeneratedTangentsAgreeWithTheFilesOfTheKhronosModels) {
    for (const std::string rel : {"/fidelity/NormalTangentMirrorTest/NormalTangentMirrorTest.glb",
                                  "/fidelity/AlphaBlendModeTest/AlphaBlendModeTest.glb"}) {
        auto m = loadGltfFile(kModels + rel);
        ASSERT_TRUE(m) << m.error().message;
        std::size_t compared = 0;
        for (const MeshPart& part : m->parts) {
            ASSERT_FALSE(part.tangentsGenerated) << rel;
            if (part.tangents.empty() || part.uvs.empty()) continue;
            // Regenerated in the part's own space: rigid parts are in rest world space, where
            // MikkTSpace gives the same frame for a rotation and uniform scale.
            auto corners = cornerTangents(part.positions, part.normals, part.uvs, part.indices);
            ASSERT_TRUE(corners) << corners.error().message;
            std::vector<glm::vec4> file, ours;
            for (std::size_t c = 0; c < part.indices.size(); ++c) {
                file.push_back(part.tangents[part.indices[c]]);
                ours.push_back((*corners)[c]);
            }
            const auto [angle, sameSign] = agreement(ours, file);
            EXPECT_LT(angle, 0.5) << rel << " " << part.name;
            EXPECT_GT(sameSign, 0.99) << rel << " " << part.name;
            std::cout << rel << " " << part.name << ": mean angle " << angle << "°, same sign "
                      << sameSign * 100.0 << " % over " << file.size() << " corners\n";
            compared += file.size();
        }
        EXPECT_GT(compared, 100u) << rel;
    }
}

TEST(TangentsTest, TheLoaderGeneratesThemForANormalMappedPrimitiveWithout) {
    auto helmet = loadGltfFile(kModels + "/fidelity/DamagedHelmet/DamagedHelmet.glb");
    ASSERT_TRUE(helmet) << helmet.error().message;
    ASSERT_EQ(helmet->parts.size(), 1u);
    const MeshPart& p = helmet->parts[0];
    EXPECT_TRUE(p.tangentsGenerated);
    ASSERT_EQ(p.tangents.size(), p.positions.size());
    for (std::size_t v = 0; v < p.tangents.size(); ++v) {
        ASSERT_NEAR(glm::length(glm::vec3(p.tangents[v])), 1.0f, 1e-3f) << v;
        ASSERT_NEAR(glm::dot(glm::vec3(p.tangents[v]), p.normals[v]), 0.0f, 1e-3f) << v;
        ASSERT_TRUE(p.tangents[v].w == 1.0f || p.tangents[v].w == -1.0f) << v;
    }

    auto cesium = loadGltfFile(kModels + "/CesiumMan/CesiumMan.glb"); // no normal map
    ASSERT_TRUE(cesium);
    for (const MeshPart& part : cesium->parts) {
        EXPECT_FALSE(part.tangentsGenerated);
        EXPECT_TRUE(part.tangents.empty());
    }
}

TEST(TangentsTest, MissingInputsAreNamed) {
    MeshPart p = strip(1, identityU);
    p.normals.pop_back();
    const MeshPart before = p;
    auto s = generateTangents(p);
    ASSERT_FALSE(s);
    EXPECT_EQ(s.error().code, ErrorCode::InvalidArgument);
    EXPECT_EQ(s.error().field, "normals");
    EXPECT_EQ(p.positions.size(), before.positions.size());
    EXPECT_TRUE(p.tangents.empty());

    MeshPart q = strip(1, identityU);
    auto s1 = generateTangents(q, 1); // no TEXCOORD_1
    ASSERT_FALSE(s1);
    EXPECT_EQ(s1.error().field, "uvs1");

    auto bad = cornerTangents({{0, 0, 0}}, {{0, 0, 1}}, {{0, 0}}, {0, 0, 5});
    ASSERT_FALSE(bad);
    EXPECT_EQ(bad.error().field, "indices");
}
