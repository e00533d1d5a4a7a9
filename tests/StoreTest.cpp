// StoreTest — the server's data folder (server/service/store): blobs and folder blobs with their
// metadata records, scene records, generated ids, unsafe names refused, unreadable records and
// leftovers of interrupted writes skipped. Files only; no GL, no HTTP.
#include "service/store.hpp"
#include "io/atomic_file.hpp"
#include "TestFiles.hpp"

#include <gtest/gtest.h>

#include <filesystem>

using namespace dermis;
using namespace dermis::test;
namespace fs = std::filesystem;

namespace {

std::vector<std::uint8_t> bytes(const std::string& s) { return {s.begin(), s.end()}; }

TEST(StoreTest, GeneratedIdsAreUniqueAndRecognised) {
    const std::string a = Store::newId("m"), b = Store::newId("m");
    EXPECT_NE(a, b);
    EXPECT_TRUE(Store::isGeneratedId(a, 'm'));
    EXPECT_FALSE(Store::isGeneratedId(a, 'p'));
    EXPECT_FALSE(Store::isGeneratedId("m_../../etc/pas", 'm'));
    EXPECT_FALSE(Store::isGeneratedId("m_0123456789ABCDEF", 'm'));
}

TEST(StoreTest, BlobsRoundTripAndRemove) {
    TempDir dir;
    auto store = Store::open(dir / "data");
    ASSERT_TRUE(store) << store.error().message;
    const std::string id = Store::newId("p");
    ASSERT_TRUE(store->putBlob("patterns", id, "png", bytes("PNGDATA"), {{"name", "ridge"}, {"created", 1.0}}));
    std::vector<std::string> skipped;
    auto blobs = store->listBlobs("patterns", skipped);
    ASSERT_EQ(blobs.size(), 1u);
    EXPECT_TRUE(skipped.empty());
    EXPECT_EQ(blobs[0].id, id);
    EXPECT_EQ(blobs[0].meta["name"], "ridge");
    EXPECT_EQ(*readWholeFile(blobs[0].file), bytes("PNGDATA"));
    ASSERT_TRUE(store->removeBlob("patterns", id));
    EXPECT_TRUE(store->listBlobs("patterns", skipped).empty());
    EXPECT_FALSE(fs::exists(blobs[0].file));
}

TEST(StoreTest, FolderBlobsHoldSeveralFilesAndRefuseUnsafeNames) {
    TempDir dir;
    auto store = Store::open(dir / "data");
    ASSERT_TRUE(store);
    const std::string id = Store::newId("m");
    ASSERT_TRUE(store->putBlobFolder("models", id, {{"a.gltf", bytes("{}")}, {"a.bin", bytes("BIN")}},
                                     "a.gltf", {{"name", "a"}}));
    std::vector<std::string> skipped;
    auto blobs = store->listBlobs("models", skipped);
    ASSERT_EQ(blobs.size(), 1u);
    EXPECT_EQ(fs::path(blobs[0].file).filename(), "a.gltf");
    EXPECT_EQ(*readWholeFile((fs::path(blobs[0].file).parent_path() / "a.bin").string()), bytes("BIN"));
    for (const char* bad : {"../x.bin", "/etc/passwd", "..", ".hidden", "a/b.bin", "a\\b", ""}) {
        EXPECT_FALSE(Store::isSafeFileName(bad)) << bad;
        auto s = store->putBlobFolder("models", Store::newId("m"), {{bad, bytes("x")}}, bad, {});
        EXPECT_FALSE(s) << bad;
    }
    EXPECT_EQ(store->listBlobs("models", skipped).size(), 1u);
    ASSERT_TRUE(store->removeBlob("models", id));
    EXPECT_FALSE(fs::exists(fs::path(blobs[0].file).parent_path()));
}

TEST(StoreTest, ScenesKeepTheirRevisionAndLatestDocument) {
    TempDir dir;
    auto store = Store::open(dir / "data");
    ASSERT_TRUE(store);
    ASSERT_TRUE(store->putScene("s_1", 1, {{"format", "dermis.scene/1"}}));
    ASSERT_TRUE(store->putScene("s_1", 2, {{"format", "dermis.scene/1"}, {"x", 2}}));
    ASSERT_TRUE(store->putScene("s_2", 7, {{"format", "dermis.scene/1"}}));
    std::vector<std::string> skipped;
    auto scenes = store->listScenes(skipped);
    ASSERT_EQ(scenes.size(), 2u);
    EXPECT_EQ(scenes[0].id, "s_1");
    EXPECT_EQ(scenes[0].revision, 2u);
    EXPECT_EQ(scenes[0].doc["x"], 2);
    ASSERT_TRUE(store->removeScene("s_2"));
    EXPECT_EQ(store->listScenes(skipped).size(), 1u);
}

TEST(StoreTest, SkipsUnreadableRecordsAndCleansInterruptedWrites) {
    TempDir dir;
    {
        auto store = Store::open(dir / "data");
        ASSERT_TRUE(store);
        ASSERT_TRUE(store->putScene("s_ok", 1, {{"format", "dermis.scene/1"}}));
    }
    writeText(dir / "data/scenes/s_bad.json", "{not json");
    writeText(dir / "data/models/m_orphan.json", R"({"id":"m_orphan","file":"m_orphan.glb"})"); // no data
    writeText(dir / "data/scenes/s_x.json.tmp.123.0", "half a write");
    fs::create_directories(dir / "data/models/m_y.d.tmp.42");
    fs::create_directories(dir / "data/upload.tmp.u_0123"); // an older version's scratch folder
    writeText(dir / "data/patterns/p_z.png.tmp.7.1", "half an upload");
    auto store = Store::open(dir / "data");
    ASSERT_TRUE(store);
    std::vector<std::string> skipped;
    EXPECT_EQ(store->listScenes(skipped).size(), 1u);
    EXPECT_EQ(store->listBlobs("models", skipped).size(), 0u);
    EXPECT_EQ(skipped.size(), 2u);
    EXPECT_FALSE(fs::exists(dir / "data/scenes/s_x.json.tmp.123.0"));
    EXPECT_FALSE(fs::exists(dir / "data/models/m_y.d.tmp.42"));
    EXPECT_FALSE(fs::exists(dir / "data/upload.tmp.u_0123"));
    EXPECT_FALSE(fs::exists(dir / "data/patterns/p_z.png.tmp.7.1"));
    EXPECT_TRUE(fs::exists(dir / "data/scenes/s_ok.json"));
}

} // namespace
