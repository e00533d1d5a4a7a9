// UvDiagnosisTest — the UV diagnosis of SPEC §8 (core diagnoseUvs, ModelDerived::uvDiagnosis) on
// hand-built models: a clean atlas has no overlap (also a grid whose shared edges run through
// texel centres, and one of triangles smaller than a texel), two regions on the same texels are
// named, a fold is an overlap of one region, mirrored islands are paired (and not when they do
// not mirror on the body), missing, non-finite and out-of-range UVs are counted and wrapped,
// palette swatches (triangles collapsed onto a point) overlap; and on the real characters: the
// KayKit Barbarian's palette atlas overlaps (regions named, left and right forearm paired),
// CesiumMan and the default character are usable with no overlap, RiggedFigure has no UVs. The
// diagnosis is deterministic and built once per model. No GL, no HTTP.
#include "BuildPaths.hpp"
#include "core/model_derived.hpp"
#include "core/uv_diagnosis.hpp"
#include "io/gltf_loader.hpp"
#include "io/scene_files.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

using namespace dermis;

namespace {

const std::string kSource = dermis::build::sourceDir();
const std::string kModels = std::string(dermis::build::testModelsDir()) + "/";

std::shared_ptr<const Model> loadShared(const std::string& path) {
    auto m = loadGltfFile(path);
    EXPECT_TRUE(m) << path << ": " << (m ? "" : m.error().message);
    return m ? std::make_shared<const Model>(std::move(*m)) : nullptr;
}

/// A model of named joints (nodes at the origin, identity inverse binds: bind space = rest world
/// space) and quads, each a part of its own on one joint.
struct Figure {
    Model m;
    explicit Figure(const std::vector<std::string>& joints) {
        for (const std::string& name : joints) {
            Node n;
            n.name = name;
            m.joints.push_back(static_cast<int>(m.nodes.size()));
            m.nodes.push_back(n);
        }
    }
    /// A part on `joint` (its node `node`): the rectangle corner + [0, size.x]·x + [0, size.y]·y
    /// (z = corner.z) with the UV rectangle uv0 … uv1; two triangles sharing vertices (one island).
    MeshPart& quad(const std::string& node, int joint, glm::vec3 corner, glm::vec2 size, glm::vec2 uv0,
                   glm::vec2 uv1) {
        MeshPart p;
        p.name = "mesh." + std::to_string(m.parts.size());
        p.node = node;
        p.positions = {corner, corner + glm::vec3(size.x, 0, 0), corner + glm::vec3(size.x, size.y, 0),
                       corner + glm::vec3(0, size.y, 0)};
        p.uvs = {uv0, {uv1.x, uv0.y}, uv1, {uv0.x, uv1.y}};
        p.indices = {0, 1, 2, 0, 2, 3};
        finish(p, joint);
        m.parts.push_back(std::move(p));
        return m.parts.back();
    }
    /// Skin every vertex of `p` fully to `joint`; normals along +z.
    void finish(MeshPart& p, int joint) {
        p.normals.assign(p.positions.size(), glm::vec3(0, 0, 1));
        for (std::size_t j = 0; j < m.nodes.size(); ++j) p.influences.push_back({static_cast<int>(j), glm::mat4(1.0f)});
        p.joints.assign(p.positions.size(), glm::u16vec4(static_cast<std::uint16_t>(joint), 0, 0, 0));
        p.weights.assign(p.positions.size(), glm::vec4(1, 0, 0, 0));
    }
    int region(const UvDiagnosis& d, const std::string& name) const {
        for (std::size_t r = 0; r < d.regions.size(); ++r)
            if (d.regions[r].name == name) return static_cast<int>(r);
        ADD_FAILURE() << "no region " << name;
        return -1;
    }
};

bool sharesWith(const UvDiagnosis& d, int a, int b) {
    for (const auto& [r, texels] : d.regions[static_cast<std::size_t>(a)].sharesWith)
        if (r == b && texels > 0) return true;
    return false;
}

std::vector<int> regionsAt(const UvDiagnosis& d, glm::dvec2 uv, bool* overlapped = nullptr) {
    const auto s = d.regionsAt(uv, overlapped);
    return {s.begin(), s.end()};
}

const SymmetryPlane kPlaneX{0, 0.0f, 0.0f};

UvDiagnosis diagnose(const Model& m) { return diagnoseUvs(m, restSkin(m), kPlaneX); }

TEST(UvDiagnosisTest, ACleanAtlasHasNoOverlap) {
    Figure f({"arm", "leg"});
    f.quad("Arm", 0, {0, 1, 0}, {0.3f, 0.3f}, {0.1f, 0.1f}, {0.4f, 0.4f});
    f.quad("Leg", 1, {0, 0, 0}, {0.4f, 0.4f}, {0.5f, 0.5f}, {0.9f, 0.9f});
    const UvDiagnosis d = diagnose(f.m);
    EXPECT_TRUE(d.hasUVs);
    EXPECT_TRUE(d.usable());
    EXPECT_EQ(d.resolution, 1024);
    EXPECT_EQ(d.overlapTexels, 0u);
    EXPECT_EQ(d.overlapFraction, 0.0);
    EXPECT_NEAR(d.usedFraction, 0.09 + 0.16, 0.003);
    EXPECT_EQ(d.islands, 2u);
    EXPECT_EQ(d.triangles, 4u);
    ASSERT_EQ(d.regions.size(), 2u);
    EXPECT_EQ(d.regions[0].name, "Arm (arm)");
    EXPECT_EQ(d.regions[1].name, "Leg (leg)");
    EXPECT_EQ(d.regions[0].joint, "arm");
    EXPECT_EQ(d.regions[1].jointNode, 1);
    EXPECT_TRUE(d.regions[0].sharesWith.empty());
    EXPECT_EQ(d.describeSharing(), "");
    EXPECT_TRUE(d.mirroredPairs.empty());
    EXPECT_EQ(d.missingTriangles + d.outOfRangeTriangles + d.partsWithoutUvs + d.subTexelTriangles, 0u);
    EXPECT_EQ(regionsAt(d, {0.25, 0.25}), std::vector<int>{0});
    EXPECT_EQ(regionsAt(d, {0.7, 0.7}), std::vector<int>{1});
    EXPECT_TRUE(regionsAt(d, {0.45, 0.2}).empty());
    EXPECT_TRUE(regionsAt(d, {NAN, 0.2}).empty());
    // Same UV density on both (0.3 UV per 0.3 units, 0.4 per 0.4): 1024 texels per unit.
    ASSERT_EQ(d.density.size(), 2u);
    for (const UvJointDensity& j : d.density) EXPECT_NEAR(j.texelsPerUnit, 1024.0, 0.01) << j.joint;
}

TEST(UvDiagnosisTest, EdgesThroughTexelCentresAndSubTexelTrianglesAreNoOverlap) {
    // A 32×32 grid of quads over all of [0,1]²: its diagonals pass through texel centres, where
    // two triangles meet; each centre belongs to exactly one of them, so every texel is used once.
    Figure f({"spine"});
    MeshPart p;
    p.node = "Body";
    const int n = 32;
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
            p.positions.push_back({i / float(n), j / float(n), 0});
            p.uvs.push_back({i / float(n), j / float(n)});
        }
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const std::uint32_t a = j * (n + 1) + i, b = a + 1, c = a + n + 2, e = a + n + 1;
            for (std::uint32_t v : {a, b, c, a, c, e}) p.indices.push_back(v);
        }
    f.finish(p, 0);
    f.m.parts.push_back(p);
    UvDiagnosis d = diagnose(f.m);
    EXPECT_EQ(d.usedTexels, 1024u * 1024u);
    EXPECT_EQ(d.usedFraction, 1.0);
    EXPECT_EQ(d.overlapTexels, 0u);
    EXPECT_EQ(d.islands, 1u);

    // The same grid squeezed into 16×16 texels: its triangles are smaller than a texel; those
    // that hold no centre claim the texel under them, beside their neighbours: no overlap.
    for (glm::vec2& uv : f.m.parts[0].uvs) uv = glm::vec2(0.25f) + uv * (16.0f / 1024.0f);
    d = diagnose(f.m);
    EXPECT_GT(d.subTexelTriangles, 0u);
    EXPECT_EQ(d.overlapTexels, 0u);
    EXPECT_GE(d.usedTexels, 16u * 16u);
    EXPECT_LE(d.usedTexels, 17u * 17u);
}

