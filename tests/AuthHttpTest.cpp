// AuthHttpTest — credentials on /api/v1, end to end (HttpTestFixture.hpp: a real dermis::Service +
// dermis::Api on 127.0.0.1, a GL context on $DERMIS_TEST_GL, cpp-httplib clients over loopback).
// It checks:
//   * without a server token every route is open: POST /session is answered but sets no cookie;
//   * bearer-token authentication on every route but the open ones (a second server);
//   * browser sessions: POST /session trades the token for an HttpOnly, SameSite=Strict cookie
//     that authorises the API and the event stream; wrong tokens and forged cookies are 401;
//     DELETE /session ends it; sessions are bounded (oldest evicted) and expire (a third server).
#include "HttpTestFixture.hpp"

using namespace dermis;
using namespace dermis::test;
using namespace dermis::test::http;

namespace {

/// One server (no token).
class AuthHttpNoTokenTest : public SharedServerTest {};

// ================================================================================================
// Sessions without a server token (one server, no token)
// ================================================================================================

TEST_F(AuthHttpNoTokenTest, SessionWithoutAServerTokenSetsNoCookie) {
    // Every route is open: signing in is answered, but there is nothing to carry.
    Http h = http();
    Reply r = h.post("/session", {{"token", "anything"}});
    EXPECT_EQ(r.status, 204) << r;
    EXPECT_FALSE(r.hasHeader("Set-Cookie")) << r.header("Set-Cookie");
    Reply out = h.del("/session");
    EXPECT_EQ(out.status, 204) << out;
    EXPECT_NE(out.header("Set-Cookie").find("Max-Age=0"), std::string::npos);
    Reply info = h.get("/info");
    ASSERT_EQ(info.status, 200);
    EXPECT_EQ(info.js()["limits"]["max_sessions"], 256);
    EXPECT_EQ(info.js()["limits"]["session_max_age_seconds"], 12 * 3600);
}

// ================================================================================================
// Authentication (a second server, with a token)
// ================================================================================================

class AuthHttpTest : public ::testing::Test {
  protected:
    static constexpr const char* kToken = "s3cret-t0ken";
    static void SetUpTestSuite() {
        ApiOptions opt;
        opt.authFreeFailures = 1 << 30; // these tests make hundreds of wrong attempts on purpose
        server_ = LiveServer::start(mainLimits(), kToken, error_, opt);
    }
    static void TearDownTestSuite() { server_.reset(); }
    void SetUp() override {
        ASSERT_TRUE(server_ && error_.empty()) << "the server did not start: " << error_;
    }
    static inline std::unique_ptr<LiveServer> server_;
    static inline std::string error_;
};

TEST_F(AuthHttpTest, EveryRouteButTheOpenOnesNeedsTheBearerToken) {
    Http anon(server_->port());
    Http authed(server_->port(), kToken);
    EXPECT_EQ(anon.get("/health").status, 200);
    EXPECT_EQ(anon.call("GET", "/health", "", "", {{"Authorization", "Bearer wrong"}}).status, 200);

    const std::vector<std::pair<std::string, httplib::Headers>> badAuth = {
        {"none", {}},
        {"wrong token", {{"Authorization", "Bearer wrong"}}},
        {"token prefix",
         {{"Authorization", std::string("Bearer ") + std::string(kToken).substr(0, 5)}}},
        {"token + suffix", {{"Authorization", std::string("Bearer ") + kToken + "x"}}},
        {"empty bearer", {{"Authorization", "Bearer "}}},
        {"basic scheme", {{"Authorization", std::string("Basic ") + kToken}}},
        {"token without scheme", {{"Authorization", kToken}}},
    };
    for (const Route& route : Api::routes()) {
        if (route.open) continue;
        const std::string path = fillRoute(route.path);
        const bool hasBody =
            route.method == "POST" || route.method == "PUT" || route.method == "PATCH";
        for (const auto& [what, headers] : badAuth) {
            SCOPED_TRACE(route.method + " " + path + " with " + what);
            Reply r = anon.call(route.method, path, hasBody ? "{}" : "",
                                hasBody ? "application/json" : "", headers);
            expectError(r, 401, "Authorization");
            EXPECT_EQ(r.js()["error"]["code"], "unauthorized");
            EXPECT_EQ(r.header("WWW-Authenticate"), "Bearer");
        }
        SCOPED_TRACE(route.method + " " + path + " with the token");
        Reply ok =
            authed.call(route.method, path, hasBody ? "[]" : "", hasBody ? "application/json" : "");
        EXPECT_NE(ok.status, 401) << ok;
        EXPECT_NE(ok.status, -1) << ok;
    }
    // Unknown paths under the prefix need the token too (no probing without it).
    expectError(anon.get("/no/such/route"), 401);

    // With the token, the API works.
    for (const char* path : {"/info", "/models", "/patterns", "/scenes", "/openapi.yaml"})
        EXPECT_EQ(authed.get(path).status, 200) << path;
    Reply created = authed.post("/scenes", smallScene());
    ASSERT_EQ(created.status, 201) << created;
    const std::string id = created.js()["id"];
    Reply frame = authed.get("/scenes/" + id + "/frame?width=64&height=64");
    EXPECT_EQ(frame.status, 200) << frame;
    expectError(anon.get("/scenes/" + id + "/frame"), 401);
    expectError(anon.del("/scenes/" + id), 401);
    EXPECT_EQ(authed.get("/scenes/" + id).status, 200); // not deleted by the refused request
    EXPECT_EQ(authed.del("/scenes/" + id).status, 204);
}

TEST_F(AuthHttpTest, SessionCookieAuthorisesTheApiAndTheEventStream) {
    Http anon(server_->port());
    Http authed(server_->port(), kToken);

    // The right token: 204 and a session cookie the page's scripts cannot read or send away.
    Reply in = anon.post("/session", {{"token", kToken}});
    ASSERT_EQ(in.status, 204) << in;
    const std::string cookie = in.header("Set-Cookie");
    const std::string id = sessionIdOf(in);
    EXPECT_TRUE(std::regex_match(id, std::regex("[0-9a-f]{32}"))) << cookie;
    EXPECT_NE(cookie.find("; HttpOnly"), std::string::npos) << cookie;
    EXPECT_NE(cookie.find("; SameSite=Strict"), std::string::npos) << cookie;
    EXPECT_NE(cookie.find("; Path=/api/v1"), std::string::npos) << cookie;
    EXPECT_NE(cookie.find("; Max-Age=43200"), std::string::npos) << cookie;
    EXPECT_EQ(in.header("Cache-Control"), "no-store");
    // Every sign-in is a new session.
    Reply again = anon.post("/session", {{"token", kToken}});
    ASSERT_EQ(again.status, 204) << again;
    const std::string other = sessionIdOf(again);
    EXPECT_NE(other, id);

    // The cookie authorises the API, alone or among other cookies.
    Reply scenes = anon.call("GET", "/scenes", "", "", cookieHeader(id));
    EXPECT_EQ(scenes.status, 200) << scenes;
    EXPECT_EQ(anon.call("GET", "/info", "", "", {{"Cookie", "theme=dark; dermis_session=" + id + "; x=1"}})
                  .status,
              200);
    Reply created = anon.call("POST", "/scenes", smallScene().dump(), "application/json", cookieHeader(id));
    ASSERT_EQ(created.status, 201) << created;
    const std::string scene = created.js()["id"];
    Reply frame = anon.call("GET", "/scenes/" + scene + "/frame?width=64&height=64", "", "", cookieHeader(id));
    EXPECT_EQ(frame.status, 200) << frame;

    // And the event stream: an edit made with the bearer token reaches the cookie's stream.
    {
        EventStream stream(server_->port(), scene, cookieHeader(id));
        ASSERT_EQ(stream.status(), 200);
        ASSERT_TRUE(stream.waitFor("event: hello")) << stream.text();
        ASSERT_EQ(authed.patch("/scenes/" + scene + "/pose", {{"time", 0.25}}).status, 200);
        EXPECT_TRUE(stream.waitFor("event: change")) << stream.text();
        EXPECT_NE(stream.text().find("\"revision\":2"), std::string::npos) << stream.text();
    }
    {
        EventStream refused(server_->port(), scene, {});
        EXPECT_EQ(refused.status(), 401);
    }

    // Sign-out forgets that session (and clears the cookie); the other one still works.
    Reply out = anon.call("DELETE", "/session", "", "", cookieHeader(id));
    EXPECT_EQ(out.status, 204) << out;
    const std::string cleared = out.header("Set-Cookie");
    EXPECT_EQ(sessionIdOf(out), "") << cleared;
    EXPECT_NE(cleared.find("Max-Age=0"), std::string::npos) << cleared;
    EXPECT_NE(cleared.find("Path=/api/v1"), std::string::npos) << cleared;
    Reply after = anon.call("GET", "/scenes", "", "", cookieHeader(id));
    expectError(after, 401, "Authorization");
    {
        EventStream ended(server_->port(), scene, cookieHeader(id));
        EXPECT_EQ(ended.status(), 401);
    }
    EXPECT_EQ(anon.call("GET", "/scenes", "", "", cookieHeader(other)).status, 200);
    EXPECT_EQ(anon.call("DELETE", "/session", "", "", cookieHeader(other)).status, 204);
    expectError(anon.call("GET", "/scenes", "", "", cookieHeader(other)), 401);
    EXPECT_EQ(authed.del("/scenes/" + scene).status, 204);
}

TEST_F(AuthHttpTest, WrongTokensAndForgedCookiesAre401) {
    Http anon(server_->port());
    for (const json& token : {json("wrong"), json(""), json(std::string(kToken) + "x"),
                              json(std::string(kToken).substr(1)), json("Bearer " + std::string(kToken))}) {
        SCOPED_TRACE(token.dump());
        Reply r = anon.post("/session", {{"token", token}});
        expectError(r, 401, "/token");
        EXPECT_EQ(r.js()["error"]["code"], "unauthorized");
        EXPECT_FALSE(r.hasHeader("Set-Cookie")) << r.header("Set-Cookie");
    }
    // A real session, to make sure none of the forgeries below is mistaken for it.
    Reply in = anon.post("/session", {{"token", kToken}});
    ASSERT_EQ(in.status, 204);
    const std::string id = sessionIdOf(in);
    std::string flipped = id;
    flipped[0] = flipped[0] == '0' ? '1' : '0';
    std::string upper = id;
    std::transform(upper.begin(), upper.end(), upper.begin(), ::toupper);
    const std::vector<std::pair<std::string, httplib::Headers>> forged = {
        {"unknown id", cookieHeader("0123456789abcdef0123456789abcdef")},
        {"one digit changed", cookieHeader(flipped)},
        {"prefix", cookieHeader(id.substr(0, 31))},
        {"suffix", cookieHeader(id + "0")},
        {"upper case", upper == id ? cookieHeader("x") : cookieHeader(upper)},
        {"empty", cookieHeader("")},
        {"the token as the cookie", cookieHeader(kToken)},
        {"another cookie's name", {{"Cookie", "session=" + id}}},
        {"name prefix", {{"Cookie", "xdermis_session=" + id}}},
        {"id as a header", {{"X-Dermis-Session", id}}},
        {"id as a bearer token", {{"Authorization", "Bearer " + id}}},
    };
    for (const auto& [what, headers] : forged) {
        SCOPED_TRACE(what);
        for (const std::string path : {"/scenes", "/info", "/scenes/s_0000000000000000/events"}) {
            Reply r = anon.call("GET", path, "", "", headers);
            expectError(r, 401, "Authorization");
            EXPECT_EQ(r.header("WWW-Authenticate"), "Bearer");
        }
    }
    // A wrong bearer token next to a good cookie, and a forged cookie next to a good one: either
    // credential is enough.
    httplib::Headers both = cookieHeader(id);
    both.emplace("Authorization", "Bearer wrong");
    EXPECT_EQ(anon.call("GET", "/scenes", "", "", both).status, 200);
    EXPECT_EQ(anon.call("GET", "/scenes", "", "", {{"Cookie", "dermis_session=forged; dermis_session=" + id}})
                  .status,
              200);
    // Sign-out with a forged cookie ends nothing.
    EXPECT_EQ(anon.call("DELETE", "/session", "", "", cookieHeader(flipped)).status, 204);
    EXPECT_EQ(anon.call("GET", "/scenes", "", "", cookieHeader(id)).status, 200);
    EXPECT_EQ(anon.call("DELETE", "/session", "", "", cookieHeader(id)).status, 204);
    // /health stays open; /session asked with another method is 405, not 401.
    EXPECT_EQ(anon.get("/health").status, 200);
    Reply get = anon.get("/session");
    expectError(get, 405);
    EXPECT_NE(get.header("Allow").find("POST"), std::string::npos);
}

// ================================================================================================
// Session limits (a third server: two sessions at most, each for 3 s)
// ================================================================================================

class AuthHttpSessionLimitTest : public ::testing::Test {
  protected:
    static constexpr const char* kToken = "limit-t0ken";
    static void SetUpTestSuite() {
        ApiOptions opt;
        opt.maxSessions = 2;
        opt.sessionMaxAgeSeconds = 3;
        server_ = LiveServer::start(mainLimits(), kToken, error_, opt);
    }
    static void TearDownTestSuite() { server_.reset(); }
    void SetUp() override {
        ASSERT_TRUE(server_ && error_.empty()) << "the server did not start: " << error_;
    }
    static inline std::unique_ptr<LiveServer> server_;
    static inline std::string error_;
};

TEST_F(AuthHttpSessionLimitTest, TheOldestSessionIsEvictedAndSessionsExpire) {
    Http anon(server_->port());
    std::vector<std::string> ids;
    for (int i = 0; i < 3; ++i) {
        Reply r = anon.post("/session", {{"token", kToken}});
        ASSERT_EQ(r.status, 204) << r;
        EXPECT_NE(r.header("Set-Cookie").find("Max-Age=3"), std::string::npos);
        ids.push_back(sessionIdOf(r));
    }
    expectError(anon.call("GET", "/scenes", "", "", cookieHeader(ids[0])), 401); // evicted
    EXPECT_EQ(anon.call("GET", "/scenes", "", "", cookieHeader(ids[1])).status, 200);
    Reply info = anon.call("GET", "/info", "", "", cookieHeader(ids[2]));
    ASSERT_EQ(info.status, 200);
    EXPECT_EQ(info.js()["limits"]["max_sessions"], 2);
    EXPECT_EQ(info.js()["limits"]["session_max_age_seconds"], 3);
    std::this_thread::sleep_for(std::chrono::milliseconds(3500));
    for (const std::string& id : ids)
        expectError(anon.call("GET", "/scenes", "", "", cookieHeader(id)), 401); // expired
}

// ================================================================================================
// Failed sign-ins are throttled per address (issue #27, item 6; a fourth server, defaults)
// ================================================================================================

class AuthHttpThrottleTest : public ::testing::Test {
  protected:
    static constexpr const char* kToken = "throttle-t0ken-0123456789";
    static void SetUpTestSuite() { server_ = LiveServer::start(mainLimits(), kToken, error_); }
    static void TearDownTestSuite() { server_.reset(); }
    void SetUp() override {
        ASSERT_TRUE(server_ && error_.empty()) << "the server did not start: " << error_;
    }
    static inline std::unique_ptr<LiveServer> server_;
    static inline std::string error_;
};

TEST_F(AuthHttpThrottleTest, AfterTenFailuresAnAddressWaitsAndItsGuessesAreNotChecked) {
    Http anon(server_->port());
    const httplib::Headers wrongBearer = {{"Authorization", "Bearer wrong"}};
    // Ten failures cost nothing; the eleventh is still checked (and starts the wait).
    for (int i = 0; i < 11; ++i) {
        Reply r = i % 2 ? anon.post("/session", {{"token", "guess" + std::to_string(i)}})
                        : anon.call("GET", "/scenes", "", "", wrongBearer);
        expectError(r, 401);
    }
    // Inside the wait every credentialed attempt is 429 with Retry-After — the right token too,
    // so a right guess inside the wait tells nothing.
    Reply guess = anon.post("/session", {{"token", "guess-12"}});
    expectError(guess, 429, "/token");
    EXPECT_EQ(guess.header("Retry-After"), "1");
    expectError(anon.post("/session", {{"token", kToken}}), 429);
    expectError(anon.call("GET", "/scenes", "", "", {{"Authorization", std::string("Bearer ") + kToken}}), 429);
    // A request without credentials is not a guess: 401 as always.
    expectError(anon.get("/scenes"), 401);
    // Guessing as fast as possible for 2 s: how many guesses are checked?
    const auto t0 = std::chrono::steady_clock::now();
    int checked = 0, refused = 0;
    while (std::chrono::steady_clock::now() - t0 < std::chrono::seconds(2)) {
        const int status = anon.post("/session", {{"token", "guess"}}).status;
        checked += status == 401;
        refused += status == 429;
    }
    EXPECT_LE(checked, 3) << "at most one guess per wait (1 s, then 2 s)";
    EXPECT_GT(refused, 20);
    std::cout << "[ figures ] 2 s of guessing after 11 failures: " << checked << " checked, " << refused
              << " answered 429\n";
    // After the wait, the right token signs in and the address starts afresh.
    int wait = 1;
    for (int i = 0; i < 70; ++i) {
        Reply r = anon.post("/session", {{"token", kToken}});
        if (r.status == 204) break;
        ASSERT_EQ(r.status, 429) << r;
        wait = std::atoi(r.header("Retry-After").c_str());
        ASSERT_GE(wait, 1);
        ASSERT_LE(wait, 60);
        std::this_thread::sleep_for(std::chrono::milliseconds(wait * 1000 + 50));
    }
    expectError(anon.post("/session", {{"token", "wrong-again"}}), 401);
}

} // namespace
