// StoreHistoryTest — a scene's history in the data folder (server/service/store_history.cpp,
// history_format.hpp): revisions stored as RFC 6902 patches in chunks that start with a snapshot.
//   * the patches turn every document into the next byte for byte (doubles bit for bit, 1 vs 1.0,
//     −0.0, inserts and deletes in long arrays, keys with "/" and "~"); chunk lines are scanned
//     without parsing their documents and a torn line ends a chunk; the --history-keep values;
//   * every revision reads back byte for byte as written, across chunk boundaries and after
//     reopening; a one-placement edit of a 1,000-placement scene takes ≤ 2 KB on disk (the
//     snapshots' share included); folders of whole-revision files (earlier versions) still read
//     and go on as chunks; an interrupted commit is forgotten;
//   * retention by count and by age keeps exactly the newest revisions and deletes the files of
//     the others; a compaction interrupted at each of its steps leaves a history that opens with
//     every kept revision intact; a writer killed with SIGKILL at random points (commits and
//     compactions) loses no acknowledged revision.
// Files only; no GL, no HTTP.
#include "service/store.hpp"
#include "io/atomic_file.hpp"
#include "TestFiles.hpp"

#include <gtest/gtest.h>

#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <iostream>
#include <random>

using namespace dermis;
using namespace dermis::test;
namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

/// A placement as the canonical document writes one (core/scene.cpp toJson): ~250 bytes.
json placement(int k, double u, double h = 1.0) {
    json e = json::object();
    e["id"] = "p" + std::to_string(k);
    e["pattern"] = "crease";
    e["center"] = {u, 0.25 + 0.0005 * (k % 1000)};
    e["scale"] = {0.08, 0.05};
    e["rotation"] = 0.0;
    e["joint"] = "forearm.l";
    e["axis"] = "x";
    e["theta_min"] = 0.0;
    e["theta_max"] = 120.0;
    e["h"] = h;
    e["model"] = "scale";
    e["target"] = "bump";
    e["response"] = "linear";
    e["enabled"] = true;
    e["label"] = "";
    return e;
}

/// A canonical-looking scene of `n` placements.
json sceneOf(int n) {
    json doc = {{"format", "dermis.scene/1"},
                {"model", "builtin:default"},
                {"heightmap", {{"size", {1024, 1024}}}},
                {"patterns", json::object()},
                {"pose", {{"time", 0.0}, {"joints", json::object()}}},
                {"render",
                 {{"size", {512, 512}},
                  {"camera", {{"yaw", 0.0}, {"pitch", 10.0}, {"distance", "auto"}}},
                  {"displacement_scale", "auto"},
                  {"bump_strength", 1.0},
                  {"msaa", 4},
                  {"displacement", "off"}}}};
    json placements = json::array();
    for (int k = 0; k < n; ++k) placements.push_back(placement(k, 0.1 + 0.0007 * k));
    doc["placements"] = std::move(placements);
    return doc;
}

/// One random edit of the kind an editor makes: a placement's field, a new placement (anywhere),
/// a deleted one, one moved, the pose, an odd value (−0.0, 1 vs 1.0, a key with "/" and "~"), a
/// placement's member that sorts first or last, or is written with escapes, added and removed
/// (the text splices of a chunk's replay).
void randomEdit(json& doc, std::mt19937& rng, int& nextId) {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    if (!doc.contains("placements") || !doc["placements"].is_array()) doc["placements"] = json::array();
    json& pl = doc["placements"];
    const std::size_t n = pl.size();
    auto any = [&](std::size_t m) { return static_cast<std::size_t>(rng() % std::max<std::size_t>(1, m)); };
    switch (rng() % 11) {
    case 0: case 1: case 2: case 3:
        if (n) pl[any(n)]["center"] = {u(rng), u(rng)};
        break;
    case 4:
        if (n) pl[any(n)]["h"] = (rng() % 2) ? json(u(rng) * 4) : json(1.0);
        break;
    case 5:
        pl.insert(pl.begin() + static_cast<std::ptrdiff_t>(any(n + 1)), placement(nextId++, u(rng)));
        break;
    case 6:
        if (n > 1) pl.erase(any(n));
        break;
    case 7:
        if (n > 2) {
            json p = pl[any(n)];
            pl.erase(pl.begin());
            pl.insert(pl.begin() + static_cast<std::ptrdiff_t>(any(pl.size() + 1)), p);
        }
        break;
    case 8:
        doc["pose"]["time"] = u(rng);
        doc["pose"]["joints"]["upper/arm~l"] = {{"axis_angles", {{"x", u(rng) * 90}, {"y", 0.0}, {"z", 0.0}}}};
        break;
    case 9:
        if (n) {
            json& p = pl[any(n)];
            static const char* const kOdd[] = {"aa_first", "zz_last", "q\"uote", "sl/ash~t", "\u00e9t\u00e9"};
            const std::string key = kOdd[rng() % 5];
            if (p.contains(key) && rng() % 2) p.erase(key);
            else p[key] = (rng() % 2) ? json(u(rng)) : json::array({1, "x", nullptr});
        }
        break;
    default:
        if (n) {
            json& p = pl[any(n)];
            p["rotation"] = (rng() % 2) ? json(-0.0) : json(0.0);
            p["label"] = (rng() % 2) ? json(std::string(rng() % 40, 'x')) : json(1u);
            if (rng() % 3 == 0) p.erase("label");
        }
        break;
    }
}

