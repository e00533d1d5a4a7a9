// GltfLoaderDamageTest — corrupt glTF input (server/io/gltf_loader.hpp) that must give an Error
// naming the field at fault, never a crash (the suite also runs under ASan/UBSan): targeted damage
// to accessors and to the structure (nodes, skins, clips, materials, images, asset, extensions),
// points and lines skipped, empty and garbage input, deep nesting and long chains, GLB header
// damage, truncated shared models, bit flips and random damage to the JSON's numbers (an error or
// a model that keeps every invariant). The builders and checks are in GltfTestBuilder.hpp. Reads
// the shared models.
#include "GltfTestBuilder.hpp"

#include <functional>
#include <limits>
#include <random>

using namespace dermis;
using namespace dermis::test;
using namespace dermis::test::gltf;

// --- corrupt input: targeted damage names the field ------------------------------------------

TEST(GltfLoaderDamageTest, DamagedAccessorsNameTheAttribute) {
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

TEST(GltfLoaderDamageTest, DamagedStructureNamesTheField) {
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

TEST(GltfLoaderDamageTest, PointsAndLinesAreSkipped) {
    SkinnedTriangle t;
    t.b.doc["meshes"][0]["primitives"][0]["mode"] = 1; // LINES
    auto m = parseModel(t.b.glb());
    ASSERT_TRUE(m.ok()) << m.error().message;
    EXPECT_TRUE(m->parts.empty());
}

// --- corrupt input: truncation, garbage, bit flips ----------------------------------------------

TEST(GltfLoaderDamageTest, EmptyAndGarbageInputAreErrors) {
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

TEST(GltfLoaderDamageTest, DeepNestingAndLongChainsDoNotExhaustTheStack) {
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

TEST(GltfLoaderDamageTest, GlbHeaderDamage) {
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

TEST(GltfLoaderDamageTest, TruncatedSharedModelsAreErrors) {
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

TEST(GltfLoaderDamageTest, BitFlipsGiveErrorsOrConsistentModels) {
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

TEST(GltfLoaderDamageTest, RandomJsonNumberDamageGivesErrorsOrConsistentModels) {
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
