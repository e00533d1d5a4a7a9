// GltfLoaderDamageTest — corrupt glTF input (server/io/gltf_loader.hpp) that must give an Error
// naming the field at fault, never a crash (the suite also runs under ASan/UBSan): targeted damage
// to accessors and to the structure (nodes, skins, clips, materials, images, asset, extensions),
// points and lines skipped, empty and garbage input, deep nesting and long chains, GLB header
// damage, truncated shared models, bit flips and random damage to the JSON's numbers (an error or
// a model that keeps every invariant), and files that declare far more than they hold (issue #12:
// an accessor without a buffer view instanced by 16 nodes, 16384² textures), refused from their
// declared sizes with TooLarge before anything big is allocated (measured in a child process). The
// builders and checks are in GltfTestBuilder.hpp. Reads the shared models.
#include "GltfTestBuilder.hpp"
#include "io/image_header.hpp"

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <functional>
#include <limits>
#include <random>
#include <sstream>

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
        SkinnedTriangle t; // huge count: past the limits before anything is read
        t.b.doc["accessors"][static_cast<std::size_t>(t.position)]["count"] = 4294967295u;
        expectFieldError(t.b.glb(), pos, ErrorCode::TooLarge);
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

// --- declared sizes past the limits: refused before allocating ----------------------------------

namespace {

/// What a function run in a child process returned, how far its resident set grew above where it
/// started (VmHWM after resetting it through /proc/self/clear_refs), and how long it took.
struct ChildRun {
    bool finished = false; ///< the child reported (false: it crashed or was killed)
    std::string outcome;
    long peakGrowthKb = -1;
    double seconds = 0;
};

long procStatusKb(const char* key) {
    std::ifstream in("/proc/self/status");
    std::string line;
    while (std::getline(in, line))
        if (line.rfind(key, 0) == 0) return std::atol(line.c_str() + std::strlen(key));
    return -1;
}

/// Runs `fn` in a forked child. Without a sanitizer (which reserves terabytes of address space)
/// the child's address space is capped 1.5 GiB above its size, so that a loader that does
/// allocate gigabytes fails there instead of exhausting the machine.
ChildRun inChild(const std::function<std::string()>& fn) {
    int fds[2];
    if (pipe(fds) != 0) return {};
    const pid_t pid = fork();
    if (pid == 0) {
        close(fds[0]);
#if !defined(__SANITIZE_ADDRESS__)
        const long vmKb = procStatusKb("VmSize:");
        const rlim_t cap = static_cast<rlim_t>(vmKb) * 1024 + (rlim_t(3) << 29);
        rlimit lim{cap, cap};
        setrlimit(RLIMIT_AS, &lim);
#endif
        { std::ofstream("/proc/self/clear_refs") << "5"; } // resets VmHWM to the current RSS
        const long startKb = procStatusKb("VmRSS:");
        const auto t0 = std::chrono::steady_clock::now();
        std::string outcome;
        try {
            outcome = fn();
        } catch (const std::exception& e) {
            outcome = std::string("exception: ") + e.what();
        }
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        const std::string msg = std::to_string(procStatusKb("VmHWM:") - startKb) + " " +
                                std::to_string(seconds) + " " + outcome;
        if (write(fds[1], msg.data(), msg.size()) < 0) _exit(2);
        _exit(0);
    }
    close(fds[1]);
    std::string msg;
    char buf[4096];
    for (ssize_t n; (n = read(fds[0], buf, sizeof buf)) > 0;)
        msg.append(buf, static_cast<std::size_t>(n));
    close(fds[0]);
    int status = 0;
    waitpid(pid, &status, 0);
    ChildRun r;
    std::istringstream in(msg);
    if (!(in >> r.peakGrowthKb >> r.seconds)) return r;
    r.finished = true;
    std::getline(in >> std::ws, r.outcome);
    return r;
}

/// "code field message" of a failed result, "ok" otherwise.
template <class R> std::string outcomeOf(const R& r) {
    if (r.ok()) return "ok";
    return std::to_string(static_cast<int>(r.error().code)) + " " + r.error().field + " " +
           r.error().message;
}

std::string expectedOutcome(ErrorCode code, const std::string& field) {
    return std::to_string(static_cast<int>(code)) + " " + field + " ";
}

constexpr long kPeakLimitKb = 200 * 1024;

} // namespace

