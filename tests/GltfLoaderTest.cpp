// GltfLoaderTest — glTF 2.0 in (server/io/gltf_loader.hpp): the shared models written by others
// (shared/models; the tests fail, never skip, when they are missing), small hand-built files that
// pin each loading rule, and corrupt input (truncated, garbage, bit flips, targeted damage) that
// must give an Error naming the field at fault — never a crash (the suite also runs under
// ASan/UBSan). Reads the shared models and writes temporary files.
#include "TestFiles.hpp"
#include "core/rig.hpp"
#include "io/gltf_loader.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <random>

using namespace dermis;
using namespace dermis::test;
using json = nlohmann::json;

namespace {

const std::string kModels = std::string(DERMIS_SHARED_DIR) + "/models/";
const std::string kCesiumMan = kModels + "CesiumMan/CesiumMan.glb";
const std::string kRiggedFigure = kModels + "RiggedFigure/RiggedFigure.glb";
const std::string kBarbarian = kModels + "KayKitBarbarian/Barbarian.glb";

constexpr int kFloat = 5126, kUByte = 5121, kUShort = 5123, kUInt = 5125;

// --- GLB assembly -----------------------------------------------------------------------------

void putU32(std::vector<std::uint8_t>& out, std::uint32_t v) {
    for (int k = 0; k < 4; ++k)
        out.push_back(static_cast<std::uint8_t>(v >> (8 * k)));
}

std::uint32_t getU32(const std::vector<std::uint8_t>& b, std::size_t at) {
    return std::uint32_t(b[at]) | std::uint32_t(b[at + 1]) << 8 | std::uint32_t(b[at + 2]) << 16 |
           std::uint32_t(b[at + 3]) << 24;
}

/// A GLB of `doc` and `bin` (glTF 2.0 §4.4), chunks padded to 4 bytes.
std::vector<std::uint8_t> makeGlb(const json& doc, std::vector<std::uint8_t> bin) {
    std::string text = doc.dump();
    while (text.size() % 4)
        text += ' ';
    while (bin.size() % 4)
        bin.push_back(0);
    const std::size_t total = 12 + 8 + text.size() + (bin.empty() ? 0 : 8 + bin.size());
    std::vector<std::uint8_t> out = {'g', 'l', 'T', 'F'};
    putU32(out, 2);
    putU32(out, static_cast<std::uint32_t>(total));
    putU32(out, static_cast<std::uint32_t>(text.size()));
    putU32(out, 0x4E4F534Au);
    out.insert(out.end(), text.begin(), text.end());
    if (!bin.empty()) {
        putU32(out, static_cast<std::uint32_t>(bin.size()));
        putU32(out, 0x004E4942u);
        out.insert(out.end(), bin.begin(), bin.end());
    }
    return out;
}

/// The JSON and BIN chunks of a well-formed GLB.
std::pair<json, std::vector<std::uint8_t>> splitGlb(const std::vector<std::uint8_t>& glb) {
    const std::uint32_t jsonLength = getU32(glb, 12);
    json doc = json::parse(glb.begin() + 20, glb.begin() + 20 + jsonLength);
    std::vector<std::uint8_t> bin;
    const std::size_t at = 20 + jsonLength;
    if (at + 8 <= glb.size()) {
        const std::uint32_t binLength = getU32(glb, at);
        bin.assign(glb.begin() + static_cast<std::ptrdiff_t>(at + 8),
                   glb.begin() + static_cast<std::ptrdiff_t>(at + 8 + binLength));
    }
    return {doc, bin};
}

template <class T> std::vector<std::uint8_t> bytesOf(const std::vector<T>& v) {
    std::vector<std::uint8_t> out(v.size() * sizeof(T));
    if (!v.empty()) std::memcpy(out.data(), v.data(), out.size());
    return out;
}

int componentsOf(const std::string& type) {
    if (type == "SCALAR") return 1;
    if (type == "VEC2") return 2;
    if (type == "VEC3") return 3;
    if (type == "VEC4") return 4;
    if (type == "MAT4") return 16;
    return 0;
}

/// Assembles small glTF files by hand: one buffer, one buffer view per array.
struct Builder {
    json doc = {{"asset", {{"version", "2.0"}}},
                {"bufferViews", json::array()},
                {"accessors", json::array()}};
    std::vector<std::uint8_t> bin;