TEST(UvDiagnosisTest, TwoRegionsOnTheSameTexelsAreNamed) {
    Figure f({"lowerarm.r", "head"});
    f.quad("Barbarian_ArmRight", 0, {-1, 1, 0}, {0.2f, 0.2f}, {0.2f, 0.2f}, {0.4f, 0.4f});
    f.quad("Barbarian_Hat", 1, {0, 2, 0}, {0.3f, 0.3f}, {0.2f, 0.2f}, {0.4f, 0.4f});
    UvDiagnosis d = diagnose(f.m);
    const int arm = f.region(d, "Barbarian_ArmRight (lowerarm.r)"), hat = f.region(d, "Barbarian_Hat (head)");
    EXPECT_FALSE(d.usable());
    EXPECT_TRUE(d.hasUVs);
    EXPECT_EQ(d.overlapFraction, 1.0); // every used texel is claimed by both
    EXPECT_EQ(d.overlapTexels, d.usedTexels);
    EXPECT_TRUE(sharesWith(d, arm, hat));
    EXPECT_TRUE(sharesWith(d, hat, arm));
    EXPECT_EQ(d.regions[static_cast<std::size_t>(arm)].sharedTexels, d.usedTexels);
    EXPECT_EQ(d.regions[static_cast<std::size_t>(arm)].foldedTexels, 0u);
    bool overlapped = false;
    EXPECT_EQ(regionsAt(d, {0.3, 0.3}, &overlapped), (std::vector<int>{arm, hat}));
    EXPECT_TRUE(overlapped);
    const std::string said = d.describeSharing();
    EXPECT_NE(said.find("Barbarian_ArmRight (lowerarm.r) shares texels with Barbarian_Hat (head)"), std::string::npos) << said;
    EXPECT_NE(said.find("Barbarian_Hat (head) shares texels with Barbarian_ArmRight (lowerarm.r)"), std::string::npos) << said;

    // Half way over: a third of the used texels (0.02 of 0.04 + 0.04 − 0.02) are shared.
    f.m.parts[1].uvs = {{0.3f, 0.2f}, {0.5f, 0.2f}, {0.5f, 0.4f}, {0.3f, 0.4f}};
    d = diagnose(f.m);
    EXPECT_NEAR(d.overlapFraction, 1.0 / 3.0, 0.005);
    EXPECT_EQ(regionsAt(d, {0.25, 0.3}, &overlapped), std::vector<int>{arm});
    EXPECT_FALSE(overlapped);
    EXPECT_EQ(regionsAt(d, {0.35, 0.3}, &overlapped), (std::vector<int>{arm, hat}));
    EXPECT_TRUE(overlapped);
    // No mirror image: the hat is not where the arm mirrors to.
    EXPECT_TRUE(d.mirroredPairs.empty());
}

