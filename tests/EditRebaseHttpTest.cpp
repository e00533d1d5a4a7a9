// EditRebaseHttpTest — SPEC §6 Concurrency over real HTTP (HttpTestFixture.hpp: a real Service +
// Api on 127.0.0.1): an If-Match naming an older revision is rebased when what the edit touches
// did not change since (200 with the next ETag), and refused with the usual 412 when it did; two
// clients editing at 10 edits/s each, each sending the ETag of its own last answer, are never
// refused on different placements and lose no update either way (TwoClientEdits.hpp). Prints
// the figures.
#include "HttpTestFixture.hpp"
#include "TwoClientEdits.hpp"

using namespace dermis;
using namespace dermis::test;
using namespace dermis::test::http;

namespace {

class EditRebaseHttpTest : public SharedServerTest {
protected:
    static Reply patchWith(const std::string& path, const json& body, std::uint64_t base,
                           const std::string& client) {
        return http().call("PATCH", path, body.dump(), "application/json",
                           {{"If-Match", "\"r" + std::to_string(base) + "\""}, {"X-Dermis-Client", client}});
    }
    /// A scene with placements "elbow" and "knee"; its path.
    static std::string twoPlacements() {
        json doc = smallScene();
        json knee = placementOf("crease", "knee");
        knee["joint"] = "shin.l";
        knee["center"] = {0.6, 0.3};
        doc["placements"].push_back(knee);
        return "/scenes/" + createScene(doc);
    }
};

TEST_F(EditRebaseHttpTest, AnOlderEtagIsRebasedUnlessTheEditConflicts) {
    Http h = http();
    const std::string s = twoPlacements();
    Reply a = patchWith(s + "/placements/elbow", {{"h", 2.0}}, 1, "ana"); // r2
    ASSERT_EQ(a.status, 200) << a;
    Reply b = patchWith(s + "/placements/knee", {{"h", 3.0}}, 1, "ben"); // r3: ben had not seen r2
    ASSERT_EQ(b.status, 200) << b;
    EXPECT_EQ(b.header("ETag"), "\"r3\"");
    const json doc = b.js()["scene"];
    EXPECT_EQ(doc["placements"][0]["h"], 2.0) << "ana's edit is kept";
    EXPECT_EQ(doc["placements"][1]["h"], 3.0);
    // Ben edits the elbow, still on r1: ana changed it since — 412, the usual answer.
    Reply stale = patchWith(s + "/placements/elbow", {{"h", 9.0}}, 1, "ben");
    expectError(stale, 412, "If-Match");
    EXPECT_EQ(stale.js()["error"]["code"], "stale_revision");
    EXPECT_EQ(stale.js()["revision"], 3);
    EXPECT_NE(stale.js()["error"]["message"].get<std::string>().find("placement \"elbow\" changed since revision 1"),
              std::string::npos)
        << stale;
    // The pose and a new placement rebase too; a whole-document edit does not.
    Reply pose = http().call("PATCH", s + "/pose", json{{"time", 0.25}}.dump(), "application/json",
                             {{"If-Match", "\"r1\""}});
    EXPECT_EQ(pose.status, 200) << pose;
    Reply added = http().call("POST", s + "/placements", placementOf("crease", "c").dump(),
                              "application/json", {{"If-Match", "\"r2\""}});
    EXPECT_EQ(added.status, 201) << added;
    Reply put = http().call("PUT", s, doc.dump(), "application/json", {{"If-Match", "\"r3\""}});
    expectError(put, 412, "If-Match");
    EXPECT_EQ(put.js()["revision"], 5);
    EXPECT_EQ(h.get(s).header("ETag"), "\"r5\"");
    ASSERT_EQ(h.del(s).status, 204);
}

TEST_F(EditRebaseHttpTest, TwoClientsAtTenEditsPerSecondEach) {
    const std::string s = twoPlacements();
    const EditCall edit = [&](int c, const std::string& pid, double value, std::uint64_t base) {
        Reply r = patchWith(s + "/placements/" + pid, {{"h", value}}, base, c ? "ben" : "ana");
        if (r.status == 200) return EditAnswer{200, r.js()["revision"].get<std::uint64_t>()};
        if (r.status == 412) return EditAnswer{412, r.js()["revision"].get<std::uint64_t>()};
        ADD_FAILURE() << r;
        return EditAnswer{r.status, base};
    };
    const auto doc = [&] { return http().get(s).js()["scene"]; };
    const std::string different[2] = {"elbow", "knee"}, same[2] = {"elbow", "elbow"};
    const TwoClientRun apart = runTwoClients(edit, doc, different, 1, 3.0, 10.0);
    std::cout << "[ figures  ] HTTP, two clients on different placements, 10 edits/s each for 3 s: "
              << apart << "\n";
    EXPECT_GE(apart.totalEdits(), 40);
    EXPECT_EQ(apart.totalRefusals(), 0);
    EXPECT_EQ(apart.lost, 0);
    EXPECT_EQ(apart.errors, 0);
    const std::uint64_t now = http().get(s).js()["revision"];
    const TwoClientRun together = runTwoClients(edit, doc, same, now, 3.0, 10.0);
    std::cout << "[ figures  ] HTTP, two clients on the same placement, 10 edits/s each for 3 s: "
              << together << "\n";
    EXPECT_GT(together.totalRefusals(), 0);
    EXPECT_EQ(together.lost, 0);
    EXPECT_EQ(together.errors, 0);
    ASSERT_EQ(http().del(s).status, 204);
}

} // namespace
