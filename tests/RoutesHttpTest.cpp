// RoutesHttpTest — what the /api/v1 routes share, end to end on one server (HttpTestFixture.hpp:
// a real dermis::Service + dermis::Api on 127.0.0.1, a GL context on $DERMIS_TEST_GL, cpp-httplib
// clients over loopback). It checks:
//   * health, info (backend, GL renderer, the configured limits) and the served OpenAPI file;
//   * OpenAPI coverage: the path+method pairs of the served YAML equal Api::routes() (generated
//     from the table the routes are registered from), the open ones (`security: []`) are exactly
//     the routes served without credentials, and every route is routed (none answers httplib's
//     generic "no such route");
//   * a known path asked with another method answers 405 with Allow.
#include "HttpTestFixture.hpp"

using namespace dermis;
using namespace dermis::test;
using namespace dermis::test::http;

namespace {

/// One server (no token).
class RoutesHttpTest : public SharedServerTest {};

// ================================================================================================
// Health, info, OpenAPI
// ================================================================================================

TEST_F(RoutesHttpTest, HealthInfoAndOpenapiAreServed) {
    Http h = http();
    Reply health = h.get("/health");
    ASSERT_EQ(health.status, 200) << health;
    EXPECT_EQ(health.js()["status"], "ok");

    Reply info = h.get("/info");
    ASSERT_EQ(info.status, 200) << info;
    const json j = info.js();
    ASSERT_TRUE(j.is_object()) << info;
    if (testBackend() != GlBackend::Auto)
        EXPECT_EQ(j["backend"], std::string(toString(testBackend())));
    EXPECT_FALSE(j.value("backend", "").empty());
    EXPECT_FALSE(j["gl"].value("renderer", "").empty()) << info;
    EXPECT_FALSE(j["gl"].value("version", "").empty()) << info;
    EXPECT_EQ(j["api"], "/api/v1");
    const json& lim = j["limits"];
    EXPECT_EQ(lim["max_upload_bytes"], kMaxUpload);
    EXPECT_EQ(lim["max_render_side"], 2048);
    EXPECT_EQ(lim["queue_length"], 16);
    EXPECT_EQ(lim["max_placements"], kMaxPlacements);
    for (const char* k : {"max_image_side", "max_map_side", "max_triangles", "max_joints",
                          "request_timeout_seconds", "max_batch_frames"})
        EXPECT_TRUE(lim.contains(k)) << k;

    Reply yaml = h.get("/openapi.yaml");
    ASSERT_EQ(yaml.status, 200) << yaml;
    EXPECT_EQ(yaml.body.rfind("openapi: 3", 0), 0u);
    EXPECT_NE(yaml.header("Content-Type").find("yaml"), std::string::npos);
    EXPECT_EQ(yaml.body, std::string(openapiYaml()));
}

// ================================================================================================
// OpenAPI coverage and routing
// ================================================================================================

TEST_F(RoutesHttpTest, OpenapiListsExactlyTheServedRoutes) {
    Reply yaml = http().get("/openapi.yaml");
    ASSERT_EQ(yaml.status, 200);
    const auto documented = openapiRoutes(yaml.body);
    std::set<std::pair<std::string, std::string>> served;
    for (const Route& r : Api::routes())
        served.insert({r.method, r.path});
    EXPECT_EQ(Api::routes().size(), served.size()) << "a route is listed twice";
    for (const auto& [m, p] : served)
        EXPECT_TRUE(documented.count({m, p}))
            << m << " " << p << " is served but not in openapi.yaml";
    for (const auto& [m, p] : documented)
        EXPECT_TRUE(served.count({m, p})) << m << " " << p << " is in openapi.yaml but not served";
    EXPECT_GE(served.size(), 29u);

    // The routes served without credentials are the ones the document marks `security: []`.
    std::set<std::pair<std::string, std::string>> open;
    for (const Route& r : Api::routes())
        if (r.open) open.insert({r.method, r.path});
    EXPECT_EQ(open, openapiOpenRoutes(yaml.body));
    const std::set<std::pair<std::string, std::string>> expectedOpen = {
        {"GET", "/health"}, {"POST", "/session"}, {"DELETE", "/session"}};
    EXPECT_EQ(open, expectedOpen);
}

TEST_F(RoutesHttpTest, EveryRouteIsRouted) {
    Http h = http();
    for (const Route& route : Api::routes()) {
        const std::string path = fillRoute(route.path);
        Reply r;
        if (route.path == "/models" && route.method == "POST")
            r = h.call("POST", path, "not a glb", "model/gltf-binary");
        else if (route.path == "/patterns" && route.method == "POST")
            r = h.call("POST", path, "not an image", "image/png");
        else if (route.method == "POST" || route.method == "PUT" || route.method == "PATCH")
            r = h.call(route.method, path, "[]", "application/json"); // never a valid document
        else
            r = h.call(route.method, path);
        SCOPED_TRACE(route.method + " " + path);
        ASSERT_NE(r.status, -1) << r;
        EXPECT_EQ(r.body.find("no such route"), std::string::npos) << r;
        EXPECT_NE(r.status, 405) << r;
        EXPECT_LT(r.status, 500) << r;
    }
    // And the generic answer exists for what is not a route, as JSON.
    Reply none = h.get("/no/such/thing");
    expectError(none, 404);
    EXPECT_NE(none.body.find("no such route"), std::string::npos);
}

TEST_F(RoutesHttpTest, AKnownPathWithAnotherMethodIs405) {
    Http h = http();
    Reply r = h.call("PATCH", "/scenes/s_0000000000000000", "{}", "application/json");
    expectError(r, 405);
    EXPECT_NE(r.header("Allow").find("GET"), std::string::npos) << r.header("Allow");
    EXPECT_NE(r.header("Allow").find("PUT"), std::string::npos) << r.header("Allow");
    expectError(h.call("DELETE", "/models"), 405);
    expectError(h.call("POST", "/health", "{}", "application/json"), 405);
}

} // namespace