/// The bytes of every file under `dir`, and the blocks they take (st_blocks · 512).
std::pair<std::uintmax_t, std::uintmax_t> folderBytes(const std::string& dir) {
    std::uintmax_t bytes = 0, blocks = 0;
    for (const auto& e : fs::recursive_directory_iterator(dir)) {
        if (!e.is_regular_file()) continue;
        bytes += e.file_size();
        struct stat st {};
        if (::stat(e.path().c_str(), &st) == 0) blocks += static_cast<std::uintmax_t>(st.st_blocks) * 512;
    }
    return {bytes, blocks};
}

/// What Service::State::applyRetention does with a scene's kept revisions (oldest first):
/// trims `history` to `keep`'s window at `now` and compacts when the store says so.
std::uint64_t retain(Store& store, const std::string& id, std::vector<RevisionInfo>& history,
                     const HistoryRetention& keep, double now) {
    const std::uint64_t oldest = oldestKept(history, keep, now);
    while (!history.empty() && history.front().revision < oldest) history.erase(history.begin());
    if (store.compactionDue(id, oldest)) EXPECT_TRUE(store.dropRevisionsBefore(id, oldest, history));
    return oldest;
}

std::string hist(const TempDir& dir, const std::string& id) { return dir / ("data/scenes/" + id + ".history"); }

// --- the format --------------------------------------------------------------------------------------

TEST(StoreHistoryTest, PatchesTurnEveryDocumentIntoTheNextByteForByte) {
    std::mt19937 rng(27);
    int nextId = 1000;
    json doc = sceneOf(40);
    // Chunks of 40 revisions, as the store writes them: each revision read back from its chunk's
    // text (the snapshot split, only touched parts parsed) and from a tree the patches applied to.
    std::string chunk = snapshotLine(1, doc.dump());
    std::uint64_t base = 1;
    std::vector<std::string> texts = {doc.dump()};
    for (std::uint64_t revision = 2; revision <= 3000; ++revision) {
        json next = doc;
        randomEdit(next, rng, nextId);
        if (revision % 7 == 0) randomEdit(next, rng, nextId);
        if (revision % 500 == 0) next["placements"] = json::array({json{{"a", 1}}, json{{"b", 2}}}); // not an editor's
        if (revision % 501 == 0) next.erase("placements");
        if (revision % 502 == 0) next = sceneOf(3);
        const json patch = historyDiff(doc, next);
        json replay = json::parse(doc.dump());
        ASSERT_TRUE(applyHistoryPatch(replay, json::parse(patch.dump()), "test")) << patch.dump();
        ASSERT_EQ(replay.dump(), next.dump()) << "revision " << revision << ": " << patch.dump();
        if ((revision - 1) % 40 == 0) {
            chunk = snapshotLine(revision, next.dump());
            base = revision;
            texts = {next.dump()};
        } else {
            chunk += patchLine(revision, patch);
            texts.push_back(next.dump());
            const std::uint64_t r = base + rng() % texts.size();
            auto text = replayChunk(chunk, base, r, "c.jsonl", "test");
            ASSERT_TRUE(text) << text.error().message;
            ASSERT_EQ(*text, texts[r - base]) << "revision " << r << " of chunk " << base;
        }
        doc = std::move(next);
    }
    for (std::uint64_t r = base; r < base + texts.size(); ++r)
        ASSERT_EQ(*replayChunk(chunk, base, r, "c.jsonl", "test"), texts[r - base]);
    // A document that is not an object, and a root replaced: read back all the same.
    const std::string odd = snapshotLine(1, "[1,2]") + patchLine(2, historyDiff(json::array({1, 2}), {{"x", 1}})) +
                            patchLine(3, historyDiff({{"x", 1}}, {{"placements", json::array()}, {"x", 1}})) +
                            patchLine(4, historyDiff({{"placements", json::array()}, {"x", 1}},
                                                     {{"placements", {placement(1, 0.5)}}, {"x", 1}}));
    EXPECT_EQ(*replayChunk(odd, 1, 2, "c1.jsonl", "test"), R"({"x":1})");
    EXPECT_EQ(*replayChunk(odd, 1, 4, "c1.jsonl", "test"), json({{"placements", {placement(1, 0.5)}}, {"x", 1}}).dump());
    // Strict: values nlohmann::json::operator== calls equal still differ when their text does.
    for (const auto& [a, b] : std::vector<std::pair<json, json>>{{0.0, -0.0}, {1u, 1.0}, {1, 1u}}) {
        const json patch = historyDiff({{"x", a}}, {{"x", b}});
        json replay = {{"x", a}};
        ASSERT_TRUE(applyHistoryPatch(replay, patch, "test"));
        EXPECT_EQ(replay.dump(), json({{"x", b}}).dump()) << patch.dump();
    }
    EXPECT_EQ(historyDiff(doc, doc), json::array());
    json root = json::array({1, 2});
    ASSERT_TRUE(applyHistoryPatch(root, historyDiff(root, "text"), "test"));
    EXPECT_EQ(root, "text");
    json bad = {{"a", 1}};
    auto refused = applyHistoryPatch(bad, json::parse(R"([{"op":"remove","path":"/b"}])"), "test");
    ASSERT_FALSE(refused);
    EXPECT_EQ(refused.error().code, ErrorCode::Parse);
}