TEST(UvDiagnosisTest, AnIslandFoldedOntoItselfOverlaps) {
    // Two triangles of one island on one joint, sharing an edge, both on the same side of it in
    // UV (mirrored halves of a face mapped onto one half).
    Figure f({"head"});
    MeshPart p;
    p.node = "Face";
    p.positions = {{0, 0, 0}, {1, 0, 0}, {0.5f, 1, 0}, {0.5f, -1, 0}};
    p.uvs = {{0.2f, 0.2f}, {0.6f, 0.2f}, {0.4f, 0.6f}, {0.4f, 0.5f}};
    p.indices = {0, 1, 2, 1, 0, 3};
    f.finish(p, 0);
    f.m.parts.push_back(p);
    const UvDiagnosis d = diagnose(f.m);
    ASSERT_EQ(d.regions.size(), 1u);
    EXPECT_EQ(d.islands, 1u);
    EXPECT_GT(d.overlapFraction, 0.5);
    EXPECT_FALSE(d.usable());
    EXPECT_EQ(d.regions[0].foldedTexels, d.overlapTexels);
    EXPECT_TRUE(d.regions[0].sharesWith.empty());
    EXPECT_EQ(d.describeSharing(), "Face (head) folds onto itself");
}

TEST(UvDiagnosisTest, MirroredIslandsArePaired) {
    Figure f({"spine", "elbow.l", "elbow.r"});
    f.quad("Body", 0, {-0.1f, 0, 0}, {0.2f, 1}, {0.7f, 0.1f}, {0.8f, 0.6f});
    f.quad("ArmL", 1, {0.5f, 1, 0}, {0.5f, 0.2f}, {0.1f, 0.1f}, {0.5f, 0.3f});
    f.quad("ArmR", 2, {-1.0f, 1, 0}, {0.5f, 0.2f}, {0.1f, 0.1f}, {0.5f, 0.3f});
    UvDiagnosis d = diagnose(f.m);
    const int left = f.region(d, "ArmL (elbow.l)"), right = f.region(d, "ArmR (elbow.r)");
    ASSERT_EQ(d.mirroredPairs.size(), 1u);
    EXPECT_EQ(d.mirroredPairs[0].regionA, left);
    EXPECT_EQ(d.mirroredPairs[0].regionB, right);
    EXPECT_EQ(d.mirroredPairs[0].islandPairs, 1u);
    EXPECT_EQ(d.mirroredPairs[0].trianglesA, 2u);
    EXPECT_TRUE(sharesWith(d, left, right));
    EXPECT_FALSE(d.usable());

    // The same UVs on an arm that is not the mirror image (moved up by 1): shared, not mirrored.
    for (glm::vec3& pos : f.m.parts[2].positions) pos.y += 1.0f;
    d = diagnose(f.m);
    EXPECT_TRUE(d.mirroredPairs.empty());
    EXPECT_TRUE(sharesWith(d, left, right));
    // Mirrored on the body but apart in UV: no pair, no overlap.
    for (glm::vec3& pos : f.m.parts[2].positions) pos.y -= 1.0f;
    for (glm::vec2& uv : f.m.parts[2].uvs) uv.y += 0.5f;
    d = diagnose(f.m);
    EXPECT_TRUE(d.mirroredPairs.empty());
    EXPECT_EQ(d.overlapTexels, 0u);
}

