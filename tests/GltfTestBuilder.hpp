// GltfTestBuilder — what GltfLoaderTest and GltfLoaderDamageTest share: the shared models' paths,
// GLB assembly and splitting (glTF 2.0 §4.4), a Builder for small hand-made files (one buffer, one
// buffer view per array), a valid SkinnedTriangle whose accessor indices are kept for targeted
// damage, and the checks: every invariant of Model (expectConsistent), rest pose = bind pose and
// clips that move (expectRestReproducesBindAndClipsMove), an error naming the field
// (expectFieldError), an error or a consistent model (expectErrorOrConsistent), and files that
// declare far more than they hold (instancedZeroMesh: an accessor without a buffer view instanced
// by many nodes; pngHeader: a PNG that declares any size; withBaseColorImages). Header-only:
// everything is inline in dermis::test::gltf, so that both suites can include it.
#pragma once

#include "BuildPaths.hpp"
#include "TestFiles.hpp"
#include "core/rig.hpp"
#include "io/gltf_loader.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

namespace dermis::test::gltf {

using json = nlohmann::json;

inline const std::string kModels = std::string(dermis::build::testModelsDir()) + "/";
inline const std::string kCesiumMan = kModels + "CesiumMan/CesiumMan.glb";
inline const std::string kRiggedFigure = kModels + "RiggedFigure/RiggedFigure.glb";
inline const std::string kBarbarian = kModels + "KayKitBarbarian/Barbarian.glb";

inline constexpr int kFloat = 5126, kUByte = 5121, kUShort = 5123, kUInt = 5125;

// --- GLB assembly -----------------------------------------------------------------------------

inline void putU32(std::vector<std::uint8_t>& out, std::uint32_t v) {
    for (int k = 0; k < 4; ++k)
        out.push_back(static_cast<std::uint8_t>(v >> (8 * k)));
}

inline std::uint32_t getU32(const std::vector<std::uint8_t>& b, std::size_t at) {
    return std::uint32_t(b[at]) | std::uint32_t(b[at + 1]) << 8 | std::uint32_t(b[at + 2]) << 16 |
           std::uint32_t(b[at + 3]) << 24;
}

/// A GLB of `doc` and `bin` (glTF 2.0 §4.4), chunks padded to 4 bytes.
inline std::vector<std::uint8_t> makeGlb(const json& doc, std::vector<std::uint8_t> bin) {
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
inline std::pair<json, std::vector<std::uint8_t>> splitGlb(const std::vector<std::uint8_t>& glb) {
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

template <class T> inline std::vector<std::uint8_t> bytesOf(const std::vector<T>& v) {
    std::vector<std::uint8_t> out(v.size() * sizeof(T));
    if (!v.empty()) std::memcpy(out.data(), v.data(), out.size());
    return out;
}

inline int componentsOf(const std::string& type) {
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

/// SkinnedTriangle with two morph targets on its mesh (glTF 2.0 §3.7.2.2) named by
/// extras.targetNames: "smile" moves vertex 2 by (0, 0.5, 0) and tips its normal towards +x,
/// "blink" moves vertex 1 by (0, 0, 1); mesh weights [0.25, 0]; a second clip "face" drives the
/// weights LINEARly from [0, 0] at 0 s to [1, 0.5] at 1 s.
struct MorphedTriangle : SkinnedTriangle {
    int smilePosition, smileNormal, blinkPosition, faceTimes, faceWeights;

    MorphedTriangle() {
        smilePosition = b.add(std::vector<float>{0, 0, 0, 0, 0, 0, 0, 0.5f, 0}, kFloat, "VEC3");
        smileNormal = b.add(std::vector<float>{0, 0, 0, 0, 0, 0, 1, 0, 0}, kFloat, "VEC3");
        blinkPosition = b.add(std::vector<float>{0, 0, 0, 0, 0, 1, 0, 0, 0}, kFloat, "VEC3");
        json& mesh = b.doc["meshes"][0];
        mesh["primitives"][0]["targets"] =
            json::array({{{"POSITION", smilePosition}, {"NORMAL", smileNormal}},
                         {{"POSITION", blinkPosition}}});
        mesh["weights"] = {0.25, 0.0};
        mesh["extras"] = {{"targetNames", {"smile", "blink"}}};
        faceTimes = b.add(std::vector<float>{0, 1}, kFloat, "SCALAR");
        faceWeights = b.add(std::vector<float>{0, 0, 1, 0.5f}, kFloat, "SCALAR");
        b.doc["animations"].push_back(
            {{"name", "face"},
             {"samplers", {{{"input", faceTimes}, {"output", faceWeights}, {"interpolation", "LINEAR"}}}},
             {"channels", {{{"sampler", 0}, {"target", {{"node", 2}, {"path", "weights"}}}}}}});
    }
};

/// `m` with every part's morph targets baked in at `weights` (morphPart) and then dropped: what
/// morphing and skinning together must equal (GltfMorphTest, MorphGLTest).
inline Model bakedMorphs(const Model& m, const std::vector<float>& weights) {
    Model out = m;
    for (MeshPart& p : out.parts) {
        const MorphedPart mp = morphPart(m, p, weights);
        p.positions = mp.positions;
        p.normals = mp.normals;
        p.tangents = mp.tangents;
        p.morphs.clear();
    }
    out.morphWeights.clear();
    return out;
}

// --- files that declare more than they hold ---------------------------------------------------

/// A GLB of a few hundred bytes: one mesh whose POSITION accessor has no buffer view (so `count`
/// zeros, glTF 2.0 §3.6.2.1) and no indices, instanced by `instances` nodes of the scene. The
/// shape of issue #12's 440-byte file (5.6 M elements × 16 instances).
inline std::vector<std::uint8_t> instancedZeroMesh(std::size_t count = 5592405,
                                                   int instances = 16) {
    json nodes = json::array(), roots = json::array();
    for (int i = 0; i < instances; ++i) {
        nodes.push_back({{"mesh", 0}});
        roots.push_back(i);
    }
    json doc = {{"asset", {{"version", "2.0"}}},
                {"accessors", {{{"componentType", kFloat}, {"type", "VEC3"}, {"count", count}}}},
                {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}}}}}}}},
                {"nodes", nodes},
                {"scenes", {{{"nodes", roots}}}},
                {"scene", 0}};
    return makeGlb(doc, {});
}