TEST(StoreHistoryTest, AOnePlacementEditIsOneSmallOperation) {
    const json a = sceneOf(1000);
    json b = a;
    b["placements"][517]["center"] = {0.123456789, 0.5};
    EXPECT_EQ(historyDiff(a, b).dump(),
              R"([{"op":"replace","path":"/placements/517/center","value":[0.123456789,0.5]}])");
    json c = a;
    c["placements"].erase(300);
    EXPECT_EQ(historyDiff(a, c).dump(), R"([{"op":"remove","path":"/placements/300"}])");
    json d = a;
    d["placements"].insert(d["placements"].begin() + 10, placement(5000, 0.5));
    const json add = historyDiff(a, d);
    ASSERT_EQ(add.size(), 1u);
    EXPECT_EQ(add[0]["op"], "add");
    EXPECT_EQ(add[0]["path"], "/placements/10");
    EXPECT_LT(patchLine(2, add).size(), 320u);
}

TEST(StoreHistoryTest, ChunkLinesAreScannedAndATornOneEndsTheChunk) {
    const std::string text = snapshotLine(7, R"({"a":1})") +
                             patchLine(8, json::parse(R"([{"op":"replace","path":"/a","value":2}])")) +
                             patchLine(9, json::parse(R"([{"op":"add","path":"/b","value":"}\n"}])"));
    auto lines = scanChunk(text);
    ASSERT_EQ(lines.size(), 3u);
    EXPECT_TRUE(lines[0].snapshot);
    EXPECT_EQ(lines[2].revision, 9u);
    EXPECT_EQ(lines[2].end, text.size());
    EXPECT_EQ(scanChunk(text, 8).size(), 2u);
    EXPECT_EQ(scanChunk(text + "{\"revision\":10,\"patch\":[{\"op\"").size(), 3u); // torn append
    EXPECT_EQ(scanChunk(text + "garbage\n" + patchLine(10, json::array())).size(), 3u);
    EXPECT_EQ(*replayChunk(text, 7, 9, "c7.jsonl", "test"), R"({"a":2,"b":"}\n"})");
    EXPECT_EQ(*replayChunk(text, 7, 7, "c7.jsonl", "test"), R"({"a":1})");
    EXPECT_EQ(replayChunk(text, 7, 10, "c7.jsonl", "test").error().code, ErrorCode::NotFound);
    EXPECT_EQ(replayChunk(text, 6, 9, "c6.jsonl", "test").error().code, ErrorCode::Parse);
    const std::string skipped = snapshotLine(7, R"({"a":1})") + patchLine(9, json::array());
    EXPECT_EQ(replayChunk(skipped, 7, 9, "c7.jsonl", "test").error().code, ErrorCode::Parse);
}

TEST(StoreHistoryTest, RetentionParsesItsFlagAndPicksTheWindow) {
    EXPECT_EQ(parseHistoryRetention("500")->revisions, 500u);
    EXPECT_EQ(parseHistoryRetention("30d")->seconds, 30 * 86400.0);
    EXPECT_EQ(parseHistoryRetention("0.5d")->seconds, 43200.0);
    EXPECT_TRUE(parseHistoryRetention("all")->keepsAll());
    EXPECT_EQ(parseHistoryRetention("500")->flag(), "--history-keep 500");
    EXPECT_EQ(parseHistoryRetention("30d")->text(), "30d");
    EXPECT_EQ(HistoryRetention{}.text(), "all");
    for (const char* bad : {"", "0", "-5", "d", "0d", "5x", "1.5", ".5d", "5.d", "1e3", "30 d", "99999999999999999999"}) {
        auto r = parseHistoryRetention(bad);
        ASSERT_FALSE(r) << bad;
        EXPECT_EQ(r.error().field, "--history-keep");
    }
    std::vector<RevisionInfo> h;
    for (std::uint64_t r = 5; r <= 14; ++r) h.push_back({r, 1000.0 + 10.0 * r, "", ""});
    EXPECT_EQ(oldestKept(h, HistoryRetention{}, 5000), 5u);
    EXPECT_EQ(oldestKept(h, HistoryRetention{3, 0.0}, 5000), 12u);
    EXPECT_EQ(oldestKept(h, HistoryRetention{30, 0.0}, 5000), 5u);
    EXPECT_EQ(oldestKept(h, HistoryRetention{0, 35.0}, 1140.0), 11u); // times 1110 … 1140
    EXPECT_EQ(oldestKept(h, HistoryRetention{0, 1.0}, 99999.0), 14u);  // the current one stays
    EXPECT_EQ(oldestKept(h, HistoryRetention{2, 35.0}, 1140.0), 13u);
    h[7].time = 0.0; // revision 12: the clock stepped back; the window ends there
    EXPECT_EQ(oldestKept(h, HistoryRetention{0, 1000.0}, 1140.0), 13u);
    EXPECT_EQ(oldestKept({}, HistoryRetention{3, 0.0}, 0.0), 0u);
}