    int view(const std::vector<std::uint8_t>& bytes, int stride = 0) {
        while (bin.size() % 4)
            bin.push_back(0);
        json v = {{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", bytes.size()}};
        if (stride) v["byteStride"] = stride;
        bin.insert(bin.end(), bytes.begin(), bytes.end());
        doc["bufferViews"].push_back(v);
        return static_cast<int>(doc["bufferViews"].size()) - 1;
    }
    int accessor(int bufferView, int componentType, const std::string& type, std::size_t count,
                 std::size_t byteOffset = 0, bool normalized = false) {
        json a = {{"componentType", componentType}, {"type", type}, {"count", count}};
        if (bufferView >= 0) a["bufferView"] = bufferView;
        if (byteOffset) a["byteOffset"] = byteOffset;
        if (normalized) a["normalized"] = true;
        doc["accessors"].push_back(a);
        return static_cast<int>(doc["accessors"].size()) - 1;
    }
    template <class T>
    int add(const std::vector<T>& values, int componentType, const std::string& type,
            bool normalized = false) {
        const std::size_t count = values.size() / static_cast<std::size_t>(componentsOf(type));
        return accessor(view(bytesOf(values)), componentType, type, count, 0, normalized);
    }
    /// Byte offset in `bin` where accessor `a`'s data starts.
    std::size_t dataOffset(int a) const {
        const json& acc = doc["accessors"][static_cast<std::size_t>(a)];
        return doc["bufferViews"][acc["bufferView"].get<std::size_t>()]["byteOffset"]
                   .get<std::size_t>() +
               acc.value("byteOffset", std::size_t(0));
    }
    std::vector<std::uint8_t> glb() const {
        json d = doc;
        d["buffers"] = json::array({{{"byteLength", bin.size()}}});
        return makeGlb(d, bin);
    }
};

/// A valid skinned triangle: nodes 0 "root" → 1 "tip", node 2 carries mesh 0 with skin 0
/// (joints 0, 1; identity inverse bind matrices), one LINEAR rotation clip on "tip", one
/// material. The accessor indices are kept for targeted damage.
struct SkinnedTriangle {
    Builder b;
    int position, normal, uv, joints, weights, indices, ibm, times, rotations;

    SkinnedTriangle() {
        position = b.add(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0}, kFloat, "VEC3");
        normal = b.add(std::vector<float>{0, 0, 1, 0, 0, 1, 0, 0, 1}, kFloat, "VEC3");
        uv = b.add(std::vector<float>{0, 0, 1, 0, 0, 1}, kFloat, "VEC2");
        joints =
            b.add(std::vector<std::uint8_t>{0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0}, kUByte, "VEC4");
        weights =
            b.add(std::vector<float>{1, 0, 0, 0, 1, 0, 0, 0, 0.5f, 0.5f, 0, 0}, kFloat, "VEC4");
        indices = b.add(std::vector<std::uint16_t>{0, 1, 2, 0}, kUShort, "SCALAR");
        b.doc["accessors"][static_cast<std::size_t>(indices)]["count"] = 3; // 4th is padding
        std::vector<float> identity2(32, 0.0f);
        for (int k = 0; k < 2; ++k)
            for (int d = 0; d < 4; ++d)
                identity2[static_cast<std::size_t>(16 * k + 5 * d)] = 1;
        ibm = b.add(identity2, kFloat, "MAT4");
        times = b.add(std::vector<float>{0, 1}, kFloat, "SCALAR");
        const float s = std::sqrt(0.5f);
        rotations = b.add(std::vector<float>{0, 0, 0, 1, 0, 0, s, s}, kFloat, "VEC4");
        json& d = b.doc;
        d["nodes"] = json::array({{{"name", "root"}, {"children", {1, 2}}},
                                  {{"name", "tip"}, {"translation", {1, 0, 0}}},
                                  {{"name", "body"}, {"mesh", 0}, {"skin", 0}}});
        d["scenes"] = json::array({{{"nodes", {0}}}});
        d["scene"] = 0;
        d["skins"] = json::array({{{"joints", {0, 1}}, {"inverseBindMatrices", ibm}}});
        d["materials"] =
            json::array({{{"name", "skin"},
                          {"pbrMetallicRoughness", {{"baseColorFactor", {1, 0.5, 0.25, 1}}}}}});
        d["meshes"] = json::array({{{"name", "tri"},
                                    {"primitives",
                                     {{{"attributes",
                                        {{"POSITION", position},
                                         {"NORMAL", normal},
                                         {"TEXCOORD_0", uv},
                                         {"JOINTS_0", joints},
                                         {"WEIGHTS_0", weights}}},
                                       {"indices", indices},
                                       {"material", 0}}}}}});
        d["animations"] = json::array(
            {{{"name", "bend"},
              {"samplers",
               {{{"input", times}, {"output", rotations}, {"interpolation", "LINEAR"}}}},
              {"channels", {{{"sampler", 0}, {"target", {{"node", 1}, {"path", "rotation"}}}}}}}});
    }
};

Result<Model> parseModel(const std::vector<std::uint8_t>& bytes) {
    auto parsed = parseGltf(bytes, "");
    if (!parsed) return parsed.error();
    if (auto s = loadGltfResources(*parsed); !s) return s.error();
    return std::move(parsed->model);
}

/// Expects `bytes` to be refused with an error naming `field`.
void expectFieldError(const std::vector<std::uint8_t>& bytes, const std::string& field,
                      ErrorCode code = ErrorCode::Parse) {
    auto r = parseGltf(bytes, "");
    ASSERT_FALSE(r.ok()) << "expected an error at " << field;
    EXPECT_EQ(r.error().field, field) << r.error().message;
    EXPECT_EQ(r.error().code, code) << r.error().message;
    EXPECT_NE(r.error().message.find("dermis::parseGltf"), std::string::npos) << r.error().message;
}

/// Every invariant Model promises (model.hpp), checked on whatever the loader returned.
void expectConsistent(const Model& m) {
    const std::size_t nodes = m.nodes.size();
    for (const Node& n : m.nodes) {
        EXPECT_LT(n.parent, static_cast<int>(nodes));
        EXPECT_NEAR(glm::length(n.rotation), 1.0f, 1e-4f);
    }
    for (int j : m.joints)
        EXPECT_TRUE(j >= 0 && static_cast<std::size_t>(j) < nodes);
    for (const MeshPart& p : m.parts) {
        const std::size_t nv = p.positions.size();
        ASSERT_GT(nv, 0u);
        ASSERT_EQ(p.normals.size(), nv);
        ASSERT_TRUE(p.uvs.empty() || p.uvs.size() == nv);
        ASSERT_EQ(p.joints.size(), nv);
        ASSERT_EQ(p.weights.size(), nv);
        ASSERT_FALSE(p.influences.empty());
        ASSERT_EQ(p.indices.size() % 3, 0u);
        for (std::uint32_t i : p.indices)
            ASSERT_LT(i, nv);
        for (const Influence& inf : p.influences)
            ASSERT_TRUE(inf.node >= 0 && static_cast<std::size_t>(inf.node) < nodes);
        for (std::size_t v = 0; v < nv; ++v) {
            ASSERT_TRUE(std::isfinite(p.positions[v].x) && std::isfinite(p.positions[v].y) &&
                        std::isfinite(p.positions[v].z));
            ASSERT_NEAR(glm::length(p.normals[v]), 1.0f, 1e-4f);
            float sum = 0.0f;
            for (int c = 0; c < 4; ++c) {
                ASSERT_GE(p.weights[v][c], 0.0f);
                if (p.weights[v][c] > 0.0f) ASSERT_LT(p.joints[v][c], p.influences.size());
                sum += p.weights[v][c];
            }
            ASSERT_NEAR(sum, 1.0f, 1e-5f);
        }
        ASSERT_TRUE(p.material >= -1 && p.material < static_cast<int>(m.materials.size()));
    }
    for (const Material& mat : m.materials)
        ASSERT_TRUE(mat.baseColorTexture >= -1 &&
                    mat.baseColorTexture < static_cast<int>(m.images.size()));
    for (const Clip& c : m.clips) {
        for (const Channel& ch : c.channels) {
            ASSERT_TRUE(ch.node >= 0 && static_cast<std::size_t>(ch.node) < nodes);
            ASSERT_FALSE(ch.times.empty());
            for (std::size_t k = 1; k < ch.times.size(); ++k)
                ASSERT_GT(ch.times[k], ch.times[k - 1]);
            const std::size_t comps = ch.path == ChannelPath::Rotation ? 4 : 3;
            const std::size_t per = ch.interpolation == Interpolation::CubicSpline ? 3 : 1;
            ASSERT_EQ(ch.values.size(), ch.times.size() * comps * per);
            ASSERT_LE(ch.times.back(), c.duration);
        }
    }
}

/// Largest distance between corresponding positions of two skinnings.
float maxDistance(const std::vector<SkinnedPart>& a, const std::vector<SkinnedPart>& b) {
    float d = 0.0f;
    for (std::size_t p = 0; p < a.size(); ++p)
        for (std::size_t v = 0; v < a[p].positions.size(); ++v)
            d = std::max(d, glm::length(a[p].positions[v] - b[p].positions[v]));
    return d;
}

/// At rest every influence of a part has the same joint matrix M = world(node) · inverseBind (the
/// rest pose is the bind pose), and skinning gives back the bind-space positions mapped by M. M is
/// the identity for rigid parts (rest world space by construction) and for skinned parts of
/// files whose skeleton sits at the origin; CesiumMan and RiggedFigure put theirs under a "Z_UP"
/// root node, so their M is that axis change. A clip pose then moves the mesh.
void expectRestReproducesBindAndClipsMove(const Model& m) {
    const auto world = worldMatrices(m, restPose(m));
    const auto rest = skin(m, world);
    ASSERT_EQ(rest.size(), m.parts.size());
    for (std::size_t p = 0; p < m.parts.size(); ++p) {
        const MeshPart& part = m.parts[p];
        SCOPED_TRACE("part " + std::to_string(p) + " (" + part.name + ")");
        auto jointMatrix = [&](const Influence& inf) {
            return world[static_cast<std::size_t>(inf.node)] * inf.inverseBind;
        };
        const glm::mat4 bindToWorld = jointMatrix(part.influences[0]);
        for (const Influence& inf : part.influences) {
            const glm::mat4 j = jointMatrix(inf);
            for (int c = 0; c < 4; ++c)
                for (int r = 0; r < 4; ++r)
                    ASSERT_NEAR(j[c][r], bindToWorld[c][r], 1e-4f);
        }
        if (part.influences.size() == 1) {
            // Rigid: positions are already in rest world space.
            for (int c = 0; c < 4; ++c)
                for (int r = 0; r < 4; ++r)
                    ASSERT_NEAR(bindToWorld[c][r], c == r ? 1.0f : 0.0f, 1e-4f);
        }
        ASSERT_EQ(rest[p].positions.size(), part.positions.size());
        float worst = 0.0f;
        for (std::size_t v = 0; v < part.positions.size(); ++v) {
            const glm::vec3 expected(bindToWorld * glm::vec4(part.positions[v], 1.0f));
            worst = std::max(worst, glm::length(rest[p].positions[v] - expected));
        }
        EXPECT_LT(worst, 1e-4f);
        for (const glm::vec3& n : rest[p].normals)
            ASSERT_NEAR(glm::length(n), 1.0f, 1e-4f);
    }
    ASSERT_FALSE(m.clips.empty());
    const Clip& clip = m.clips[0];
    const auto posed = skin(m, worldMatrices(m, sampleClip(m, 0, clip.duration * 0.5f)));
    EXPECT_GT(maxDistance(posed, rest), 1e-3f) << "clip " << clip.name << " does not move";
    for (const auto& part : posed)
        for (const glm::vec3& n : part.normals)
            ASSERT_NEAR(glm::length(n), 1.0f, 1e-4f);
}

/// Parses damaged bytes: an error, or a model that keeps every invariant. Never a crash.
void expectErrorOrConsistent(const std::vector<std::uint8_t>& bytes, const std::string& what) {
    SCOPED_TRACE(what);
    auto r = parseGltf(bytes, "");
    if (!r.ok()) {
        EXPECT_FALSE(r.error().message.empty());
        return;
    }
    expectConsistent(r->model);
    (void)skin(r->model, worldMatrices(r->model, restPose(r->model)));
}

Result<Model> loadShared(const std::string& path) {
    auto m = loadGltfFile(path);
    EXPECT_TRUE(m.ok()) << path << ": " << (m.ok() ? "" : m.error().message)
                        << " (the shared models are required: " << kModels << ")";
    return m;
}

} // namespace

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

// --- corrupt input: targeted damage names the field ------------------------------------------

TEST(GltfLoaderTest, DamagedAccessorsNameTheAttribute) {
    const std::string pos = "/meshes/0/primitives/0/attributes/POSITION";
    {
        SkinnedTriangle t; // more elements than the buffer view holds
        t.b.doc["accessors"][static_cast<std::size_t>(t.position)]["count"] = 4;
        // (NORMAL etc. still have 3: POSITION is read first and fails on its own bounds.)
        expectFieldError(t.b.glb(), pos);
    }
    {
        SkinnedTriangle t; // huge count
        t.b.doc["accessors"][static_cast<std::size_t>(t.position)]["count"] = 4294967295u;
        expectFieldError(t.b.glb(), pos, ErrorCode::Unsupported);
    }
    {
        SkinnedTriangle t; // byteOffset past the view
        t.b.doc["accessors"][static_cast<std::size_t>(t.position)]["byteOffset"] = 1u << 31;
        expectFieldError(t.b.glb(), pos);
    }
    {
        SkinnedTriangle t; // view past the buffer
        const auto v = t.b.doc["accessors"][static_cast<std::size_t>(t.position)]["bufferView"]
                           .get<std::size_t>();
        t.b.doc["bufferViews"][v]["byteOffset"] = 1000000;
        expectFieldError(t.b.glb(), pos);
    }
    {
        SkinnedTriangle t; // wrong type
        t.b.doc["accessors"][static_cast<std::size_t>(t.position)]["type"] = "VEC2";
        expectFieldError(t.b.glb(), pos);
    }
    {
        SkinnedTriangle t; // NaN position
        const float nan = std::numeric_limits<float>::quiet_NaN();
        std::memcpy(&t.b.bin[t.b.dataOffset(t.position) + 4], &nan, 4);
        expectFieldError(t.b.glb(), pos);
    }
    {
        SkinnedTriangle t; // no POSITION
        t.b.doc["meshes"][0]["primitives"][0]["attributes"].erase("POSITION");
        expectFieldError(t.b.glb(), pos);
    }
    {
        SkinnedTriangle t; // attribute with another vertex count
        t.b.doc["accessors"][static_cast<std::size_t>(t.uv)]["count"] = 2;
        expectFieldError(t.b.glb(), "/meshes/0/primitives/0/attributes/TEXCOORD_0");
    }
    {
        SkinnedTriangle t; // index out of range
        t.b.bin[t.b.dataOffset(t.indices) + 2] = 3;
        expectFieldError(t.b.glb(), "/meshes/0/primitives/0/indices");
    }
    {
        SkinnedTriangle t; // not a whole number of triangles
        t.b.doc["accessors"][static_cast<std::size_t>(t.indices)]["count"] = 4;
        expectFieldError(t.b.glb(), "/meshes/0/primitives/0/indices");
    }
    {
        SkinnedTriangle t; // weighted joint beyond the skin's joints
        t.b.bin[t.b.dataOffset(t.joints) + 4] = 2;
        expectFieldError(t.b.glb(), "/meshes/0/primitives/0/attributes/JOINTS_0");
    }
    {
        SkinnedTriangle t; // float joints
        t.b.doc["accessors"][static_cast<std::size_t>(t.joints)]["componentType"] = kFloat;
        t.b.doc["accessors"][static_cast<std::size_t>(t.joints)]["count"] = 1;
        expectFieldError(t.b.glb(), "/meshes/0/primitives/0/attributes/JOINTS_0");
    }
    {
        SkinnedTriangle t; // 32-bit joints are not glTF
        t.b.doc["accessors"][static_cast<std::size_t>(t.joints)]["componentType"] = kUInt;
        expectFieldError(t.b.glb(), "/meshes/0/primitives/0/attributes/JOINTS_0");
    }
}

TEST(GltfLoaderTest, DamagedStructureNamesTheField) {
    {
        SkinnedTriangle t; // key times not increasing
        const float one = 0.0f;
        std::memcpy(&t.b.bin[t.b.dataOffset(t.times) + 4], &one, 4);
        expectFieldError(t.b.glb(), "/animations/0/samplers/0/input");
    }
    {
        SkinnedTriangle t; // output count does not match the keys
        t.b.doc["accessors"][static_cast<std::size_t>(t.rotations)]["count"] = 1;
        expectFieldError(t.b.glb(), "/animations/0/samplers/0/output");
    }
    {
        SkinnedTriangle t; // unknown interpolation
        t.b.doc["animations"][0]["samplers"][0]["interpolation"] = "BOUNCE";
        expectFieldError(t.b.glb(), "/animations/0/samplers/0/interpolation",
                         ErrorCode::Unsupported);
    }
    {
        SkinnedTriangle t; // channel on a missing node
        t.b.doc["animations"][0]["channels"][0]["target"]["node"] = 17;
        expectFieldError(t.b.glb(), "/animations/0/channels/0/target/node");
    }
    {
        SkinnedTriangle t; // node cycle
        t.b.doc["nodes"][1]["children"] = {0};
        t.b.doc["nodes"][0]["children"] = {1};
        t.b.doc["nodes"][2].erase("mesh");
        expectFieldError(t.b.glb(), "/nodes/0");
    }
    {
        SkinnedTriangle t; // two parents
        t.b.doc["nodes"][1]["children"] = {2};
        expectFieldError(t.b.glb(), "/nodes/1/children/0");
    }
    {
        SkinnedTriangle t; // child out of range
        t.b.doc["nodes"][0]["children"] = {1, 2, 9};
        expectFieldError(t.b.glb(), "/nodes/0/children/2");
    }
    {
        SkinnedTriangle t; // skin joint out of range
        t.b.doc["skins"][0]["joints"] = {0, 5};
        expectFieldError(t.b.glb(), "/skins/0/joints/1");
    }
    {
        SkinnedTriangle t; // too few inverse bind matrices
        t.b.doc["skins"][0]["joints"] = {0, 1, 2};
        expectFieldError(t.b.glb(), "/skins/0/inverseBindMatrices");
    }
    {
        SkinnedTriangle t; // node skin out of range
        t.b.doc["nodes"][2]["skin"] = 3;
        expectFieldError(t.b.glb(), "/nodes/2/skin");
    }
    {
        SkinnedTriangle t; // rotation of zero length
        t.b.doc["nodes"][1]["rotation"] = {0, 0, 0, 0};
        expectFieldError(t.b.glb(), "/nodes/1/rotation");
    }
    {
        SkinnedTriangle t; // projective matrix
        t.b.doc["nodes"][1]["matrix"] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0.5, 0, 0, 0, 1};
        expectFieldError(t.b.glb(), "/nodes/1/matrix");
    }
    {
        SkinnedTriangle t; // material out of range
        t.b.doc["meshes"][0]["primitives"][0]["material"] = 4;
        expectFieldError(t.b.glb(), "/meshes/0/primitives/0/material");
    }
    {
        SkinnedTriangle t; // default scene out of range
        t.b.doc["scene"] = 2;
        expectFieldError(t.b.glb(), "/scene");
    }
    {
        SkinnedTriangle t; // image stored past the end of its buffer (tinygltf 2.7 reads it)
        const int v = t.b.view(std::vector<std::uint8_t>(16, 1));
        t.b.doc["bufferViews"][static_cast<std::size_t>(v)]["byteLength"] = 1 << 20;
        t.b.doc["images"] = json::array({{{"bufferView", v}, {"mimeType", "image/png"}}});
        expectFieldError(t.b.glb(), "/images/0/bufferView");
    }
    {
        SkinnedTriangle t; // texture without data
        t.b.doc["images"] = json::array({{{"uri", "elsewhere.png"}}});
        t.b.doc["textures"] = json::array({{{"source", 0}}});
        t.b.doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
        expectFieldError(t.b.glb(), "/images/0", ErrorCode::NotFound);
    }
    {
        SkinnedTriangle t; // glTF 1.0
        t.b.doc["asset"]["version"] = "1.0";
        expectFieldError(t.b.glb(), "/asset/version", ErrorCode::Unsupported);
    }
    {
        SkinnedTriangle t; // a required extension this loader does not implement
        t.b.doc["extensionsRequired"] = {"KHR_draco_mesh_compression"};
        expectFieldError(t.b.glb(), "/extensionsRequired/0", ErrorCode::Unsupported);
    }
}