TEST(UvDiagnosisTest, MissingAndNonFiniteUvsAreCounted) {
    Figure f({"spine", "head"});
    f.quad("Body", 0, {0, 0, 0}, {1, 1}, {0.1f, 0.1f}, {0.5f, 0.5f});
    f.quad("Head", 1, {0, 2, 0}, {1, 1}, {0.6f, 0.6f}, {0.9f, 0.9f}).uvs.clear();
    UvDiagnosis d = diagnose(f.m);
    EXPECT_FALSE(d.hasUVs);
    EXPECT_FALSE(d.usable());
    EXPECT_EQ(d.partsWithoutUvs, 1u);
    EXPECT_EQ(d.missingTriangles, 2u);
    EXPECT_EQ(d.triangles, 2u);
    EXPECT_NEAR(d.usedFraction, 0.16, 0.003);
    ASSERT_EQ(d.triangleRegion.size(), 2u);
    EXPECT_EQ(d.triangleRegion[1], (std::vector<int>{-1, -1}));
    EXPECT_EQ(d.triangleRegion[0], (std::vector<int>{0, 0}));

    f.m.parts[1].uvs = {{0.6f, 0.6f}, {NAN, 0.6f}, {0.9f, 0.9f}, {0.6f, 0.9f}};
    d = diagnose(f.m);
    EXPECT_TRUE(d.hasUVs);
    EXPECT_EQ(d.partsWithoutUvs, 0u);
    EXPECT_EQ(d.missingTriangles, 1u); // the triangle with the NaN corner
    EXPECT_EQ(d.triangles, 3u);
    EXPECT_EQ(d.triangleRegion[1], (std::vector<int>{-1, 1}));
}

TEST(UvDiagnosisTest, OutOfRangeUvsAreCountedAndWrapped) {
    Figure f({"spine", "head"});
    f.quad("Body", 0, {0, 0, 0}, {1, 1}, {1.2f, 1.2f}, {1.4f, 1.4f}); // [0.2, 0.4]² wrapped
    UvDiagnosis d = diagnose(f.m);
    EXPECT_EQ(d.outOfRangeVertices, 4u);
    EXPECT_EQ(d.outOfRangeTriangles, 2u);
    EXPECT_TRUE(d.usable());
    EXPECT_NEAR(d.usedFraction, 0.04, 0.002);
    EXPECT_EQ(regionsAt(d, {0.3, 0.3}), std::vector<int>{0});
    EXPECT_EQ(regionsAt(d, {1.3, -0.7}), std::vector<int>{0});
    // Another region on [0.3, 0.5]² overlaps the wrapped one.
    f.quad("Head", 1, {0, 2, 0}, {1, 1}, {0.3f, 0.3f}, {0.5f, 0.5f});
    d = diagnose(f.m);
    EXPECT_GT(d.overlapTexels, 0u);
    EXPECT_TRUE(sharesWith(d, 0, 1));
    EXPECT_EQ(d.outOfRangeVertices, 4u);
    // A triangle across the edge u = 1 holds texels on both sides of it.
    Figure g({"spine"});
    g.quad("Band", 0, {0, 0, 0}, {1, 1}, {0.9f, 0.4f}, {1.1f, 0.6f});
    d = diagnose(g.m);
    EXPECT_EQ(d.outOfRangeVertices, 2u);
    EXPECT_EQ(regionsAt(d, {0.95, 0.5}), std::vector<int>{0});
    EXPECT_EQ(regionsAt(d, {0.05, 0.5}), std::vector<int>{0});
    EXPECT_TRUE(regionsAt(d, {0.2, 0.5}).empty());
    EXPECT_EQ(d.overlapTexels, 0u);
}