// --- the store ---------------------------------------------------------------------------------------

TEST(StoreHistoryTest, EveryRevisionReadsBackByteForByteAcrossChunksAndReopens) {
    TempDir dir;
    const std::string id = "s_00000000000000a1";
    std::vector<std::string> written(1, ""); // by revision
    std::mt19937 rng(5);
    int nextId = 100;
    json doc = sceneOf(30);
    auto store = Store::open(dir / "data");
    ASSERT_TRUE(store);
    auto write = [&](Store& s, std::uint64_t r) {
        if (r > 1) randomEdit(doc, rng, nextId);
        if (r % 97 == 0) doc = sceneOf(static_cast<int>(r % 50)); // a whole new document now and then
        ASSERT_TRUE(s.putScene(id, r, doc));
        written.push_back(doc.dump());
    };
    auto readAll = [&](const Store& s) {
        for (std::uint64_t r = 1; r < written.size(); ++r) {
            auto got = s.readRevision(id, r);
            ASSERT_TRUE(got) << "revision " << r << ": " << got.error().message;
            ASSERT_EQ(got->dump(), written[r]) << "revision " << r;
        }
    };
    for (std::uint64_t r = 1; r <= 300; ++r) write(*store, r);
    readAll(*store);
    const auto chunks = std::count_if(fs::directory_iterator(hist(dir, id)), fs::directory_iterator(),
                                      [](const auto& e) { return e.path().extension() == ".jsonl" &&
                                                                 e.path().filename() != "index.jsonl"; });
    EXPECT_GE(chunks, 3); // 300 revisions of a small scene: several chunks (patches outweigh snapshots)
    EXPECT_EQ(store->readRevision(id, 301).error().code, ErrorCode::NotFound);
    EXPECT_EQ(store->readRevision(id, 0).error().code, ErrorCode::NotFound);

    // Reopened: the same list and documents; the next revision starts a chunk, and all still read.
    auto again = Store::open(dir / "data");
    ASSERT_TRUE(again);
    std::vector<std::string> skipped;
    auto scenes = again->listScenes(skipped);
    ASSERT_EQ(scenes.size(), 1u);
    auto h = again->loadHistory(id, scenes[0].revision, scenes[0].doc);
    ASSERT_TRUE(h) << h.error().message;
    ASSERT_EQ(h->revisions.size(), 300u);
    EXPECT_EQ(h->revisions.back().revision, 300u);
    EXPECT_EQ(h->droppedBefore, 0u);
    readAll(*again);
    for (std::uint64_t r = 301; r <= 340; ++r) write(*again, r);
    EXPECT_TRUE(fs::exists(hist(dir, id) + "/c301.jsonl"));
    readAll(*again);
    readAll(*store); // a reader of the same folder needs no state
}

TEST(StoreHistoryTest, AOnePlacementEditOfAThousandPlacementsTakesUnder2KB) {
    TempDir dir;
    const std::string id = "s_00000000000000b2";
    auto store = Store::open(dir / "data");
    ASSERT_TRUE(store);
    json doc = sceneOf(1000);
    std::mt19937 rng(9);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<json> kept;
    const int edits = static_cast<int>(3 * kChunkRevisions); // three whole chunks: snapshots included
    using Clock = std::chrono::steady_clock;
    double writeMs = 0.0;
    for (int r = 1; r <= edits; ++r) {
        if (r > 1) doc["placements"][rng() % 1000]["center"] = {u(rng), u(rng)};
        const auto t0 = Clock::now();
        ASSERT_TRUE(store->putScene(id, RevisionInfo{static_cast<std::uint64_t>(r), 1.7e9 + r,
                                                     "patch placement p" + std::to_string(r % 1000), "bench"},
                                    doc));
        writeMs += std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
        if (r % 37 == 0 || r == edits) kept.push_back(doc);
    }
    const auto [bytes, blocks] = folderBytes(hist(dir, id));
    const double perEdit = static_cast<double>(bytes) / edits;
    std::cout << "[ figures  ] history of a 1,000-placement scene (" << doc.dump().size() / 1024
              << " KB a document): " << perEdit << " bytes per one-placement edit over " << edits
              << " edits (" << static_cast<double>(blocks) / edits << " in blocks), "
              << writeMs / edits << " ms per durable write\n";
    EXPECT_LE(perEdit, 2048.0);
    // Reading any revision: its chunk's snapshot plus at most kChunkRevisions − 1 patches, as
    // text (what GET ?revision= sends) and parsed (what a revert or a frame needs).
    std::vector<double> textMs, treeMs;
    for (int k = 0; k < 40; ++k) {
        const std::uint64_t r = 1 + (k * 7919) % edits;
        const auto t0 = Clock::now();
        auto text = store->readRevisionText(id, r);
        const auto t1 = Clock::now();
        auto tree = store->readRevision(id, r);
        textMs.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
        treeMs.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t1).count());
        ASSERT_TRUE(text && tree);
        ASSERT_EQ(tree->dump(), *text);
    }
    std::sort(textMs.begin(), textMs.end());
    std::sort(treeMs.begin(), treeMs.end());
    std::cout << "[ figures  ] reading a revision of it: " << textMs[textMs.size() / 2] << " ms p50, "
              << textMs.back() << " ms max as text; " << treeMs[treeMs.size() / 2] << " ms p50 parsed\n";
    EXPECT_EQ(store->readRevision(id, edits)->dump(), kept.back().dump());
    EXPECT_EQ(store->readRevision(id, 37 * 5)->dump(), kept[4].dump());
}