TEST(GltfLoaderTest, PointsAndLinesAreSkipped) {
    SkinnedTriangle t;
    t.b.doc["meshes"][0]["primitives"][0]["mode"] = 1; // LINES
    auto m = parseModel(t.b.glb());
    ASSERT_TRUE(m.ok()) << m.error().message;
    EXPECT_TRUE(m->parts.empty());
}

// --- corrupt input: truncation, garbage, bit flips ----------------------------------------------

TEST(GltfLoaderTest, EmptyAndGarbageInputAreErrors) {
    auto empty = parseGltf({}, "");
    ASSERT_FALSE(empty.ok());
    EXPECT_EQ(empty.error().code, ErrorCode::Parse);
    std::mt19937 rng(11);
    for (std::size_t size : {1u, 3u, 4u, 19u, 20u, 64u, 1000u, 100000u}) {
        std::vector<std::uint8_t> garbage(size);
        for (auto& b : garbage)
            b = static_cast<std::uint8_t>(rng());
        EXPECT_FALSE(parseGltf(garbage, "").ok()) << size;
        // Garbage behind a valid GLB magic and header.
        if (size >= 20) {
            std::memcpy(garbage.data(), "glTF", 4);
            EXPECT_FALSE(parseGltf(garbage, "").ok()) << size;
        }
    }
    for (const std::string text :
         {"{", "[]", "{}", "null", "{\"asset\":{}}",
          "{\"asset\":{\"version\":\"2.0\"},\"nodes\":[{\"children\":[0]}]}",
          "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":"
          "18446744073709551615}]}"})
        EXPECT_FALSE(parseGltf(std::vector<std::uint8_t>(text.begin(), text.end()), "").ok())
            << text;
}