TEST(GltfLoaderDamageTest, InstancedZeroFilledMeshIsRefusedFromItsDeclaredSize) {
    // Issue #12: 440 bytes, one mesh of 5.6 M zero-filled vertices instanced by 16 nodes (5.2 GB
    // and 17 s before the limit was checked after conversion).
    const std::vector<std::uint8_t> glb = instancedZeroMesh();
    EXPECT_LT(glb.size(), 600u);
    const ChildRun run = inChild([&] { return outcomeOf(parseGltf(glb, "")); });
    ASSERT_TRUE(run.finished) << "the loader crashed or was killed";
    const std::string field = "/meshes/0/primitives/0/attributes/POSITION";
    EXPECT_EQ(run.outcome.rfind(expectedOutcome(ErrorCode::TooLarge, field), 0), 0u) << run.outcome;
    EXPECT_NE(run.outcome.find("16 instances"), std::string::npos) << run.outcome;
    EXPECT_NE(run.outcome.find("max_triangles 1000000"), std::string::npos) << run.outcome;
    EXPECT_LT(run.peakGrowthKb, kPeakLimitKb);
    std::printf("instanced zero mesh (%zu bytes): refused in %.4f s, peak +%ld KiB\n", glb.size(),
                run.seconds, run.peakGrowthKb);

    // One instance of a mesh within the limits loads; the same under a lower triangle limit not.
    auto one = parseGltf(instancedZeroMesh(30, 1), "");
    ASSERT_TRUE(one.ok()) << one.error().message;
    EXPECT_EQ(one->model.triangleCount(), 10u);
    GltfLimits low;
    low.maxTriangles = 100;
    auto many = parseGltf(instancedZeroMesh(30, 11), "", low);
    ASSERT_FALSE(many.ok());
    EXPECT_EQ(many.error().code, ErrorCode::TooLarge);
    EXPECT_EQ(many.error().field, field);
    EXPECT_TRUE(parseGltf(instancedZeroMesh(30, 10), "", low).ok());
}

TEST(GltfLoaderDamageTest, AccessorCountsJointsAndPartsAreCheckedBeforeReading) {
    GltfLimits low;
    low.maxJoints = 1;
    {
        SkinnedTriangle t; // a zero-filled NORMAL far longer than POSITION: refused unread
        t.b.doc["accessors"][static_cast<std::size_t>(t.normal)].erase("bufferView");
        t.b.doc["accessors"][static_cast<std::size_t>(t.normal)]["count"] = 100000000;
        expectFieldError(t.b.glb(), "/meshes/0/primitives/0/attributes/NORMAL",
                         ErrorCode::TooLarge);
    }
    {
        SkinnedTriangle t; // animation keys without a buffer view
        t.b.doc["accessors"][static_cast<std::size_t>(t.rotations)].erase("bufferView");
        t.b.doc["accessors"][static_cast<std::size_t>(t.rotations)]["count"] = 100000000;
        expectFieldError(t.b.glb(), "/animations/0/samplers/0/output", ErrorCode::TooLarge);
    }
    {
        SkinnedTriangle t; // one sampler read by many channels: each use counts
        json channels = json::array();
        for (int k = 0; k < 100; ++k)
            channels.push_back({{"sampler", 0}, {"target", {{"node", 1}, {"path", "rotation"}}}});
        t.b.doc["animations"][0]["channels"] = channels;
        t.b.doc["accessors"][static_cast<std::size_t>(t.times)].erase("bufferView");
        t.b.doc["accessors"][static_cast<std::size_t>(t.times)]["count"] = 3000000;
        t.b.doc["accessors"][static_cast<std::size_t>(t.rotations)].erase("bufferView");
        t.b.doc["accessors"][static_cast<std::size_t>(t.rotations)]["count"] = 3000000;
        // 15 M values per channel; the fifth channel's output passes 72 M.
        expectFieldError(t.b.glb(), "/animations/0/samplers/0/output", ErrorCode::TooLarge);
    }
    {
        SkinnedTriangle t; // two joints, one allowed
        auto r = parseGltf(t.b.glb(), "", low);
        ASSERT_FALSE(r.ok());
        EXPECT_EQ(r.error().code, ErrorCode::TooLarge);
        EXPECT_EQ(r.error().field, "/skins/0/joints");
        EXPECT_NE(r.error().message.find("max_joints 1"), std::string::npos) << r.error().message;
    }
    {
        SkinnedTriangle t; // the same joint listed many times still counts per listing
        t.b.doc["skins"][0]["joints"] = json::array({0, 0, 0});
        low.maxJoints = 2;
        auto r = parseGltf(t.b.glb(), "", low);
        ASSERT_FALSE(r.ok());
        EXPECT_EQ(r.error().field, "/skins/0/joints");
    }
    {
        SkinnedTriangle t; // mesh parts after instancing
        GltfLimits parts;
        parts.maxParts = 2;
        for (int k = 0; k < 2; ++k) {
            t.b.doc["nodes"].push_back({{"mesh", 0}});
            t.b.doc["nodes"][0]["children"].push_back(3 + k);
        }
        auto r = parseGltf(t.b.glb(), "", parts);
        ASSERT_FALSE(r.ok());
        EXPECT_EQ(r.error().code, ErrorCode::TooLarge);
        EXPECT_EQ(r.error().field, "/meshes/0/primitives/0");
        parts.maxParts = 3;
        EXPECT_TRUE(parseGltf(t.b.glb(), "", parts).ok());
    }
    // The shared models load under the server's default limits.
    for (const std::string& path : {kCesiumMan, kRiggedFigure, kBarbarian})
        EXPECT_TRUE(loadGltfFile(path).ok()) << path;
}