TEST(StoreHistoryTest, FoldersOfWholeRevisionsStillReadAndGoOnAsChunks) {
    TempDir dir;
    const std::string id = "s_00000000000000c3";
    // The layout of earlier versions: r<N>.json {"revision","time","op","client","scene"} per
    // revision, index.jsonl, the current record.
    const std::string h = hist(dir, id);
    fs::create_directories(h);
    std::vector<std::string> written(1, "");
    std::mt19937 rng(3);
    int nextId = 100;
    json doc = sceneOf(12);
    std::string index;
    for (std::uint64_t r = 1; r <= 40; ++r) {
        if (r > 1) randomEdit(doc, rng, nextId);
        const json meta = {{"revision", r}, {"time", 1.7e9 + r}, {"op", "edit " + std::to_string(r)}, {"client", "old"}};
        json record = meta;
        record["scene"] = doc;
        writeText(h + "/r" + std::to_string(r) + ".json", record.dump());
        index += meta.dump() + "\n";
        written.push_back(doc.dump());
    }
    writeText(h + "/index.jsonl", index);
    writeText(dir / ("data/scenes/" + id + ".json"), json({{"id", id}, {"revision", 40}, {"scene", doc}}).dump());

    auto store = Store::open(dir / "data");
    ASSERT_TRUE(store);
    std::vector<std::string> skipped;
    auto scenes = store->listScenes(skipped);
    ASSERT_EQ(scenes.size(), 1u);
    auto loaded = store->loadHistory(id, 40, scenes[0].doc);
    ASSERT_TRUE(loaded) << loaded.error().message;
    ASSERT_EQ(loaded->revisions.size(), 40u);
    EXPECT_EQ(loaded->revisions[9].op, "edit 10");
    EXPECT_EQ(loaded->revisions[9].client, "old");
    for (std::uint64_t r = 1; r <= 40; ++r) ASSERT_EQ(store->readRevision(id, r)->dump(), written[r]) << r;
    for (std::uint64_t r = 41; r <= 80; ++r) {
        randomEdit(doc, rng, nextId);
        ASSERT_TRUE(store->putScene(id, r, doc));
        written.push_back(doc.dump());
    }
    EXPECT_TRUE(fs::exists(h + "/c41.jsonl"));
    EXPECT_FALSE(fs::exists(h + "/r41.json"));
    auto reopened = Store::open(dir / "data");
    ASSERT_TRUE(reopened);
    ASSERT_EQ(reopened->loadHistory(id, 80, doc)->revisions.size(), 80u);
    for (std::uint64_t r = 1; r <= 80; ++r) ASSERT_EQ(reopened->readRevision(id, r)->dump(), written[r]) << r;

    // Retention reaches the old files too: keeping 30 deletes r1 … r40 (every one below 51).
    std::vector<RevisionInfo> history = reopened->loadHistory(id, 80, doc)->revisions;
    EXPECT_EQ(retain(*reopened, id, history, HistoryRetention{30, 0.0}, 0.0), 51u);
    EXPECT_FALSE(fs::exists(h + "/r40.json"));
    EXPECT_FALSE(fs::exists(h + "/r1.json"));
    for (std::uint64_t r = 51; r <= 80; ++r) ASSERT_EQ(reopened->readRevision(id, r)->dump(), written[r]) << r;
}