TEST(UvDiagnosisTest, PaletteSwatchesCollapsedOntoOnePointOverlap) {
    // Two parts whose triangles all sit on one UV point (a colour swatch): each claims the texel
    // under it, so the two regions share it.
    Figure f({"hips", "head"});
    f.quad("Pants", 0, {0, 0, 0}, {1, 1}, {0.55f, 0.55f}, {0.55f, 0.55f});
    f.quad("Helmet", 1, {0, 2, 0}, {1, 1}, {0.55f, 0.55f}, {0.55f, 0.55f});
    const UvDiagnosis d = diagnose(f.m);
    EXPECT_EQ(d.subTexelTriangles, 4u);
    EXPECT_EQ(d.usedTexels, 1u);
    EXPECT_EQ(d.overlapTexels, 1u);
    EXPECT_FALSE(d.usable());
    EXPECT_TRUE(sharesWith(d, 0, 1));
    bool overlapped = false;
    EXPECT_EQ(regionsAt(d, {0.55, 0.55}, &overlapped), (std::vector<int>{0, 1}));
    EXPECT_TRUE(overlapped);
}

TEST(UvDiagnosisTest, ModelWithoutPartsOrUvsIsEmpty) {
    const UvDiagnosis empty = diagnoseUvs(Model{});
    EXPECT_FALSE(empty.hasUVs);
    EXPECT_FALSE(empty.usable());
    EXPECT_EQ(empty.usedTexels, 0u);
    EXPECT_TRUE(empty.regions.empty());
    EXPECT_TRUE(empty.regionsAt({0.5, 0.5}).empty());
    EXPECT_TRUE(modelUvsHoldHeightmaps(UvLayoutMode::Model, empty));
    EXPECT_FALSE(modelUvsHoldHeightmaps(UvLayoutMode::Auto, empty));
    EXPECT_FALSE(modelUvsHoldHeightmaps(UvLayoutMode::Generated, empty));
}

// --- the real characters --------------------------------------------------------------------

TEST(UvDiagnosisTest, TheBarbariansPaletteAtlasOverlapsAndNamesTheRegions) {
    auto model = loadShared(kModels + "KayKitBarbarian/Barbarian.glb");
    ASSERT_TRUE(model);
    const ModelDerived derived(model);
    const UvDiagnosis& d = derived.uvDiagnosis();
    EXPECT_TRUE(d.hasUVs);
    EXPECT_GT(d.overlapFraction, 0.005);
    EXPECT_FALSE(d.usable());
    EXPECT_TRUE(modelUvsHoldHeightmaps(UvLayoutMode::Model, d));
    EXPECT_FALSE(modelUvsHoldHeightmaps(UvLayoutMode::Auto, d));
    EXPECT_GT(d.usedFraction, 0.0);
    EXPECT_LT(d.usedFraction, 0.5);
    EXPECT_EQ(d.triangles, model->triangleCount());
    // The hat (a rigid mesh under the head) is named by its node and the joint above it, and
    // shares texels with the body.
    int hat = -1, armL = -1, armR = -1;
    for (std::size_t r = 0; r < d.regions.size(); ++r) {
        if (d.regions[r].name == "Barbarian_Hat (head)") hat = static_cast<int>(r);
        if (d.regions[r].name == "Barbarian_ArmLeft (lowerarm.l)") armL = static_cast<int>(r);
        if (d.regions[r].name == "Barbarian_ArmRight (lowerarm.r)") armR = static_cast<int>(r);
    }
    ASSERT_GE(hat, 0);
    ASSERT_GE(armL, 0);
    ASSERT_GE(armR, 0);
    const UvRegion& h = d.regions[static_cast<std::size_t>(hat)];
    EXPECT_EQ(h.joint, "head");
    EXPECT_GT(h.sharedTexels, 0u);
    ASSERT_FALSE(h.sharesWith.empty());
    bool withBody = false;
    for (const auto& [r, texels] : h.sharesWith)
        withBody = withBody || d.regions[static_cast<std::size_t>(r)].part == "Barbarian_Body";
    EXPECT_TRUE(withBody);
    // Left and right forearm are one texel: shared and mirrored.
    EXPECT_TRUE(sharesWith(d, armL, armR));
    bool forearms = false;
    for (const UvMirroredPair& p : d.mirroredPairs)
        forearms = forearms || (p.regionA == armL && p.regionB == armR && p.islandPairs > 0);
    EXPECT_TRUE(forearms);
    const std::string said = d.describeSharing();
    EXPECT_NE(said.find("shares texels with"), std::string::npos) << said;
    // Density per driving joint: the forearms' islands are the same size on both sides.
    const UvJointDensity *l = nullptr, *r = nullptr;
    for (const UvJointDensity& j : d.density) {
        if (j.joint == "lowerarm.l") l = &j;
        if (j.joint == "lowerarm.r") r = &j;
    }
    ASSERT_TRUE(l && r);
    EXPECT_GT(l->texelsPerUnit, 0.0);
    EXPECT_NEAR(l->texelsPerUnit, r->texelsPerUnit, 0.01 * l->texelsPerUnit);

    // Built once, and the same on a second build.
    EXPECT_EQ(&derived.uvDiagnosis(), &d);
    EXPECT_EQ(derived.uvDiagnosisBuilds(), 1);
    const UvDiagnosis again = diagnoseUvs(*model);
    EXPECT_EQ(again.texelSets, d.texelSets);
    EXPECT_EQ(again.regionSets, d.regionSets);
    EXPECT_EQ(again.overlapTexels, d.overlapTexels);
    ASSERT_EQ(again.regions.size(), d.regions.size());
    for (std::size_t k = 0; k < d.regions.size(); ++k) {
        EXPECT_EQ(again.regions[k].name, d.regions[k].name);
        EXPECT_EQ(again.regions[k].sharesWith, d.regions[k].sharesWith);
    }
    EXPECT_EQ(again.mirroredPairs.size(), d.mirroredPairs.size());
}

