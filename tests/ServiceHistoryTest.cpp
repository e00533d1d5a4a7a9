// ServiceHistoryTest — SPEC §6 History, Concurrency and Presence on the service without HTTP or
// GL: every edit kept as a revision with its op and client, any revision read back, revert (undo
// and redo), history across a reopen and after an interrupted commit, If-Match (stale edits change
// nothing), events carrying client/op/placement, presence broadcast and lapse.
#include "ServiceFixture.hpp"

#include "io/atomic_file.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

using namespace dermis;
using namespace dermis::test;
namespace fs = std::filesystem;

namespace {

const json kEmpty = {{"format", "dermis.scene/1"}, {"model", "builtin:default"}};

class ServiceHistoryTest : public ServiceFixture {
protected:
    /// The data of an SSE message as JSON.
    static json dataOf(const std::string& sse) {
        return json::parse(sse.substr(sse.find("data: ") + 6));
    }
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
    auto sub = svc_->subscribe(id);
    ASSERT_TRUE(sub);
    (*sub)->next(1000); // hello
    const json before = (*svc_->getScene(id))["scene"];
    const EditContext stale{1, "bob"};
    std::vector<Error> errors;
    auto collect = [&](auto r) {
        ASSERT_FALSE(r);
        errors.push_back(r.error());
    };
    collect(svc_->replaceScene(id, before, stale));
    collect(svc_->addPlacement(id, placement("b", 0.5), stale));
    collect(svc_->patchPlacement(id, "a", {{"h", 3}}, stale));
    collect(svc_->deletePlacement(id, "a", stale));
    collect(svc_->reorderPlacements(id, json::array({"a"}), stale));
    collect(svc_->putPose(id, {{"time", 1}}, stale));
    collect(svc_->patchPose(id, {{"time", 1}}, stale));
    collect(svc_->revert(id, 1, stale));
    collect(svc_->deleteScene(id, stale));
    ASSERT_EQ(errors.size(), 9u);
    for (const Error& e : errors) {
        EXPECT_EQ(e.code, ErrorCode::StaleRevision) << e.message;
        EXPECT_EQ(e.field, "If-Match");
        ASSERT_TRUE(e.currentRevision);
        EXPECT_EQ(*e.currentRevision, 2u);
        EXPECT_STREQ(errorCodeName(e.code), "stale_revision");
    }
    EXPECT_EQ(revisionOf(id), 2u);
    EXPECT_EQ((*svc_->getScene(id))["scene"], before);
    EXPECT_EQ((*svc_->listRevisions(id, 10, std::nullopt))["revisions"].size(), 2u);
    EXPECT_FALSE((*sub)->next(50)) << "a refused edit must not be announced";
    // The current revision passes.
    auto fresh = svc_->patchPlacement(id, "a", {{"h", 3}}, EditContext{2, "bob"});
    ASSERT_TRUE(fresh) << fresh.error().message;
    const json event = dataOf(*(*sub)->next(1000));
    EXPECT_EQ(event["type"], "placement_updated");
    EXPECT_EQ(event["revision"], 3);
    EXPECT_EQ(event["client"], "bob");
    EXPECT_EQ(event["op"], "patch placement a");
    EXPECT_EQ(event["placement"], "a");
    ASSERT_TRUE(svc_->putPose(id, {{"time", 0}}));
    const json poseEvent = dataOf(*(*sub)->next(1000));
    EXPECT_TRUE(poseEvent["placement"].is_null());
    EXPECT_EQ(poseEvent["client"], "");
    svc_->unsubscribe(id, *sub);
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
    const std::string sse = *(*sub)->next(1000);
    EXPECT_EQ(sse.rfind("event: presence\n", 0), 0u) << sse;
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