TEST(StoreHistoryTest, AnInterruptedCommitIsForgotten) {
    TempDir dir;
    const std::string id = "s_00000000000000d4";
    const std::string h = hist(dir, id);
    std::vector<std::string> written(1, "");
    json doc = sceneOf(10);
    {
        auto store = Store::open(dir / "data");
        ASSERT_TRUE(store);
        for (std::uint64_t r = 1; r <= 10; ++r) {
            doc["placements"][r % 10]["h"] = 1.0 + 0.1 * static_cast<double>(r);
            ASSERT_TRUE(store->putScene(id, r, doc));
            written.push_back(doc.dump());
        }
        // Revision 11 reached its chunk and the index, not the current record (the commit point):
        // the record of 10 is put back as a crash before the rename would have left it.
        const auto record = readBytes(dir / ("data/scenes/" + id + ".json"));
        json ghost = doc;
        ghost["placements"][0]["h"] = 99.0;
        ASSERT_TRUE(store->putScene(id, 11, ghost));
        writeBytes(dir / ("data/scenes/" + id + ".json"), record);
    }
    // And more a crash may leave: a torn append, a chunk and a temp file of revision 12.
    {
        std::ofstream torn(h + "/c1.jsonl", std::ios::app);
        torn << R"({"revision":12,"patch":[{"op":"repl)";
    }
    writeText(h + "/c12.jsonl", snapshotLine(12, "{}"));
    writeText(h + "/c13.jsonl.tmp.1.0", "half");
    const auto before = fs::file_size(h + "/c1.jsonl");
    auto store = Store::open(dir / "data");
    ASSERT_TRUE(store);
    auto loaded = store->loadHistory(id, 10, json::parse(written[10]));
    ASSERT_TRUE(loaded);
    ASSERT_EQ(loaded->revisions.size(), 10u);
    EXPECT_EQ(loaded->revisions.back().revision, 10u);
    EXPECT_LT(fs::file_size(h + "/c1.jsonl"), before); // cut after revision 10's line
    EXPECT_FALSE(fs::exists(h + "/c12.jsonl"));
    EXPECT_FALSE(fs::exists(h + "/c13.jsonl.tmp.1.0"));
    EXPECT_EQ(store->readRevision(id, 11).error().code, ErrorCode::NotFound);
    doc["placements"][3]["h"] = 7.0;
    ASSERT_TRUE(store->putScene(id, 11, doc)); // revision 11 for real
    written.push_back(doc.dump());
    for (std::uint64_t r = 1; r <= 11; ++r) ASSERT_EQ(store->readRevision(id, r)->dump(), written[r]) << r;
    // A scene whose history is gone (or predates history) gets its current revision imported.
    fs::remove_all(h);
    auto imported = Store::open(dir / "data")->loadHistory(id, 11, doc);
    ASSERT_TRUE(imported);
    ASSERT_EQ(imported->revisions.size(), 1u);
    EXPECT_EQ(imported->revisions[0].op, "imported");
    EXPECT_EQ(store->readRevision(id, 11)->dump(), written[11]);
}

// --- retention ---------------------------------------------------------------------------------------

/// The revisions a history folder holds on disk: from its oldest file's first revision.
std::uint64_t oldestOnDisk(const std::string& h) {
    std::uint64_t oldest = ~std::uint64_t(0);
    for (const auto& e : fs::directory_iterator(h)) {
        const std::string name = e.path().filename().string();
        if (name == "index.jsonl") continue;
        oldest = std::min<std::uint64_t>(oldest, std::stoull(name.substr(1)));
    }
    return oldest;
}

TEST(StoreHistoryTest, RetentionByCountAndByAgeKeepsExactlyTheNewestRevisions) {
    // 100 revisions, or those of the last 99 minutes with one revision a minute: the same 100.
    for (const HistoryRetention keep : {HistoryRetention{100, 0.0}, HistoryRetention{0, 99 * 60.0}}) {
        SCOPED_TRACE(keep.flag());
        TempDir dir;
        const std::string id = "s_00000000000000e5";
        auto store = Store::open(dir / "data");
        ASSERT_TRUE(store);
        std::vector<std::string> written(1, "");
        std::vector<RevisionInfo> history;
        std::mt19937 rng(11);
        int nextId = 100;
        json doc = sceneOf(20);
        const double t0 = 1.7e9;
        std::uint64_t oldest = 0;
        for (std::uint64_t r = 1; r <= 400; ++r) {
            if (r > 1) randomEdit(doc, rng, nextId);
            const RevisionInfo info{r, t0 + 60.0 * static_cast<double>(r), "edit", ""}; // one a minute
            ASSERT_TRUE(store->putScene(id, info, doc));
            written.push_back(doc.dump());
            history.push_back(info);
            oldest = retain(*store, id, history, keep, info.time);
            ASSERT_EQ(oldest, r > 100 ? r - 99 : 1) << "revision " << r;
            ASSERT_EQ(history.size(), r - oldest + 1);
        }
        const std::string h = hist(dir, id);
        const std::uint64_t onDisk = oldestOnDisk(h);
        std::cout << "[ figures  ] " << keep.flag() << ": revisions 301 … 400 kept, files hold "
                  << 401 - onDisk << " (" << folderBytes(h).first / 1024 << " KB)\n";
        EXPECT_LE(onDisk, 301u);
        EXPECT_GT(onDisk, 301u - kChunkRevisions / 2); // files of older revisions are gone
        for (std::uint64_t r = 301; r <= 400; ++r) ASSERT_EQ(store->readRevision(id, r)->dump(), written[r]) << r;

        // Reopened: the index starts at the last compaction's window; the same trim gives the same.
        auto again = Store::open(dir / "data");
        ASSERT_TRUE(again);
        auto loaded = again->loadHistory(id, 400, doc);
        ASSERT_TRUE(loaded);
        EXPECT_GE(loaded->droppedBefore, onDisk);
        EXPECT_LE(loaded->droppedBefore, 301u);
        ASSERT_EQ(loaded->revisions.front().revision, loaded->droppedBefore);
        std::vector<RevisionInfo> reloaded = loaded->revisions;
        EXPECT_EQ(retain(*again, id, reloaded, keep, t0 + 400 * 60.0), 301u);
        ASSERT_EQ(reloaded.size(), 100u);
        for (std::uint64_t r = 301; r <= 400; ++r) ASSERT_EQ(again->readRevision(id, r)->dump(), written[r]) << r;
    }
}

