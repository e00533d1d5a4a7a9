// ServiceHistoryTest — SPEC §6 History, Concurrency and Presence on the service without HTTP or
// GL: every edit kept as a revision with its op and client, any revision read back, revert (undo
// and redo), history across a reopen and after an interrupted commit, If-Match (stale edits change
// nothing), events carrying client/op/placement, presence broadcast and lapse; the history
// retention (--history-keep by count and by age): dropped revisions answer Gone, across reopens.
#include "ServiceFixture.hpp"
#include "TwoClientEdits.hpp"

#include "io/atomic_file.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <iostream>
#include <fstream>
#include <thread>

using namespace dermis;
using namespace dermis::test;
namespace fs = std::filesystem;

namespace {

const json kEmpty = {{"format", "dermis.scene/1"}, {"model", "builtin:default"}};

class ServiceHistoryTest : public ServiceFixture {
protected:
    /// The data of a live event as JSON.
    static json dataOf(const SceneEvent& e) { return json::parse(e.data); }
    json placement(const std::string& pid, double u) {
        return {{"id", pid}, {"pattern", "crease"}, {"joint", "forearm.l"}, {"center", {u, 0.5}}};
    }
};

TEST_F(ServiceHistoryTest, EveryEditIsKeptWithItsOpAndClient) {
    auto created = svc_->createScene(kEmpty, EditContext{{}, "alice"});
    ASSERT_TRUE(created) << created.error().message;
    const std::string id = (*created)["id"];
    ASSERT_TRUE(svc_->addPlacement(id, placement("a", 0.3), EditContext{{}, "alice"}));
    ASSERT_TRUE(svc_->patchPlacement(id, "a", {{"h", 2.0}}, EditContext{{}, "bob"}));
    ASSERT_TRUE(svc_->patchPose(id, {{"time", 0.5}}));
    ASSERT_TRUE(svc_->deletePlacement(id, "a", EditContext{{}, "bob"}));

    auto list = svc_->listRevisions(id, 50, std::nullopt);
    ASSERT_TRUE(list) << list.error().message;
    EXPECT_EQ((*list)["revision"], 5);
    const json& revs = (*list)["revisions"];
    ASSERT_EQ(revs.size(), 5u);
    const std::vector<std::pair<std::string, std::string>> expected = {
        {"delete placement a", "bob"}, {"patch pose", ""}, {"patch placement a", "bob"},
        {"add placement a", "alice"}, {"create", "alice"}};
    for (std::size_t k = 0; k < revs.size(); ++k) {
        EXPECT_EQ(revs[k]["revision"], 5 - k);
        EXPECT_EQ(revs[k]["op"], expected[k].first);
        EXPECT_EQ(revs[k]["client"], expected[k].second);
        const std::string t = revs[k]["time"];
        EXPECT_EQ(t.size(), 24u) << t; // 2026-11-23T19:05:00.123Z
        EXPECT_EQ(t.back(), 'Z');
    }
    // Paging: newest first, strictly below `before`.
    auto page = svc_->listRevisions(id, 2, 4);
    ASSERT_TRUE(page);
    ASSERT_EQ((*page)["revisions"].size(), 2u);
    EXPECT_EQ((*page)["revisions"][0]["revision"], 3);
    EXPECT_EQ((*page)["revisions"][1]["revision"], 2);
    EXPECT_FALSE(svc_->listRevisions(id, 0, std::nullopt));
    EXPECT_FALSE(svc_->listRevisions(id, 1001, std::nullopt));
    EXPECT_FALSE(svc_->listRevisions("s_nope", 10, std::nullopt));

    // Any revision reads back as it was.
    auto r3 = svc_->getSceneRevision(id, 3);
    ASSERT_TRUE(r3) << r3.error().message;
    EXPECT_EQ((*r3)["revision"], 3);
    EXPECT_EQ((*r3)["current_revision"], 5);
    ASSERT_EQ((*r3)["scene"]["placements"].size(), 1u);
    EXPECT_EQ((*r3)["scene"]["placements"][0]["h"], 2.0);
    EXPECT_EQ((*svc_->getSceneRevision(id, 5))["scene"], (*svc_->getScene(id))["scene"]);
    for (std::uint64_t bad : {0ull, 6ull, 1000ull}) {
        auto missing = svc_->getSceneRevision(id, bad);
        ASSERT_FALSE(missing) << bad;
        EXPECT_EQ(missing.error().code, ErrorCode::NotFound);
        EXPECT_EQ(missing.error().field, "revision");
    }
}

TEST_F(ServiceHistoryTest, RevertIsANewRevisionEqualToTheOldOne) {
    const std::string id = (*svc_->createScene(kEmpty))["id"];
    ASSERT_TRUE(svc_->addPlacement(id, placement("a", 0.3)));            // 2
    ASSERT_TRUE(svc_->patchPlacement(id, "a", {{"center", {0.6, 0.4}}})); // 3
    const json at2 = (*svc_->getSceneRevision(id, 2))["scene"];
    const json at3 = (*svc_->getScene(id))["scene"];
    auto undo = svc_->revert(id, 2, EditContext{{}, "carol"}); // 4 = 2
    ASSERT_TRUE(undo) << undo.error().message;
    EXPECT_EQ((*undo)["revision"], 4);
    EXPECT_EQ((*undo)["scene"], at2);
    auto redo = svc_->revert(id, 3); // 5 = 3
    ASSERT_TRUE(redo);
    EXPECT_EQ((*redo)["scene"], at3);
    auto list = *svc_->listRevisions(id, 2, std::nullopt);
    EXPECT_EQ(list["revisions"][0]["op"], "revert to 3");
    EXPECT_EQ(list["revisions"][1]["op"], "revert to 2");
    EXPECT_EQ(list["revisions"][1]["client"], "carol");

    for (std::uint64_t bad : {0ull, 6ull, 99ull}) {
        auto r = svc_->revert(id, bad);
        ASSERT_FALSE(r) << bad;
        EXPECT_EQ(r.error().code, ErrorCode::NotFound);
        EXPECT_EQ(r.error().field, "/revision");
    }
    // A revision of another scene is not this scene's.
    const std::string other = (*svc_->createScene(kEmpty))["id"];
    EXPECT_FALSE(svc_->revert(other, 3));
    EXPECT_EQ(revisionOf(id), 5u);
    EXPECT_EQ(revisionOf(other), 1u);
}

TEST_F(ServiceHistoryTest, HistorySurvivesReopeningAndInterruptedCommits) {
    const std::string id = (*svc_->createScene(kEmpty))["id"];
    for (int k = 0; k < 5; ++k)
        ASSERT_TRUE(svc_->addPlacement(id, placement("p" + std::to_string(k), 0.1 + 0.1 * k),
                                       EditContext{{}, "dave"}));
    const json at4 = (*svc_->getSceneRevision(id, 4))["scene"];
    // A commit killed after its revision file and index line but before the current record:
    // the scene stays at 6 and the stray revision 7 is forgotten.
    const fs::path hist = fs::path(dir_ / "data") / "scenes" / (id + ".history");
    ASSERT_TRUE(fs::is_directory(hist));
    {
        std::ofstream idx(hist / "index.jsonl", std::ios::app);
        idx << R"({"revision":7,"time":1,"op":"ghost","client":"x"})" << "\n{\"revision\":8,\"ti";
    }
    {
        std::ofstream ghost(hist / "r7.json");
        ghost << R"({"revision":7,"scene":{}})";
    }
    open();
    EXPECT_EQ(revisionOf(id), 6u);
    auto list = svc_->listRevisions(id, 100, std::nullopt);
    ASSERT_TRUE(list);
    ASSERT_EQ((*list)["revisions"].size(), 6u);
    EXPECT_EQ((*list)["revisions"][0]["op"], "add placement p4");
    EXPECT_EQ((*list)["revisions"][0]["client"], "dave");
    EXPECT_EQ((*svc_->getSceneRevision(id, 4))["scene"], at4);
    // The next edit takes revision 7 for real.
    ASSERT_TRUE(svc_->deletePlacement(id, "p0"));
    EXPECT_EQ((*svc_->listRevisions(id, 1, std::nullopt))["revisions"][0]["op"], "delete placement p0");
    EXPECT_NE((*svc_->getSceneRevision(id, 7))["scene"], json::object());

    // A scene stored before history existed: its current revision becomes the first kept one.
    fs::remove_all(hist);
    open();
    auto imported = svc_->listRevisions(id, 100, std::nullopt);
    ASSERT_TRUE(imported);
    ASSERT_EQ((*imported)["revisions"].size(), 1u);
    EXPECT_EQ((*imported)["revisions"][0]["revision"], 7);
    EXPECT_EQ((*imported)["revisions"][0]["op"], "imported");
    ASSERT_TRUE(svc_->deleteScene(id));
    EXPECT_FALSE(fs::exists(hist));
}

TEST_F(ServiceHistoryTest, StaleEditsAreRefusedAndChangeNothing) {
    const std::string id = (*svc_->createScene(kEmpty))["id"];
    ASSERT_TRUE(svc_->addPlacement(id, placement("a", 0.3), EditContext{1, "alice"})); // 1 → 2
    ASSERT_TRUE(svc_->patchPose(id, {{"time", 0.25}}, EditContext{2, "alice"}));       // 2 → 3
    auto sub = svc_->subscribe(id);
    ASSERT_TRUE(sub);
    (*sub)->next(1000); // hello
    const json before = (*svc_->getScene(id))["scene"];
    // Based on revision 1, every edit conflicts with what changed since: placement a came, the
    // pose changed, and whole-document edits are never rebased.
    const EditContext stale{1, "bob"};
    std::vector<Error> errors;
    auto collect = [&](auto r) {
        ASSERT_FALSE(r);
        errors.push_back(r.error());
    };
    collect(svc_->replaceScene(id, before, stale));
    collect(svc_->addPlacement(id, placement("a", 0.5), stale)); // a was added since 1
    collect(svc_->patchPlacement(id, "a", {{"h", 3}}, stale));
    collect(svc_->deletePlacement(id, "a", stale));
    collect(svc_->mirrorPlacement(id, "a", stale));
    collect(svc_->reorderPlacements(id, json::array({"a"}), stale));
    collect(svc_->putPose(id, {{"time", 1}}, stale));
    collect(svc_->patchPose(id, {{"time", 1}}, stale));
    collect(svc_->revert(id, 1, stale));
    collect(svc_->deleteScene(id, stale));
    // A revision the scene has not reached yet is stale for every edit.
    collect(svc_->addPlacement(id, placement("c", 0.5), EditContext{4, "bob"}));
    ASSERT_EQ(errors.size(), 11u);
    for (const Error& e : errors) {
        EXPECT_EQ(e.code, ErrorCode::StaleRevision) << e.message;
        EXPECT_EQ(e.field, "If-Match");
        ASSERT_TRUE(e.currentRevision);
        EXPECT_EQ(*e.currentRevision, 3u);
        EXPECT_STREQ(errorCodeName(e.code), "stale_revision");
    }
    EXPECT_NE(errors[2].message.find("placement \"a\" was added since revision 1"), std::string::npos)
        << errors[2].message;
    EXPECT_NE(errors[6].message.find("the pose changed since revision 1"), std::string::npos)
        << errors[6].message;
    EXPECT_EQ(revisionOf(id), 3u);
    EXPECT_EQ((*svc_->getScene(id))["scene"], before);
    EXPECT_EQ((*svc_->listRevisions(id, 10, std::nullopt))["revisions"].size(), 3u);
    EXPECT_FALSE((*sub)->next(50)) << "a refused edit must not be announced";
    // The current revision passes.
    auto fresh = svc_->patchPlacement(id, "a", {{"h", 3}}, EditContext{3, "bob"});
    ASSERT_TRUE(fresh) << fresh.error().message;
    const json event = dataOf(*(*sub)->next(1000));
    EXPECT_EQ(event["type"], "placement_updated");
    EXPECT_EQ(event["revision"], 4);
    EXPECT_EQ(event["client"], "bob");
    EXPECT_EQ(event["op"], "patch placement a");
    EXPECT_EQ(event["placement"], "a");
    ASSERT_TRUE(svc_->putPose(id, {{"time", 0}}));
    const json poseEvent = dataOf(*(*sub)->next(1000));
    EXPECT_TRUE(poseEvent["placement"].is_null());
    EXPECT_EQ(poseEvent["client"], "");
    svc_->unsubscribe(id, *sub);
}

TEST_F(ServiceHistoryTest, IfMatchOnAnOlderRevisionRebasesEditsOfWhatDidNotChange) {
    const std::string id = (*svc_->createScene(kEmpty))["id"];
    ASSERT_TRUE(svc_->addPlacement(id, placement("a", 0.3)));                          // 2
    ASSERT_TRUE(svc_->addPlacement(id, placement("b", 0.5)));                          // 3
    auto h = [&](const std::string& pid) {
        const json doc = (*svc_->getScene(id))["scene"];
        for (const json& p : doc["placements"])
            if (p["id"] == pid) return p.value("h", 1.0);
        return -1.0;
    };
    auto expectStale = [&](auto r, const std::string& why) {
        ASSERT_FALSE(r) << why;
        EXPECT_EQ(r.error().code, ErrorCode::StaleRevision) << r.error().message;
        EXPECT_NE(r.error().message.find(why), std::string::npos) << r.error().message;
    };
    // Alice and Bob both read revision 3; Alice edits a, Bob then edits b: no conflict.
    auto alice = svc_->patchPlacement(id, "a", {{"h", 2.0}}, EditContext{3, "alice"}); // 4
    ASSERT_TRUE(alice) << alice.error().message;
    auto bob = svc_->patchPlacement(id, "b", {{"h", 3.0}}, EditContext{3, "bob"}); // 5, rebased
    ASSERT_TRUE(bob) << bob.error().message;
    EXPECT_EQ((*bob)["revision"], 5);
    EXPECT_EQ(h("a"), 2.0) << "Alice's edit is kept";
    EXPECT_EQ(h("b"), 3.0);
    // Bob, still on 3, edits a: Alice changed it since — refused, nothing changes.
    expectStale(svc_->patchPlacement(id, "a", {{"h", 9.0}}, EditContext{3, "bob"}),
                "placement \"a\" changed since revision 3");
    expectStale(svc_->deletePlacement(id, "a", EditContext{3, "bob"}), "placement \"a\" changed");
    EXPECT_EQ(h("a"), 2.0);
    // The pose: unchanged since 3, so a pose edit based on 3 applies; a second one on 3 does not.
    ASSERT_TRUE(svc_->patchPose(id, {{"time", 0.5}}, EditContext{3, "alice"})); // 6
    expectStale(svc_->putPose(id, {{"time", 0.7}}, EditContext{5, "bob"}), "the pose changed since revision 5");
    // Adding: an append by someone else is no conflict; the same id added since is.
    ASSERT_TRUE(svc_->addPlacement(id, placement("c", 0.6), EditContext{3, "bob"})); // 7
    auto generated = svc_->addPlacement(id, {{"pattern", "crease"}, {"joint", "forearm.l"}},
                                        EditContext{4, "alice"}); // 8
    ASSERT_TRUE(generated) << generated.error().message;
    expectStale(svc_->addPlacement(id, placement("c", 0.7), EditContext{6, "alice"}),
                "placement \"c\" was added since revision 6");
    // Order: rebased while the list of ids is the same; refused after an add or a delete.
    const json order = json::array({"b", "a", "c", "p3"});
    expectStale(svc_->reorderPlacements(id, order, EditContext{7, "bob"}), "the placements were added");
    ASSERT_TRUE(svc_->patchPlacement(id, "c", {{"h", 4.0}}, EditContext{8, "alice"})); // 9
    ASSERT_TRUE(svc_->reorderPlacements(id, order, EditContext{8, "bob"}));            // 10
    // A deleted placement: an edit of it based on before the delete is refused (not a 404).
    ASSERT_TRUE(svc_->deletePlacement(id, "c", EditContext{10, "alice"})); // 11
    expectStale(svc_->patchPlacement(id, "c", {{"h", 5.0}}, EditContext{10, "bob"}),
                "placement \"c\" was deleted since revision 10");
    // Whole-document edits are never rebased.
    expectStale(svc_->replaceScene(id, (*svc_->getScene(id))["scene"], EditContext{10, "bob"}), "not 10");
    expectStale(svc_->revert(id, 2, EditContext{10, "bob"}), "not 10");
    EXPECT_EQ(revisionOf(id), 11u);

    // Beyond the recent revisions kept in memory, the base document comes from the history.
    for (int k = 0; k < 40; ++k) ASSERT_TRUE(svc_->patchPlacement(id, "b", {{"h", 1.0 + k}})); // → 51
    auto old = svc_->patchPlacement(id, "a", {{"h", 7.0}}, EditContext{11, "alice"});
    ASSERT_TRUE(old) << old.error().message;
    EXPECT_EQ(h("a"), 7.0);
    expectStale(svc_->patchPlacement(id, "b", {{"h", 7.0}}, EditContext{11, "alice"}),
                "placement \"b\" changed since revision 11");
    // Reading a revision: the same document from memory as from the history, and the time of each.
    using Clock = std::chrono::steady_clock;
    const auto t0 = Clock::now();
    for (int k = 0; k < 200; ++k) ASSERT_TRUE(svc_->getSceneRevision(id, 50));
    const auto t1 = Clock::now();
    for (int k = 0; k < 200; ++k) ASSERT_TRUE(svc_->getSceneRevision(id, 12));
    const auto t2 = Clock::now();
    std::cout << "[ figures  ] reading an old revision of a 5-placement scene: "
              << std::chrono::duration<double, std::micro>(t1 - t0).count() / 200
              << " us from the recent ones in memory, "
              << std::chrono::duration<double, std::micro>(t2 - t1).count() / 200
              << " us from the history on disk\n";
    open(); // after a restart the recent window holds the current revision only: the same answers
    const json at50 = (*svc_->getSceneRevision(id, 50))["scene"];
    EXPECT_EQ(at50["placements"][0]["id"], "b");
    EXPECT_EQ(at50["placements"][0]["h"], 39.0);
    auto afterRestart = svc_->patchPlacement(id, "b", {{"h", 8.0}}, EditContext{51, "bob"});
    ASSERT_TRUE(afterRestart) << afterRestart.error().message;
    expectStale(svc_->patchPlacement(id, "a", {{"h", 8.0}}, EditContext{51, "bob"}), "placement \"a\" changed");
}

TEST_F(ServiceHistoryTest, TwoClientsOnDifferentPlacementsLoseNothingAndAreNeverRefused) {
    const std::string id = (*svc_->createScene(kEmpty))["id"];
    ASSERT_TRUE(svc_->addPlacement(id, placement("a", 0.3)));
    ASSERT_TRUE(svc_->addPlacement(id, placement("b", 0.5)));
    const EditCall edit = [&](int c, const std::string& pid, double value, std::uint64_t base) {
        auto r = svc_->patchPlacement(id, pid, {{"h", value}}, EditContext{base, c ? "bob" : "alice"});
        if (r) return EditAnswer{200, (*r)["revision"].get<std::uint64_t>()};
        if (r.error().code == ErrorCode::StaleRevision) return EditAnswer{412, *r.error().currentRevision};
        ADD_FAILURE() << r.error().message;
        return EditAnswer{500, base};
    };
    const auto doc = [&] { return (*svc_->getScene(id))["scene"]; };
    const std::string different[2] = {"a", "b"}, same[2] = {"a", "a"};
    const TwoClientRun apart = runTwoClients(edit, doc, different, 3, 3.0, 10.0);
    std::cout << "[ figures  ] service, two clients on different placements, 10 edits/s each for 3 s: "
              << apart << "\n";
    EXPECT_GE(apart.totalEdits(), 40);
    EXPECT_EQ(apart.totalRefusals(), 0);
    EXPECT_EQ(apart.lost, 0);
    EXPECT_EQ(apart.errors, 0);
    const TwoClientRun together = runTwoClients(edit, doc, same, revisionOf(id), 3.0, 10.0);
    std::cout << "[ figures  ] service, two clients on the same placement, 10 edits/s each for 3 s: "
              << together << "\n";
    EXPECT_GT(together.totalRefusals(), 0);
    EXPECT_EQ(together.lost, 0);
    EXPECT_EQ(together.errors, 0);
}

TEST_F(ServiceHistoryTest, FramesOfRecentRevisionsComeFromTheCachedScene) {
    const std::string id = defaultScene(); // r1
    FrameParams p;
    p.width = p.height = 64;
    auto frame = [&](std::optional<std::uint64_t> revision) {
        FrameParams q = p;
        q.revision = revision;
        auto f = svc_->frame(id, q);
        EXPECT_TRUE(f) << f.error().message;
        return f ? f->bytes : std::vector<std::uint8_t>{};
    };
    const std::uint64_t n0 = svc_->framesPrepared();
    const auto plain = frame(std::nullopt);
    const auto r1 = frame(1); // what the editor sends: the current revision, named
    EXPECT_EQ(r1, plain);
    EXPECT_EQ(svc_->framesPrepared(), n0) << "the current revision is not parsed again";
    ASSERT_TRUE(svc_->patchPlacement(id, "elbow_l", {{"h", 2.5}})); // r2
    EXPECT_NE(frame(std::nullopt), plain);
    EXPECT_EQ(frame(1), r1) << "a recent revision: from its cached scene";
    EXPECT_EQ(svc_->framesPrepared(), n0);
    // A preview changes the document: parsed and checked.
    FrameParams preview = p;
    preview.preview = {{"elbow_l", {{"h", 3.0}}}};
    ASSERT_TRUE(svc_->frame(id, preview));
    EXPECT_EQ(svc_->framesPrepared(), n0 + 1);
    // Beyond the recent revisions the document is read and parsed again: the same bytes.
    for (int k = 0; k < 20; ++k) ASSERT_TRUE(svc_->patchPose(id, {{"time", 0.05 * k}}));
    EXPECT_EQ(frame(1), r1);
    EXPECT_EQ(svc_->framesPrepared(), n0 + 2);
    EXPECT_EQ(frame(revisionOf(id)), frame(std::nullopt));
    EXPECT_EQ(svc_->framesPrepared(), n0 + 2);

    // A recent revision that names a pattern deleted since is not rendered from its cache: it
    // no longer renders (409), as before.
    auto added = svc_->addPattern(patternPng(8, 8), "bumps");
    ASSERT_TRUE(added) << added.error().message;
    const std::string pat = (*added)["id"];
    json pl = {{"id", "up"}, {"pattern", pat}, {"joint", "forearm.l"}, {"center", {0.3, 0.4}}};
    auto withUpload = svc_->addPlacement(id, pl);
    ASSERT_TRUE(withUpload) << withUpload.error().message;
    const std::uint64_t used = (*withUpload)["revision"];
    ASSERT_TRUE(svc_->deletePlacement(id, "up"));
    ASSERT_TRUE(svc_->deletePattern(pat));
    FrameParams old = p;
    old.revision = used;
    auto gone = svc_->frame(id, old);
    ASSERT_FALSE(gone);
    EXPECT_EQ(gone.error().code, ErrorCode::Conflict) << gone.error().message;
}

TEST_F(ServiceHistoryTest, RetentionDropsOldRevisionsThatThenAnswerGone) {
    ServerLimits keep5;
    keep5.historyKeep = *parseHistoryRetention("5");
    open(keep5);
    const std::string id = (*svc_->createScene(kEmpty))["id"];
    for (int k = 0; k < 20; ++k) ASSERT_TRUE(svc_->patchPose(id, {{"time", 0.1 * k}})); // → 21
    const json at19 = (*svc_->getSceneRevision(id, 19))["scene"];
    auto expectKept = [&](std::uint64_t oldest) {
        auto list = svc_->listRevisions(id, 100, std::nullopt);
        ASSERT_TRUE(list);
        ASSERT_EQ((*list)["revisions"].size(), 21 - oldest + 1);
        EXPECT_EQ((*list)["revisions"].back()["revision"], oldest);
    };
    expectKept(17);
    auto gone = [&](const Result<json>& r, const std::string& field) {
        ASSERT_FALSE(r);
        EXPECT_EQ(r.error().code, ErrorCode::Gone);
        EXPECT_EQ(r.error().field, field);
        EXPECT_NE(r.error().message.find("revision 3 was dropped by the history retention (--history-keep 5); "
                                         "the oldest kept revision is 17"),
                  std::string::npos)
            << r.error().message;
    };
    gone(svc_->getSceneRevision(id, 3), "revision");
    gone(svc_->revert(id, 3, EditContext{}), "/revision"); // nothing made: still 21
    EXPECT_EQ(revisionOf(id), 21u);
    FrameParams old;
    old.revision = 16; // still among the recent revisions in memory: dropped all the same
    auto frame = svc_->frame(id, old);
    ASSERT_FALSE(frame);
    EXPECT_EQ(frame.error().code, ErrorCode::Gone);
    EXPECT_EQ(svc_->getSceneRevision(id, 22).error().code, ErrorCode::NotFound);
    EXPECT_EQ((*svc_->getSceneRevision(id, 19))["scene"], at19);
    EXPECT_EQ(svc_->info()["limits"]["history_keep"], "5");

    // Reopened with the same flag: the same window; the files of dropped revisions go in batches.
    for (int k = 0; k < 60; ++k) ASSERT_TRUE(svc_->patchPose(id, {{"time", 0.01 * k}})); // → 81
    open(keep5);
    auto list = svc_->listRevisions(id, 100, std::nullopt);
    ASSERT_EQ((*list)["revisions"].size(), 5u);
    EXPECT_EQ((*list)["revisions"][4]["revision"], 77);
    EXPECT_EQ(svc_->getSceneRevision(id, 76).error().code, ErrorCode::Gone);
    const fs::path hist = fs::path(dir_ / "data") / "scenes" / (id + ".history");
    EXPECT_FALSE(fs::exists(hist / "c1.jsonl")) << "revisions 1 … 20 are still on disk";
    std::string index;
    {
        std::ifstream in(hist / "index.jsonl");
        std::getline(in, index);
    }
    EXPECT_EQ(index.rfind("{\"dropped_before\":", 0), 0u) << index;

    // By age: revisions made before the window (their times put back 40 days) go at the next open.
    open();
    ASSERT_TRUE(svc_->replaceScene(id, kEmpty));
    std::string lines, line;
    {
        std::ifstream in(hist / "index.jsonl");
        while (std::getline(in, line)) {
            json j = json::parse(line);
            if (j.contains("revision") && j["revision"].get<std::uint64_t>() <= 79)
                j["time"] = j["time"].get<double>() - 40 * 86400.0;
            lines += j.dump() + "\n";
        }
    }
    ASSERT_TRUE(writeFileAtomically((hist / "index.jsonl").string(), std::vector<std::uint8_t>(lines.begin(), lines.end())));
    ServerLimits month;
    month.historyKeep = *parseHistoryRetention("30d");
    open(month);
    list = svc_->listRevisions(id, 100, std::nullopt);
    ASSERT_EQ((*list)["revisions"].size(), 3u); // 80, 81, 82
    auto aged = svc_->getSceneRevision(id, 79);
    ASSERT_FALSE(aged);
    EXPECT_EQ(aged.error().code, ErrorCode::Gone);
    EXPECT_NE(aged.error().message.find("(--history-keep 30d); the oldest kept revision is 80"), std::string::npos)
        << aged.error().message;
}

TEST_F(ServiceHistoryTest, PresenceIsBroadcastListedAndChecked) {
    const std::string id = (*svc_->createScene(kEmpty))["id"];
    auto sub = svc_->subscribe(id);
    (*sub)->next(1000); // hello
    auto r = svc_->postPresence(id, {{"client", "alice"}, {"selection", {"a", "b"}}, {"color", "#ff8800"}});
    ASSERT_TRUE(r) << r.error().message;
    ASSERT_EQ((*r)["presence"].size(), 1u);
    EXPECT_EQ((*r)["presence"][0]["selection"], json({"a", "b"}));
    EXPECT_NEAR((*r)["presence"][0]["expires_in"].get<double>(), ServerLimits{}.presenceSeconds, 1.0);
    const SceneEvent sse = *(*sub)->next(1000);
    EXPECT_EQ(sse.name, "presence") << sse.data;
    EXPECT_EQ(dataOf(sse)["client"], "alice");
    EXPECT_EQ(dataOf(sse)["color"], "#ff8800");
    ASSERT_TRUE(svc_->postPresence(id, {{"client", "bob"}}));
    EXPECT_EQ((*svc_->listPresence(id))["presence"].size(), 2u);
    EXPECT_EQ(revisionOf(id), 1u) << "presence is not an edit";

    json huge = json::array();
    for (int k = 0; k < 40000; ++k) huge.push_back("placement_" + std::to_string(k)); // ~0.6 MB
    const std::vector<std::pair<json, std::string>> bad = {
        {json::array(), ""},
        {{{"selection", {"a"}}}, "/client"},
        {{{"client", ""}}, "/client"},
        {{{"client", std::string(65, 'x')}}, "/client"},
        {{{"client", "a\nb"}}, "/client"},
        {{{"client", "c"}, {"selection", "a"}}, "/selection"},
        {{{"client", "c"}, {"selection", huge}}, "/selection"},
        {{{"client", "c"}, {"selection", {1}}}, "/selection/0"},
        {{{"client", "c"}, {"color", std::string(100, 'f')}}, "/color"},
        {{{"client", "c"}, {"cursor", 1}}, "/cursor"},
    };
    for (const auto& [body, field] : bad) {
        auto e = svc_->postPresence(id, body);
        ASSERT_FALSE(e) << body.dump().substr(0, 80);
        EXPECT_EQ(e.error().code, ErrorCode::InvalidArgument);
        EXPECT_EQ(e.error().field, field);
    }
    EXPECT_FALSE(svc_->postPresence("s_nope", {{"client", "c"}}));
    EXPECT_EQ((*svc_->listPresence(id))["presence"].size(), 2u);
    svc_->unsubscribe(id, *sub);
}

TEST_F(ServiceHistoryTest, PresenceIsBoundedPerAddressAndPerScene) {
    const std::string id = (*svc_->createScene(kEmpty))["id"];
    // One address cycling names keeps at most its share; its oldest entries make room.
    for (int k = 0; k < 40; ++k)
        ASSERT_TRUE(svc_->postPresence(id, {{"client", "bot" + std::to_string(k)}}, "10.0.0.1"));
    json live = (*svc_->listPresence(id))["presence"];
    ASSERT_EQ(live.size(), Service::kMaxPresencePerAddress);
    EXPECT_EQ(live.back()["client"], "bot39");
    for (const json& e : live) EXPECT_NE(e["client"], "bot0") << "the oldest names were dropped";
    // Other addresses fill the scene up to its cap; then a new name is refused, a known one not.
    const std::size_t others = Service::kMaxPresencePerScene - Service::kMaxPresencePerAddress;
    for (std::size_t k = 0; k < others; ++k)
        ASSERT_TRUE(svc_->postPresence(id, {{"client", "p" + std::to_string(k)}}, "10.0.1." + std::to_string(k)));
    EXPECT_EQ((*svc_->listPresence(id))["presence"].size(), Service::kMaxPresencePerScene);
    auto full = svc_->postPresence(id, {{"client", "late"}}, "10.0.2.1");
    ASSERT_FALSE(full);
    EXPECT_EQ(full.error().code, ErrorCode::Unavailable);
    EXPECT_TRUE(svc_->postPresence(id, {{"client", "p0"}, {"selection", {"a"}}}, "10.0.1.0")) << "a refresh";
    EXPECT_TRUE(svc_->postPresence(id, {{"client", "bot99"}}, "10.0.0.1")) << "within its own share";
    EXPECT_EQ((*svc_->listPresence(id))["presence"].size(), Service::kMaxPresencePerScene);
}

TEST_F(ServiceHistoryTest, PresenceLapsesAfterItsTime) {
    ServerLimits limits;
    limits.presenceSeconds = 0.3;
    open(limits);
    const std::string id = (*svc_->createScene(kEmpty))["id"];
    auto sub = svc_->subscribe(id);
    (*sub)->next(1000); // hello
    ASSERT_TRUE(svc_->postPresence(id, {{"client", "alice"}, {"selection", {"a"}}}));
    (*sub)->next(1000); // alice's presence
    std::this_thread::sleep_for(std::chrono::milliseconds(150));
    ASSERT_TRUE(svc_->postPresence(id, {{"client", "bob"}}));
    (*sub)->next(1000); // bob's presence
    EXPECT_EQ((*svc_->listPresence(id))["presence"].size(), 2u);
    std::this_thread::sleep_for(std::chrono::milliseconds(200)); // alice lapsed, bob not yet
    const json live = (*svc_->listPresence(id))["presence"];
    ASSERT_EQ(live.size(), 1u);
    EXPECT_EQ(live[0]["client"], "bob");
    const json left = dataOf(*(*sub)->next(1000));
    EXPECT_EQ(left["client"], "alice");
    EXPECT_EQ(left["left"], true);
    EXPECT_TRUE(left["selection"].empty());
    svc_->unsubscribe(id, *sub);
}

} // namespace