TEST(GltfLoaderTest, DeepNestingAndLongChainsDoNotExhaustTheStack) {
    const auto bytesOf = [](const std::string& text) {
        return std::vector<std::uint8_t>(text.begin(), text.end());
    };
    // 100 000 nested arrays in `extras` (tinygltf copies extras recursively).
    const std::string deep =
        "{\"asset\":{\"version\":\"2.0\"},\"extras\":" + std::string(100000, '[') +
        std::string(100000, ']') + "}";
    auto r = parseGltf(bytesOf(deep), "");
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().code, ErrorCode::Parse);
    // A 100 000-node parent chain with a triangle at the far end is fine.
    SkinnedTriangle t;
    json& nodes = t.b.doc["nodes"];
    const int first = static_cast<int>(nodes.size());
    const int n = 100000;
    for (int i = 0; i < n; ++i) {
        json node = {{"translation", {0, 0, 0.001}}};
        if (i + 1 < n)
            node["children"] = {first + i + 1};
        else
            node["mesh"] = 0;
        nodes.push_back(node);
    }
    t.b.doc["scenes"][0]["nodes"] = {0, first};
    auto m = parseModel(t.b.glb());
    ASSERT_TRUE(m.ok()) << m.error().message;
    ASSERT_EQ(m->parts.size(), 2u); // skinned under node 2, rigid at the chain's end
    EXPECT_NEAR(m->parts[1].positions[0].z, 0.001f * n, 0.1f); // float sums
    // The same chain closed into a cycle is refused.
    nodes.back()["children"] = {first};
    auto cycle = parseGltf(t.b.glb(), "");
    ASSERT_FALSE(cycle.ok());
    EXPECT_EQ(cycle.error().field.rfind("/nodes/", 0), 0u) << cycle.error().field;
}