TEST(StoreHistoryTest, ACompactionInterruptedAtAnyStepLeavesAWholeHistory) {
    TempDir dir;
    const std::string id = "s_00000000000000f6";
    std::vector<std::string> written(1, "");
    std::vector<RevisionInfo> history;
    {
        auto store = Store::open(dir / "before");
        ASSERT_TRUE(store);
        std::mt19937 rng(13);
        int nextId = 100;
        json doc = sceneOf(25);
        for (std::uint64_t r = 1; r <= 400; ++r) {
            if (r > 1) randomEdit(doc, rng, nextId);
            const RevisionInfo info{r, 1.7e9 + r, "edit " + std::to_string(r), "c"};
            ASSERT_TRUE(store->putScene(id, info, doc));
            written.push_back(doc.dump());
            history.push_back(info);
        }
    }
    // The whole compaction (keep 101: revisions 300 … 400), done on a copy.
    fs::copy(dir / "before", dir / "after", fs::copy_options::recursive);
    {
        auto store = Store::open(dir / "after");
        std::vector<std::string> skipped;
        const json current = store->listScenes(skipped)[0].doc;
        std::vector<RevisionInfo> kept = store->loadHistory(id, 400, current)->revisions;
        ASSERT_TRUE(store->compactionDue(id, 300));
        EXPECT_EQ(retain(*store, id, kept, HistoryRetention{101, 0.0}, 0.0), 300u);
    }
    const std::string before = dir / ("before/scenes/" + id + ".history");
    const std::string after = dir / ("after/scenes/" + id + ".history");
    std::vector<std::string> deleted;
    for (const auto& e : fs::directory_iterator(before))
        if (!fs::exists(after + "/" + e.path().filename().string())) deleted.push_back(e.path().filename().string());
    ASSERT_GE(deleted.size(), 2u);

    // Each state a kill -9 can leave, opened as a restarted server would.
    struct Case {
        const char* name;
        std::uint64_t oldest; ///< the first revision the history lists
    };
    for (const Case c : {Case{"the new index written, not yet renamed", 1}, Case{"the index switched", 300},
                         Case{"the index switched, some files deleted", 300}, Case{"done", 300}}) {
        SCOPED_TRACE(c.name);
        const std::string data = dir / "case";
        fs::remove_all(data);
        fs::copy(dir / (c.oldest == 1 ? "before" : "after"), data, fs::copy_options::recursive);
        const std::string h = data + "/scenes/" + id + ".history";
        if (c.oldest == 1) fs::copy_file(after + "/index.jsonl", h + "/index.jsonl.tmp.77.0");
        if (std::string(c.name).find("switched") != std::string::npos) { // the deleted files back
            for (std::size_t k = 0; k < deleted.size(); ++k)
                if (std::string(c.name).find("some") == std::string::npos || k % 2 == 0)
                    fs::copy_file(before + "/" + deleted[k], h + "/" + deleted[k]);
        }
        auto store = Store::open(data);
        ASSERT_TRUE(store);
        std::vector<std::string> skipped;
        const json current = store->listScenes(skipped)[0].doc;
        auto loaded = store->loadHistory(id, 400, current);
        ASSERT_TRUE(loaded) << loaded.error().message;
        ASSERT_EQ(loaded->revisions.front().revision, c.oldest);
        ASSERT_EQ(loaded->revisions.size(), 401 - c.oldest);
        EXPECT_EQ(loaded->droppedBefore, c.oldest == 1 ? 0 : 300);
        EXPECT_EQ(loaded->revisions[5].op, "edit " + std::to_string(c.oldest + 5));
        for (const RevisionInfo& r : loaded->revisions)
            ASSERT_EQ(store->readRevision(id, r.revision)->dump(), written[r.revision]) << r.revision;
        EXPECT_FALSE(fs::exists(h + "/index.jsonl.tmp.77.0"));
        if (c.oldest == 300) // what the compaction did not get to delete, the open did
            for (const std::string& name : deleted) EXPECT_FALSE(fs::exists(h + "/" + name)) << name;
        json next = json::parse(written[400]);
        next["pose"]["time"] = 3.5;
        ASSERT_TRUE(store->putScene(id, 401, next));
        EXPECT_EQ(store->readRevision(id, 401)->dump(), next.dump());
        EXPECT_EQ(store->readRevision(id, 400)->dump(), written[400]);
    }
}