TEST(GltfLoaderDamageTest, HugeTexturesAreRefusedFromTheirHeaderBeforeDecoding) {
    // Issue #12: three 16384² PNG textures (4.4 GB held). Here the PNGs are headers without
    // pixels: a decoder would allocate 16384² × 4 bytes before finding that out.
    const std::vector<std::uint8_t> huge = pngHeader(16384, 16384);
    SkinnedTriangle t;
    withBaseColorImages(t, {huge, huge, huge});
    const std::vector<std::uint8_t> glb = t.b.glb();
    const ChildRun run = inChild([&] {
        auto parsed = parseGltf(glb, "");
        if (!parsed) return "parse: " + outcomeOf(parsed);
        return outcomeOf(loadGltfResources(*parsed));
    });
    ASSERT_TRUE(run.finished) << "the loader crashed or was killed";
    EXPECT_EQ(run.outcome.rfind(expectedOutcome(ErrorCode::TooLarge, "/images/0"), 0), 0u)
        << run.outcome;
    EXPECT_NE(run.outcome.find("16384×16384"), std::string::npos) << run.outcome;
    EXPECT_LT(run.peakGrowthKb, kPeakLimitKb);
    std::printf("three 16384² textures (%zu bytes): refused in %.4f s, peak +%ld KiB\n",
                glb.size(), run.seconds, run.peakGrowthKb);

    // The budget counts every texture: two 64×64 fit in 40000 bytes, three do not (the third
    // named).
    GltfLimits budget;
    budget.maxTextureBytes = 40000;
    const std::vector<std::uint8_t> small = pngHeader(64, 64);
    SkinnedTriangle three;
    withBaseColorImages(three, {small, small, small});
    auto parsed = parseGltf(three.b.glb(), "", budget);
    ASSERT_TRUE(parsed.ok()) << parsed.error().message;
    auto s = loadGltfResources(*parsed, budget);
    ASSERT_FALSE(s.ok());
    EXPECT_EQ(s.error().code, ErrorCode::TooLarge);
    EXPECT_EQ(s.error().field, "/images/2");

    // Not a PNG or JPEG: refused before decoding, naming the image.
    SkinnedTriangle other;
    withBaseColorImages(other, {std::vector<std::uint8_t>{'G', 'I', 'F', '8', '9', 'a', 0, 0}});
    auto p2 = parseGltf(other.b.glb(), "");
    ASSERT_TRUE(p2.ok()) << p2.error().message;
    auto s2 = loadGltfResources(*p2);
    ASSERT_FALSE(s2.ok());
    EXPECT_EQ(s2.error().field, "/images/0");
}

TEST(GltfLoaderDamageTest, TexturesOverTheSideLimitAreDownscaled) {
    TempDir dir;
    // 64 × 32: left half red, right half blue; JPEG and PNG headers give the declared size.
    std::vector<std::uint8_t> px(64 * 32 * 3, 0);
    for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 64; ++x)
            px[static_cast<std::size_t>((y * 64 + x) * 3 + (x < 32 ? 0 : 2))] = 255;
    writeImage(dir / "tex.png", 64, 32, 3, px, OIIO::TypeDesc::UINT8);
    writeImage(dir / "tex.jpg", 64, 32, 3, px, OIIO::TypeDesc::UINT8);
    const std::vector<std::uint8_t> png = readBytes(dir / "tex.png");
    const std::vector<std::uint8_t> jpg = readBytes(dir / "tex.jpg");
    for (const auto* bytes : {&png, &jpg}) {
        const auto size = encodedImageSize(bytes->data(), bytes->size());
        ASSERT_TRUE(size);
        EXPECT_EQ(size->width, 64u);
        EXPECT_EQ(size->height, 32u);
        for (std::size_t cut : {std::size_t(0), std::size_t(10), std::size_t(20)})
            EXPECT_FALSE(encodedImageSize(bytes->data(), cut)) << cut; // truncated header
    }

    SkinnedTriangle t;
    withBaseColorImages(t, {png});
    GltfLimits limits;
    limits.maxImageSide = 16;
    auto parsed = parseGltf(t.b.glb(), "", limits);
    ASSERT_TRUE(parsed.ok()) << parsed.error().message;
    ASSERT_TRUE(loadGltfResources(*parsed, limits).ok());
    const Image8& img = parsed->model.images[0];
    ASSERT_EQ(img.width, 16);
    ASSERT_EQ(img.height, 8);
    ASSERT_EQ(img.rgba.size(), 16u * 8u * 4u);
    EXPECT_EQ((std::vector<std::uint8_t>(img.rgba.begin(), img.rgba.begin() + 4)),
              (std::vector<std::uint8_t>{255, 0, 0, 255}));
    EXPECT_EQ((std::vector<std::uint8_t>(img.rgba.end() - 4, img.rgba.end())),
              (std::vector<std::uint8_t>{0, 0, 255, 255}));
}