TEST(GltfLoaderTest, GlbHeaderDamage) {
    SkinnedTriangle t;
    const std::vector<std::uint8_t> good = t.b.glb();
    ASSERT_TRUE(parseGltf(good, "").ok());
    auto with = [&](std::size_t at, std::uint32_t value) {
        std::vector<std::uint8_t> b = good;
        for (int k = 0; k < 4; ++k)
            b[at + static_cast<std::size_t>(k)] = static_cast<std::uint8_t>(value >> (8 * k));
        return b;
    };
    const std::size_t binHeader = 20 + getU32(good, 12);
    EXPECT_FALSE(parseGltf(with(4, 1), "").ok()); // version 1
    EXPECT_FALSE(parseGltf(with(8, static_cast<std::uint32_t>(good.size() + 4)), "").ok());
    EXPECT_FALSE(parseGltf(with(12, 0), "").ok());                  // empty JSON chunk
    EXPECT_FALSE(parseGltf(with(12, 0xFFFFFFF0u), "").ok());        // JSON past the end
    EXPECT_FALSE(parseGltf(with(binHeader, 0xFFFFFFF0u), "").ok()); // BIN past the end
    // BIN length that fits only without its 8-byte chunk header (tinygltf 2.7 misses this).
    EXPECT_FALSE(
        parseGltf(with(binHeader, static_cast<std::uint32_t>(good.size() - binHeader)), "").ok());
    // A shorter total length that cuts the BIN chunk.
    EXPECT_FALSE(parseGltf(with(8, static_cast<std::uint32_t>(good.size() - 4)), "").ok());
}