/// CRC-32 (ISO 3309, as PNG uses) of `n` bytes.
inline std::uint32_t crc32Of(const std::uint8_t* p, std::size_t n) {
    std::uint32_t c = 0xFFFFFFFFu;
    for (std::size_t i = 0; i < n; ++i) {
        c ^= p[i];
        for (int k = 0; k < 8; ++k)
            c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
    }
    return c ^ 0xFFFFFFFFu;
}

/// A PNG signature, an IHDR chunk declaring `width` × `height` 8-bit RGB, then IEND: 45 bytes
/// whose header is valid and whose pixels are missing (any decoder fails after allocating).
inline std::vector<std::uint8_t> pngHeader(std::uint32_t width, std::uint32_t height) {
    std::vector<std::uint8_t> out = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    auto be = [&](std::vector<std::uint8_t>& v, std::uint32_t x) {
        for (int k = 3; k >= 0; --k)
            v.push_back(static_cast<std::uint8_t>(x >> (8 * k)));
    };
    auto chunk = [&](const char* type, const std::vector<std::uint8_t>& data) {
        be(out, static_cast<std::uint32_t>(data.size()));
        std::vector<std::uint8_t> body(type, type + 4);
        body.insert(body.end(), data.begin(), data.end());
        out.insert(out.end(), body.begin(), body.end());
        be(out, crc32Of(body.data(), body.size()));
    };
    std::vector<std::uint8_t> ihdr;
    be(ihdr, width);
    be(ihdr, height);
    ihdr.insert(ihdr.end(), {8, 2, 0, 0, 0}); // 8-bit, RGB, deflate, adaptive, no interlace
    chunk("IHDR", ihdr);
    chunk("IEND", {});
    return out;
}