// --- kill -9 -----------------------------------------------------------------------------------------

/// Revision r's document, a function of r alone (the killed writer and the checker agree on it).
json docAt(std::uint64_t r) {
    json doc = sceneOf(20 + static_cast<int>((r / 40) % 4));
    doc["placements"][r % 20]["h"] = 0.01 * static_cast<double>(r);
    doc["placements"][(r * 7) % 20]["center"] = {0.001 * static_cast<double>(r % 997), 0.5};
    doc["pose"]["time"] = 0.5 * static_cast<double>(r % 100);
    return doc;
}

/// Opens the data folder as a restarted server would: the scene's current revision and its
/// history (trimmed to `keep`).
struct Reopened {
    std::uint64_t current = 0;
    std::vector<RevisionInfo> history;
};
Reopened reopen(Store& store, const std::string& id, const HistoryRetention& keep) {
    Reopened out;
    std::vector<std::string> skipped;
    for (const auto& rec : store.listScenes(skipped)) {
        if (rec.id != id) continue;
        out.current = rec.revision;
        auto h = store.loadHistory(id, rec.revision, rec.doc);
        if (!h) {
            ADD_FAILURE() << h.error().message;
            return out;
        }
        out.history = h->revisions;
        retain(store, id, out.history, keep, 0.0);
    }
    return out;
}

TEST(StoreHistoryTest, AWriterKilledAtAnyPointLosesNoAcknowledgedRevision) {
    TempDir dir;
    const std::string id = "s_0000000000000a07";
    const HistoryRetention keep{50, 0.0}; // compactions among the commits
    std::mt19937 rng(std::random_device{}());
    std::uint64_t acknowledged = 0;
    for (int round = 0; round < 8; ++round) {
        int fds[2];
        ASSERT_EQ(::pipe(fds), 0);
        const pid_t pid = ::fork();
        ASSERT_GE(pid, 0);
        if (pid == 0) { // the writer: a restarted server going on with edits, acknowledging each
            ::close(fds[0]);
            auto store = Store::open(dir / "data");
            if (!store) ::_exit(3);
            Reopened state = reopen(*store, id, keep);
            for (std::uint64_t r = state.current + 1;; ++r) {
                const RevisionInfo info{r, 1.7e9 + static_cast<double>(r), "edit", ""};
                if (!store->putScene(id, info, docAt(r))) ::_exit(4);
                state.history.push_back(info);
                const std::uint64_t oldest = oldestKept(state.history, keep, 0.0);
                while (state.history.front().revision < oldest) state.history.erase(state.history.begin());
                if (store->compactionDue(id, oldest) && !store->dropRevisionsBefore(id, oldest, state.history))
                    ::_exit(5);
                if (::write(fds[1], &r, sizeof r) != sizeof r) ::_exit(6);
            }
        }
        ::close(fds[1]);
        // Killed after some acknowledged commits, at a random moment within the next.
        const std::uint64_t target = acknowledged + 20 + rng() % 120;
        std::uint64_t r = 0;
        while (acknowledged < target && ::read(fds[0], &r, sizeof r) == sizeof r) acknowledged = r;
        ::usleep(static_cast<useconds_t>(rng() % 3000));
        ::kill(pid, SIGKILL);
        int status = 0;
        ::waitpid(pid, &status, 0);
        while (::read(fds[0], &r, sizeof r) == sizeof r) acknowledged = r;
        ::close(fds[0]);
        ASSERT_TRUE(WIFSIGNALED(status)) << "the writer stopped by itself: " << WEXITSTATUS(status);

        auto store = Store::open(dir / "data");
        ASSERT_TRUE(store);
        const Reopened state = reopen(*store, id, keep);
        SCOPED_TRACE("round " + std::to_string(round) + ": acknowledged " + std::to_string(acknowledged) +
                     ", current " + std::to_string(state.current));
        ASSERT_GE(state.current, acknowledged); // the one in flight may have committed
        ASSERT_LE(state.current, acknowledged + 1);
        ASSERT_EQ(state.history.size(), std::min<std::uint64_t>(50, state.current));
        for (std::size_t k = 0; k < state.history.size(); ++k) {
            const std::uint64_t rev = state.current - (state.history.size() - 1 - k);
            ASSERT_EQ(state.history[k].revision, rev);
            auto got = store->readRevision(id, rev);
            ASSERT_TRUE(got) << "revision " << rev << ": " << got.error().message;
            ASSERT_EQ(got->dump(), docAt(rev).dump()) << "revision " << rev;
        }
        acknowledged = state.current;
    }
    std::cout << "[ figures  ] 8 writers killed with SIGKILL: " << acknowledged
              << " revisions committed, every acknowledged one kept\n";
}

} // namespace