TEST(GltfLoaderTest, TruncatedSharedModelsAreErrors) {
    for (const std::string& path : {kCesiumMan, kRiggedFigure, kBarbarian}) {
        const auto bytes = readBytes(path);
        ASSERT_FALSE(bytes.empty()) << path << " is missing (shared models are required)";
        ASSERT_TRUE(parseGltf(bytes, "").ok()) << path;
        const std::size_t n = bytes.size();
        for (std::size_t cut : {std::size_t(1), std::size_t(12), std::size_t(20), std::size_t(100),
                                n / 5, n / 2, n - 1000, n - 8, n - 1}) {
            std::vector<std::uint8_t> b(bytes.begin(),
                                        bytes.begin() + static_cast<std::ptrdiff_t>(cut));
            auto r = parseGltf(b, "");
            EXPECT_FALSE(r.ok()) << path << " cut at " << cut;
        }
    }
}

TEST(GltfLoaderTest, BitFlipsGiveErrorsOrConsistentModels) {
    std::mt19937 rng(1234);
    // Small models get more flips; the JSON chunk (where structure lives) gets half of them.
    const std::vector<std::pair<std::string, int>> models = {
        {kCesiumMan, 120}, {kRiggedFigure, 120}, {kBarbarian, 6}};
    for (const auto& [path, flips] : models) {
        const auto bytes = readBytes(path);
        ASSERT_FALSE(bytes.empty()) << path << " is missing (shared models are required)";
        const std::size_t jsonEnd = 20 + getU32(bytes, 12);
        for (int k = 0; k < flips; ++k) {
            std::vector<std::uint8_t> b = bytes;
            const int nflips = 1 + static_cast<int>(rng() % 4);
            for (int f = 0; f < nflips; ++f) {
                const std::size_t at = k % 2 == 0 ? rng() % jsonEnd : rng() % b.size();
                b[at] ^= static_cast<std::uint8_t>(1u << (rng() % 8));
            }
            expectErrorOrConsistent(b, path + " flip set " + std::to_string(k));
        }
    }
}

