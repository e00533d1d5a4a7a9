// LayoutCacheTest — generated layouts cached per model content, in memory and in a data folder
// (service/layout_cache): one generation per content, a second process reads the file, a damaged
// file is rebuilt, failures are not cached, concurrent first requests share one generation, and
// a folder that cannot be written only loses the disk copy.
#include "service/layout_cache.hpp"

#include "core/layout_codec.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <thread>
#include <vector>

using namespace dermis;
namespace fs = std::filesystem;

namespace {

std::shared_ptr<const Model> quadModel(float lift = 0.0f) {
    auto m = std::make_shared<Model>();
    MeshPart p;
    p.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, lift}, {1, 1, 0}};
    p.normals.assign(4, glm::vec3(0, 0, 1));
    p.indices = {0, 1, 2, 2, 1, 3};
    m->parts.push_back(p);
    return m;
}

/// A stand-in generator: the model's triangles spread along u, counting its calls.
struct CountingGenerator {
    std::shared_ptr<std::atomic<int>> calls = std::make_shared<std::atomic<int>>(0);
    bool fail = false;
    LayoutCache::Generator fn() {
        return [calls = calls, fail = fail](const Model& m) -> Result<TextureLayout> {
            ++*calls;
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
            if (fail) return makeError(ErrorCode::Unsupported, "fake", "", "cannot lay this out");
            TextureLayout l;
            l.kind = "generated";
            for (const MeshPart& p : m.parts) {
                PartLayout pl;
                for (std::size_t k = 0; k < p.indices.size(); ++k) {
                    pl.source.push_back(p.indices[k]);
                    pl.uvs.push_back({0.1f + 0.01f * float(k), 0.5f});
                    pl.indices.push_back(static_cast<std::uint32_t>(k));
                }
                l.parts.push_back(pl);
            }
            return l;
        };
    }
};

struct TempDir {
    fs::path path = fs::temp_directory_path() / ("dermis-layoutcache-" + std::to_string(::getpid()) + "-" +
                                                 std::to_string(std::rand()));
    ~TempDir() { std::error_code ec; fs::remove_all(path, ec); }
};

} // namespace

TEST(LayoutCacheTest, OneGenerationPerContentThenMemory) {
    TempDir dir;
    CountingGenerator gen;
    LayoutCache cache(dir.path.string(), "test1", gen.fn());
    auto a = quadModel();
    auto first = cache.generated(a);
    ASSERT_TRUE(first) << first.error().message;
    auto second = cache.generated(a);
    ASSERT_TRUE(second);
    EXPECT_EQ(first->get(), second->get());
    // Another model object with the same bytes is the same content.
    auto same = cache.generated(quadModel());
    ASSERT_TRUE(same);
    EXPECT_EQ(same->get(), first->get());
    EXPECT_EQ(gen.calls->load(), 1);
    EXPECT_EQ(cache.stats().memoryHits, 2u);
    // Other bytes: a new generation.
    ASSERT_TRUE(cache.generated(quadModel(0.5f)));
    EXPECT_EQ(gen.calls->load(), 2);
    EXPECT_TRUE(fs::exists(dir.path / (cache.keyOf(a) + ".bin")));
}

TEST(LayoutCacheTest, AnotherProcessReadsTheFileAndADamagedFileIsRebuilt) {
    TempDir dir;
    CountingGenerator gen;
    auto a = quadModel();
    std::string key;
    std::vector<std::uint8_t> bytes;
    {
        LayoutCache cache(dir.path.string(), "test1", gen.fn());
        auto l = cache.generated(a);
        ASSERT_TRUE(l);
        key = cache.keyOf(a);
        bytes = encodeTextureLayout(**l);
    }
    {
        LayoutCache cache(dir.path.string(), "test1", gen.fn());
        auto l = cache.generated(a);
        ASSERT_TRUE(l);
        EXPECT_EQ(encodeTextureLayout(**l), bytes);
        EXPECT_EQ(cache.stats().diskHits, 1u);
        EXPECT_EQ(gen.calls->load(), 1);
    }
    { std::ofstream(dir.path / (key + ".bin"), std::ios::binary | std::ios::trunc) << "DMLY garbage"; }
    {
        LayoutCache cache(dir.path.string(), "test1", gen.fn());
        auto l = cache.generated(a);
        ASSERT_TRUE(l);
        EXPECT_EQ(gen.calls->load(), 2);
        EXPECT_EQ(fs::file_size(dir.path / (key + ".bin")), bytes.size()); // rewritten
    }
    // A new salt (generator version) never reads the old file.
    LayoutCache other(dir.path.string(), "test2", gen.fn());
    EXPECT_NE(other.keyOf(a), key);
    ASSERT_TRUE(other.generated(a));
    EXPECT_EQ(gen.calls->load(), 3);
}

TEST(LayoutCacheTest, FailuresAreNotCached) {
    CountingGenerator gen;
    gen.fail = true;
    LayoutCache cache("", "test1", gen.fn());
    auto a = quadModel();
    auto r = cache.generated(a);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("cannot lay this out"), std::string::npos);
    EXPECT_FALSE(cache.generated(a));
    EXPECT_EQ(gen.calls->load(), 2);
}

TEST(LayoutCacheTest, ConcurrentFirstRequestsShareOneGeneration) {
    CountingGenerator gen;
    LayoutCache cache("", "test1", gen.fn());
    auto a = quadModel();
    std::vector<std::thread> threads;
    std::vector<const TextureLayout*> got(6, nullptr);
    for (int t = 0; t < 6; ++t)
        threads.emplace_back([&, t] { if (auto l = cache.generated(a)) got[t] = l->get(); });
    for (auto& t : threads) t.join();
    EXPECT_EQ(gen.calls->load(), 1);
    for (auto* p : got) EXPECT_EQ(p, got[0]);
    EXPECT_NE(got[0], nullptr);
}

TEST(LayoutCacheTest, AnUnwritableFolderOnlyLosesTheDiskCopy) {
    TempDir dir;
    fs::create_directories(dir.path);
    { std::ofstream(dir.path / "file") << "x"; }
    CountingGenerator gen;
    LayoutCache cache((dir.path / "file" / "layouts").string(), "test1", gen.fn()); // under a file
    auto l = cache.generated(quadModel());
    ASSERT_TRUE(l);
    EXPECT_EQ(cache.stats().diskWriteFailures, 1u);
    EXPECT_TRUE(cache.generated(quadModel()));
    EXPECT_EQ(gen.calls->load(), 1);
}

TEST(LayoutCacheTest, KeepsTheNewestEntries) {
    CountingGenerator gen;
    LayoutCache cache("", "test1", gen.fn(), 2);
    auto a = quadModel(0.1f), b = quadModel(0.2f), c = quadModel(0.3f);
    ASSERT_TRUE(cache.generated(a));
    ASSERT_TRUE(cache.generated(b));
    ASSERT_TRUE(cache.generated(c)); // a is dropped
    EXPECT_EQ(gen.calls->load(), 3);
    ASSERT_TRUE(cache.generated(c));
    EXPECT_EQ(gen.calls->load(), 3);
    ASSERT_TRUE(cache.generated(a));
    EXPECT_EQ(gen.calls->load(), 4);
}