/// `t` with one base-colour texture per image of `images` (PNG bytes in buffer views): material
/// i uses image i (material 0 is the triangle's).
inline void withBaseColorImages(SkinnedTriangle& t,
                                const std::vector<std::vector<std::uint8_t>>& images) {
    json& d = t.b.doc;
    d["images"] = json::array();
    d["textures"] = json::array();
    for (std::size_t i = 0; i < images.size(); ++i) {
        const int view = t.b.view(images[i]);
        d["images"].push_back({{"bufferView", view}, {"mimeType", "image/png"}});
        d["textures"].push_back({{"source", i}});
        if (i >= d["materials"].size()) d["materials"].push_back({{"name", "m" + std::to_string(i)}});
        d["materials"][i]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", i}};
    }
}

inline Result<Model> parseModel(const std::vector<std::uint8_t>& bytes) {
    auto parsed = parseGltf(bytes, "");
    if (!parsed) return parsed.error();
    if (auto s = loadGltfResources(*parsed); !s) return s.error();
    return std::move(parsed->model);
}

/// Expects `bytes` to be refused with an error naming `field`.
inline void expectFieldError(const std::vector<std::uint8_t>& bytes, const std::string& field,
                             ErrorCode code = ErrorCode::Parse) {
    auto r = parseGltf(bytes, "");
    ASSERT_FALSE(r.ok()) << "expected an error at " << field;
    EXPECT_EQ(r.error().field, field) << r.error().message;
    EXPECT_EQ(r.error().code, code) << r.error().message;
    EXPECT_NE(r.error().message.find("dermis::parseGltf"), std::string::npos) << r.error().message;
}

/// Every invariant Model promises (model.hpp), checked on whatever the loader returned.
inline void expectConsistent(const Model& m) {
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
        for (const MorphTarget& t : p.morphs) {
            ASSERT_TRUE(t.weight >= 0 && static_cast<std::size_t>(t.weight) < m.morphWeights.size());
            for (const auto* d : {&t.positions, &t.normals, &t.tangents})
                ASSERT_TRUE(d->empty() || d->size() == nv);
        }
    }
    for (const MorphWeight& w : m.morphWeights) {
        ASSERT_FALSE(w.name.empty());
        ASSERT_TRUE(w.node >= 0 && static_cast<std::size_t>(w.node) < nodes);
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
            const std::size_t comps = ch.path == ChannelPath::Rotation  ? 4
                                      : ch.path == ChannelPath::Weights ? static_cast<std::size_t>(ch.morphCount)
                                                                        : 3;
            if (ch.path == ChannelPath::Weights)
                ASSERT_TRUE(ch.morphFirst >= 0 && ch.morphCount > 0 &&
                            static_cast<std::size_t>(ch.morphFirst + ch.morphCount) <= m.morphWeights.size());
            const std::size_t per = ch.interpolation == Interpolation::CubicSpline ? 3 : 1;
            ASSERT_EQ(ch.values.size(), ch.times.size() * comps * per);
            ASSERT_LE(ch.times.back(), c.duration);
        }
    }
}

/// Largest distance between corresponding positions of two skinnings.
inline float maxDistance(const std::vector<SkinnedPart>& a, const std::vector<SkinnedPart>& b) {
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
inline void expectRestReproducesBindAndClipsMove(const Model& m) {
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
inline void expectErrorOrConsistent(const std::vector<std::uint8_t>& bytes,
                                    const std::string& what) {
    SCOPED_TRACE(what);
    auto r = parseGltf(bytes, "");
    if (!r.ok()) {
        EXPECT_FALSE(r.error().message.empty());
        return;
    }
    expectConsistent(r->model);
    (void)skin(r->model, worldMatrices(r->model, restPose(r->model)));
}

inline Result<Model> loadShared(const std::string& path) {
    auto m = loadGltfFile(path);
    EXPECT_TRUE(m.ok()) << path << ": " << (m.ok() ? "" : m.error().message)
                        << " (the shared models are required: " << kModels << ")";
    return m;
}

} // namespace dermis::test::gltf