TEST(GltfLoaderTest, RandomJsonNumberDamageGivesErrorsOrConsistentModels) {
    // Replace random integers of CesiumMan's JSON (indices, counts, offsets) with hostile ones.
    const auto bytes = readBytes(kCesiumMan);
    ASSERT_FALSE(bytes.empty()) << kCesiumMan << " is missing (shared models are required)";
    const auto [doc, bin] = splitGlb(bytes);
    std::vector<json::json_pointer> numbers;
    std::function<void(const json&, const json::json_pointer&)> collect =
        [&](const json& j, const json::json_pointer& ptr) {
            if (j.is_number_integer())
                numbers.push_back(ptr);
            else if (j.is_object())
                for (auto it = j.begin(); it != j.end(); ++it)
                    collect(*it, ptr / it.key());
            else if (j.is_array())
                for (std::size_t i = 0; i < j.size(); ++i)
                    collect(j[i], ptr / i);
        };
    collect(doc, json::json_pointer());
    ASSERT_GT(numbers.size(), 100u);
    std::mt19937 rng(99);
    const std::vector<json> hostile = {
        -1, 0, 1, 3, 255, 65536, 2147483647, 4294967295u, -2147483648LL, 1e300, "x"};
    for (int k = 0; k < 150; ++k) {
        json d = doc;
        d[numbers[rng() % numbers.size()]] = hostile[rng() % hostile.size()];
        expectErrorOrConsistent(makeGlb(d, bin), "damage " + std::to_string(k));
    }
}