TEST(UvDiagnosisTest, CesiumManAndTheDefaultCharacterAreUsable) {
    for (const std::string& path :
         {kModels + "CesiumMan/CesiumMan.glb", resolveModelPath("builtin:default", "", kSource)}) {
        SCOPED_TRACE(path);
        auto model = loadShared(path);
        ASSERT_TRUE(model);
        const UvDiagnosis d = diagnoseUvs(*model);
        EXPECT_TRUE(d.hasUVs);
        EXPECT_TRUE(d.usable());
        EXPECT_LT(d.overlapFraction, 0.005);
        EXPECT_EQ(d.overlapTexels, 0u);
        EXPECT_EQ(d.describeSharing(), "");
        EXPECT_TRUE(d.mirroredPairs.empty());
        EXPECT_EQ(d.missingTriangles + d.outOfRangeVertices, 0u);
        EXPECT_TRUE(modelUvsHoldHeightmaps(UvLayoutMode::Auto, d));
        // The used texels are the atlas' UV area.
        double area = 0.0;
        for (const MeshPart& p : model->parts)
            for (std::size_t t = 0; t + 2 < p.indices.size(); t += 3) {
                const glm::dvec2 a(p.uvs[p.indices[t]]), b(p.uvs[p.indices[t + 1]]), c(p.uvs[p.indices[t + 2]]);
                area += 0.5 * std::abs((b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y));
            }
        EXPECT_NEAR(d.usedFraction, area, 0.01);
        // An even atlas: every driving joint within a factor of two of the median density.
        ASSERT_FALSE(d.density.empty());
        std::vector<double> tpu;
        for (const UvJointDensity& j : d.density) tpu.push_back(j.texelsPerUnit);
        std::sort(tpu.begin(), tpu.end());
        const double median = tpu[tpu.size() / 2];
        EXPECT_GT(tpu.front(), median / 2);
        EXPECT_LT(tpu.back(), median * 2);
    }
}

TEST(UvDiagnosisTest, RiggedFigureHasNoUvs) {
    auto model = loadShared(kModels + "RiggedFigure/RiggedFigure.glb");
    ASSERT_TRUE(model);
    const UvDiagnosis d = diagnoseUvs(*model);
    EXPECT_FALSE(d.hasUVs);
    EXPECT_FALSE(d.usable());
    EXPECT_EQ(d.partsWithoutUvs, model->parts.size());
    EXPECT_EQ(d.missingTriangles, model->triangleCount());
    EXPECT_EQ(d.usedTexels, 0u);
    EXPECT_TRUE(d.regions.empty());
    EXPECT_FALSE(modelUvsHoldHeightmaps(UvLayoutMode::Auto, d));
}

} // namespace
