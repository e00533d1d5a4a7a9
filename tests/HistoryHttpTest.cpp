// HistoryHttpTest — SPEC §6 History and Concurrency over real HTTP (HttpTestFixture.hpp: a real
// Service + Api on 127.0.0.1): ETag on reads and edits, If-Match on every edit route (412
// stale_revision with the current revision, nothing changed; weak, malformed and multiple ETags
// 400), X-Dermis-Client in the history and the events, revisions paged newest first, a revision's
// document, revert as undo and redo, presence broadcast on the event stream; with
// --history-keep, 410 gone for the revisions it dropped (read, revert, frame).
#include "HttpTestFixture.hpp"

using namespace dermis;
using namespace dermis::test;
using namespace dermis::test::http;

namespace {

class HistoryHttpTest : public SharedServerTest {
protected:
    static httplib::Headers ifMatch(const std::string& etag, const std::string& client = "") {
        httplib::Headers h{{"If-Match", etag}};
        if (!client.empty()) h.emplace("X-Dermis-Client", client);
        return h;
    }
    static Reply send(const std::string& method, const std::string& path, const json& body,
                      httplib::Headers headers) {
        return http().call(method, path, body.is_null() ? "" : body.dump(),
                           body.is_null() ? "" : "application/json", std::move(headers));
    }
};

TEST_F(HistoryHttpTest, EtagsAndIfMatchGuardEveryEditRoute) {
    Http h = http();
    const std::string id = createScene(smallScene());
    const std::string s = "/scenes/" + id;
    Reply got = h.get(s);
    ASSERT_EQ(got.status, 200) << got;
    EXPECT_EQ(got.header("ETag"), "\"r1\"");

    // One fresh edit per route with the right ETag: each answers the next ETag.
    std::uint64_t rev = 1;
    auto fresh = [&](const std::string& method, const std::string& path, const json& body, int status) {
        Reply r = send(method, path, body, ifMatch("\"r" + std::to_string(rev) + "\"", "alice"));
        ASSERT_EQ(r.status, status) << method << " " << path << ": " << r;
        ++rev;
        EXPECT_EQ(r.header("ETag"), "\"r" + std::to_string(rev) + "\"") << method << " " << path;
    };
    fresh("POST", s + "/placements", placementOf("crease", "b"), 201);
    fresh("PATCH", s + "/placements/b", json{{"h", 2.0}}, 200);
    fresh("PUT", s + "/placements", json::array({"b", "elbow"}), 200);
    fresh("DELETE", s + "/placements/b", json(), 200);
    fresh("PUT", s + "/pose", json{{"time", 0.25}}, 200);
    fresh("PATCH", s + "/pose", json{{"time", 0.5}}, 200);
    fresh("POST", s + "/revert", json{{"revision", 2}}, 200);
    json doc = h.get(s).js()["scene"];
    fresh("PUT", s, doc, 200);
    ASSERT_EQ(rev, 9u);

    // Someone changes everything an edit can touch (r10: elbow, the pose, a new placement, the
    // order); the same routes based on r9 conflict with it: 412, the current revision, nothing
    // changed. (An edit of something that did not change since is rebased: EditRebaseHttpTest.)
    json changed = doc;
    changed["placements"] = json::array({doc["placements"][1], doc["placements"][0], placementOf("crease", "c")});
    changed["placements"][1]["h"] = 2.5;
    changed["pose"]["time"] = 0.75;
    ASSERT_EQ(h.put(s, changed).status, 200);
    const json before = h.get(s).js();
    const std::vector<std::tuple<std::string, std::string, json>> edits = {
        {"POST", s + "/placements", placementOf("crease", "c")},
        {"PATCH", s + "/placements/elbow", json{{"h", 3.0}}},
        {"PUT", s + "/placements", json::array({"elbow", "b"})},
        {"DELETE", s + "/placements/elbow", json()},
        {"PUT", s + "/pose", json{{"time", 1.0}}},
        {"PATCH", s + "/pose", json{{"time", 1.0}}},
        {"POST", s + "/revert", json{{"revision", 1}}},
        {"PUT", s, doc},
        {"DELETE", s, json()},
    };
    for (const auto& [method, path, body] : edits) {
        Reply r = send(method, path, body, ifMatch("\"r9\"", "bob"));
        expectError(r, 412, "If-Match");
        EXPECT_EQ(r.js()["error"]["code"], "stale_revision") << method << " " << path;
        EXPECT_EQ(r.js()["revision"], 10) << method << " " << path;
    }
    EXPECT_EQ(h.get(s).js(), before);

    // Weak, malformed and multiple ETags are refused before anything else happens: 400.
    for (const std::string bad : {"W/\"r10\"", "r10", "\"10\"", "\"r\"", "\"r10\", \"r9\"",
                                  "\"r99999999999999999999999\"", "\"r9x\""}) {
        Reply r = send("PATCH", s + "/placements/elbow", json{{"h", 3.0}}, ifMatch(bad));
        expectError(r, 400, "If-Match");
    }
    // "r0" is a well-formed ETag of a revision no scene has: stale (412 with the current one).
    Reply r0 = send("PATCH", s + "/placements/elbow", json{{"h", 3.0}}, ifMatch("\"r0\""));
    expectError(r0, 412, "If-Match");
    EXPECT_EQ(r0.js()["revision"], 10);
    EXPECT_EQ(h.get(s).js(), before);
    // `*` matches any current revision; no If-Match applies as before.
    Reply star = send("PATCH", s + "/pose", json{{"time", 0.0}}, ifMatch("*"));
    EXPECT_EQ(star.status, 200) << star;
    Reply plain = h.patch(s + "/pose", {{"time", 0.1}});
    EXPECT_EQ(plain.status, 200) << plain;
    EXPECT_EQ(plain.js()["revision"], 12);
    // A client name longer than 64 characters or with control characters: 400.
    Reply longName = send("PATCH", s + "/pose", json{{"time", 0.0}},
                          {{"X-Dermis-Client", std::string(65, 'x')}});
    expectError(longName, 400, "X-Dermis-Client");
    ASSERT_EQ(h.del(s).status, 204);
}

TEST_F(HistoryHttpTest, RevisionsRevertAndEventsCarryTheClient) {
    Http h = http();
    const std::string id = createScene(smallScene());
    const std::string s = "/scenes/" + id;
    EventStream events(server_->port(), id, {});
    ASSERT_TRUE(events.waitFor("\"hello\""));
    Reply patched = send("PATCH", s + "/placements/elbow", json{{"h", 2.5}}, {{"X-Dermis-Client", "alice"}});
    ASSERT_EQ(patched.status, 200) << patched;
    ASSERT_TRUE(events.waitFor("\"op\":\"patch placement elbow\"")) << events.text();
    EXPECT_NE(events.text().find("\"client\":\"alice\""), std::string::npos) << events.text();
    EXPECT_NE(events.text().find("\"placement\":\"elbow\""), std::string::npos) << events.text();

    Reply list = h.get(s + "/revisions?limit=10");
    ASSERT_EQ(list.status, 200) << list;
    ASSERT_EQ(list.js()["revisions"].size(), 2u);
    EXPECT_EQ(list.js()["revisions"][0]["op"], "patch placement elbow");
    EXPECT_EQ(list.js()["revisions"][0]["client"], "alice");
    EXPECT_EQ(list.js()["revisions"][1]["op"], "create");
    EXPECT_EQ(list.header("ETag"), "\"r2\"");
    Reply page = h.get(s + "/revisions?limit=1&before=2");
    ASSERT_EQ(page.status, 200);
    ASSERT_EQ(page.js()["revisions"].size(), 1u);
    EXPECT_EQ(page.js()["revisions"][0]["revision"], 1);

    Reply old = h.get(s + "?revision=1");
    ASSERT_EQ(old.status, 200) << old;
    EXPECT_EQ(old.js()["revision"], 1);
    EXPECT_EQ(old.js()["current_revision"], 2);
    EXPECT_EQ(old.js()["scene"]["placements"][0]["h"], smallScene()["placements"][0].value("h", 1.0));

    Reply undo = send("POST", s + "/revert", json{{"revision", 1}}, {{"X-Dermis-Client", "bob"}});
    ASSERT_EQ(undo.status, 200) << undo;
    EXPECT_EQ(undo.js()["revision"], 3);
    EXPECT_EQ(undo.js()["scene"], old.js()["scene"]);
    ASSERT_TRUE(events.waitFor("\"op\":\"revert to 1\"")) << events.text();

    // Presence goes to the same stream as its own event.
    Reply here = h.post(s + "/presence", {{"client", "bob"}, {"selection", {"elbow"}}, {"color", "#3080ff"}});
    ASSERT_EQ(here.status, 200) << here;
    ASSERT_EQ(here.js()["presence"].size(), 1u);
    ASSERT_TRUE(events.waitFor("event: presence")) << events.text();
    EXPECT_EQ(h.get(s + "/presence").js()["presence"][0]["selection"], json({"elbow"}));

    // Bad history requests: clear 4xx errors, nothing changed.
    expectError(h.post(s + "/revert", {{"revision", 99}}), 404, "/revision");
    expectError(h.post(s + "/revert", {{"revision", 0}}), 422, "/revision");
    expectError(h.post(s + "/revert", {{"revision", "1"}}), 422, "/revision");
    expectError(h.post(s + "/revert", {{"revision", 1}, {"extra", true}}), 422);
    expectError(h.get(s + "?revision=0"), 422, "revision");
    expectError(h.get(s + "?revision=abc"), 422, "revision");
    expectError(h.get(s + "?revision=7"), 404, "revision");
    expectError(h.get(s + "/revisions?limit=0"), 422, "limit");
    expectError(h.get(s + "/revisions?limit=5000"), 422, "limit");
    expectError(h.get(s + "/revisions?before=-1"), 422, "before");
    expectError(h.get("/scenes/s_0000000000000000/revisions"), 404);
    const std::string other = createScene(smallScene());
    expectError(h.post("/scenes/" + other + "/revert", {{"revision", 3}}), 404, "/revision");
    json many = json::array();
    for (int k = 0; k < 70000; ++k) many.push_back("placement_" + std::to_string(k)); // ~1 MB
    expectError(h.post(s + "/presence", {{"client", "eve"}, {"selection", many}}), 422, "/selection");
    EXPECT_EQ(h.get(s).js()["revision"], 3);
    ASSERT_EQ(h.del(s).status, 204);
    ASSERT_EQ(h.del("/scenes/" + other).status, 204);
}

TEST(HistoryRetentionHttpTest, DroppedRevisionsAnswer410) {
    ServerLimits limits = mainLimits();
    limits.historyKeep = *parseHistoryRetention("3");
    std::string error;
    auto server = LiveServer::start(limits, "", error);
    ASSERT_TRUE(server && error.empty()) << error;
    Http h(server->port());
    EXPECT_EQ(h.get("/info").js()["limits"]["history_keep"], "3");
    Reply created = h.post("/scenes", smallScene());
    ASSERT_EQ(created.status, 201) << created;
    const std::string s = "/scenes/" + created.js()["id"].get<std::string>();
    for (int k = 0; k < 6; ++k) ASSERT_EQ(h.patch(s + "/placements/elbow", {{"h", 1.0 + k}}).status, 200); // → 7
    Reply list = h.get(s + "/revisions");
    ASSERT_EQ(list.status, 200) << list;
    ASSERT_EQ(list.js()["revisions"].size(), 3u);
    EXPECT_EQ(list.js()["revisions"][2]["revision"], 5);
    Reply gone = h.get(s + "?revision=2");
    expectError(gone, 410, "revision");
    EXPECT_EQ(gone.js()["error"]["code"], "gone");
    EXPECT_NE(gone.js()["error"]["message"].get<std::string>().find(
                  "revision 2 was dropped by the history retention (--history-keep 3); the oldest kept revision is 5"),
              std::string::npos)
        << gone;
    expectError(h.post(s + "/revert", {{"revision", 4}}), 410, "/revision");
    expectError(h.get(s + "/frame?width=64&height=64&revision=1"), 410, "revision");
    EXPECT_EQ(h.get(s + "?revision=5").status, 200);
    expectError(h.get(s + "?revision=8"), 404, "revision");
    EXPECT_EQ(h.get(s).js()["revision"], 7);
}

} // namespace
