// ApiHttpTest — the /api/v1 HTTP API end to end: a real dermis::Service + dermis::Api served on
// 127.0.0.1 (any free port) from a thread of this process, with a GL context on the backend named
// by $DERMIS_TEST_GL, and real cpp-httplib clients over loopback. It checks:
//   * health, info (backend, GL renderer, the configured limits) and the served OpenAPI file;
//   * OpenAPI coverage: the path+method pairs of the served YAML equal Api::routes() (generated
//     from the table the routes are registered from), the open ones (`security: []`) are exactly
//     the routes served without credentials, and every route is routed (none answers httplib's
//     generic "no such route");
//   * models: built-in details, .glb uploads of the shared models (CesiumMan, KayKit Barbarian,
//     RiggedFigure without UVs), UV layouts as JSON and PNG, deletion;
//   * patterns: the built-in manifest and previews, a custom PNG upload used by id and through a
//     scene's alias map, 409 while in use, 204 once unused;
//   * scenes: create (default pattern set), get, list, replace, placement add/patch/reorder/delete,
//     pose put/patch (merge, null removal), revisions, frames (PNG/JPEG, size, backend header,
//     changing with the pose), height maps (png16/exr/f32, normal), delete;
//   * server-sent events: hello, then one change event per edit with increasing revisions;
//   * the stateless batch: multipart/mixed with one decodable image part per frame;
//   * bearer-token authentication on every route but the open ones (a second server);
//   * browser sessions: POST /session trades the token for an HttpOnly, SameSite=Strict cookie
//     that authorises the API and the event stream; wrong tokens and forged cookies are 401;
//     DELETE /session ends it; sessions are bounded (oldest evicted) and expire (a third server);
//   * a table of bad inputs (malformed JSON, wrong types, non-finite numbers, unknown ids, path
//     tricks, bad sizes and formats, corrupt and oversized uploads, wrong content types, conflicts,
//     limits): each answers {"error": {"code", "message", "field"}} with the right status and
//     the server stays healthy after each;
//   * back-pressure: with a render queue of 1, concurrent frames answer 200 or 503 + Retry-After;
//     event streams beyond half the HTTP threads are refused (503) so that /health still answers;
//   * a known path asked with another method answers 405 with Allow.
#include "TestFiles.hpp"
#include "http/api.hpp"
#include "service/service.hpp"
#include "io/frame_io.hpp"

#include <gtest/gtest.h>
#include <httplib.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <memory>
#include <mutex>
#include <random>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

using namespace dermis;
using namespace dermis::test;
using nlohmann::json;

namespace {

const std::string kShared = DERMIS_SHARED_DIR;
const std::string kApi = "/api/v1";
const std::string kCesiumMan = kShared + "/models/CesiumMan/CesiumMan.glb";
const std::string kBarbarian = kShared + "/models/KayKitBarbarian/Barbarian.glb";
const std::string kRiggedFigure = kShared + "/models/RiggedFigure/RiggedFigure.glb";
constexpr std::size_t kMaxUpload = 8u << 20;
constexpr std::size_t kMaxPlacements = 24; // the default pattern set has 18

GlBackend testBackend() {
    const char* env = std::getenv("DERMIS_TEST_GL");
    if (!env || !*env) return GlBackend::Auto;
    auto b = glBackendFromString(env);
    return b ? *b : GlBackend::Auto;
}

std::string str(const std::vector<std::uint8_t>& b) {
    return {b.begin(), b.end()};
}
std::string fileText(const std::string& path) {
    return str(readBytes(path));
}

// --- a server in this process --------------------------------------------------------------------

/// A Service + Api on 127.0.0.1:<free port>, served from its own thread; stopped and joined on
/// destruction.
class LiveServer {
  public:
    /// Starts a server; nullptr and `error` set when anything fails (the tests then fail).
    /// `base` supplies the options the tests do not set themselves (session limits).
    static std::unique_ptr<LiveServer> start(const ServerLimits& limits, const std::string& token,
                                             std::string& error, ApiOptions base = {}) {
        auto s = std::unique_ptr<LiveServer>(new LiveServer());
        auto svc = Service::open(s->dir_.str(), testBackend(), limits);
        if (!svc) {
            error = "Service::open: " + svc.error().message;
            return nullptr;
        }
        s->service_ = std::move(*svc);
        ApiOptions opt = std::move(base);
        opt.bind = "127.0.0.1";
        opt.port = 0;
        opt.token = token;
        opt.threads = 24;
        s->api_ = std::make_unique<Api>(*s->service_, opt);
        auto port = s->api_->bind();
        if (!port) {
            error = "Api::bind: " + port.error().message;
            return nullptr;
        }
        s->port_ = *port;
        s->thread_ = std::thread([api = s->api_.get()] { api->run(); });
        // Wait until it answers, so that stop() never races the start of listening.
        for (int i = 0; i < 500; ++i) {
            httplib::Client c("127.0.0.1", s->port_);
            if (auto r = c.Get(kApi + "/health"); r && r->status == 200) return s;
            std::this_thread::sleep_for(std::chrono::milliseconds(10));
        }
        error = "the server did not answer /health within 5 s";
        return s; // the destructor stops and joins it
    }

    ~LiveServer() {
        if (api_) api_->stop();
        if (thread_.joinable()) thread_.join();
        api_.reset();
        service_.reset();
    }

    int port() const { return port_; }
    Service& service() { return *service_; }

  private:
    LiveServer() = default;
    TempDir dir_;
    std::unique_ptr<Service> service_;
    std::unique_ptr<Api> api_;
    std::thread thread_;
    int port_ = 0;
};

// --- a client ------------------------------------------------------------------------------------

struct Reply {
    int status = -1; ///< -1: no answer (transport error)
    std::string body;
    httplib::Headers headers;
    std::string transportError;

    json js() const { return json::parse(body, nullptr, false); }
    std::string header(const std::string& name) const {
        auto it = headers.find(name);
        return it == headers.end() ? "" : it->second;
    }
    bool hasHeader(const std::string& name) const { return headers.count(name) > 0; }
    std::vector<std::uint8_t> bytes() const { return {body.begin(), body.end()}; }
};

std::ostream& operator<<(std::ostream& os, const Reply& r) {
    os << "status " << r.status;
    if (!r.transportError.empty()) os << " (" << r.transportError << ")";
    return os << ": " << r.body.substr(0, 400);
}

/// Requests under /api/v1 on one server, each on a fresh connection.
class Http {
  public:
    explicit Http(int port, std::string token = "") : port_(port), token_(std::move(token)) {}

    Reply call(const std::string& method, const std::string& path, const std::string& body = "",
               const std::string& contentType = "", httplib::Headers extra = {}) const {
        httplib::Client cli("127.0.0.1", port_);
        cli.set_read_timeout(120, 0);
        cli.set_write_timeout(60, 0);
        cli.set_connection_timeout(10, 0);
        httplib::Request req;
        req.method = method;
        req.path = kApi + path;
        req.headers = std::move(extra);
        if (!token_.empty() && !req.has_header("Authorization"))
            req.headers.emplace("Authorization", "Bearer " + token_);
        if (!contentType.empty()) req.headers.emplace("Content-Type", contentType);
        req.body = body;
        Reply out;
        auto res = cli.send(req);
        if (!res) {
            out.transportError = httplib::to_string(res.error());
            return out;
        }
        out.status = res->status;
        out.body = res->body;
        out.headers = res->headers;
        return out;
    }

    Reply get(const std::string& path) const { return call("GET", path); }
    Reply del(const std::string& path) const { return call("DELETE", path); }
    Reply post(const std::string& path, const json& body) const {
        return call("POST", path, body.dump(), "application/json");
    }
    Reply put(const std::string& path, const json& body) const {
        return call("PUT", path, body.dump(), "application/json");
    }
    Reply patch(const std::string& path, const json& body) const {
        return call("PATCH", path, body.dump(), "application/json");
    }
    Reply upload(const std::string& path, const std::vector<std::uint8_t>& bytes,
                 const std::string& contentType) const {
        return call("POST", path, str(bytes), contentType);
    }

  private:
    int port_;
    std::string token_;
};

/// The error shape every failure answers; `field` checked when not empty.
void expectError(const Reply& r, int status, const std::string& field = "") {
    EXPECT_EQ(r.status, status) << r;
    EXPECT_NE(r.header("Content-Type").find("application/json"), std::string::npos) << r;
    const json j = r.js();
    ASSERT_TRUE(j.is_object() && j.contains("error")) << r;
    const json& e = j["error"];
    EXPECT_TRUE(e.contains("code") && e["code"].is_string()) << r;
    EXPECT_TRUE(e.contains("message") && e["message"].is_string() &&
                !e["message"].get<std::string>().empty())
        << r;
    EXPECT_TRUE(e.contains("field") && e["field"].is_string()) << r;
    if (!field.empty() && e.contains("field")) EXPECT_EQ(e["field"], field) << r;
}

// --- documents and images ------------------------------------------------------------------------

/// A small scene on the default character: one crease on the left elbow, 256² maps, 128² frames.
json smallScene() {
    return json::parse(R"({
      "format": "dermis.scene/1",
      "model": "builtin:default",
      "heightmap": {"size": [256, 256]},
      "placements": [
        {"id": "elbow", "pattern": "crease", "center": [0.3, 0.4], "scale": [0.08, 0.05],
         "joint": "forearm.l", "axis": "x", "theta_min": 0, "theta_max": 120}
      ],
      "pose": {"animation": "elbow_curl", "time": 0.5},
      "render": {"size": [128, 128], "msaa": 1}
    })");
}

/// A placement of `pattern` on the left forearm.
json placementOf(const std::string& pattern, const std::string& id = "") {
    json p = {{"pattern", pattern},   {"center", {0.5, 0.5}}, {"scale", {0.2, 0.2}},
              {"joint", "forearm.l"}, {"axis", "x"},          {"theta_min", 0},
              {"theta_max", 90}};
    if (!id.empty()) p["id"] = id;
    return p;
}

/// A 64×64 grey dome as PNG bytes (first channel: 128 = height 0, 255 = 1).
std::vector<std::uint8_t> domePng(int w = 64, int h = 64) {
    Image8 img;
    img.width = w;
    img.height = h;
    img.rgba.resize(static_cast<std::size_t>(w) * h * 4);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const double dx = (x + 0.5) / w - 0.5, dy = (y + 0.5) / h - 0.5;
            const double r = std::min(1.0, std::sqrt(dx * dx + dy * dy) * 2.0);
            const auto g = static_cast<std::uint8_t>(128 + std::lround(127 * (1.0 - r * r)));
            std::uint8_t* p = &img.rgba[(static_cast<std::size_t>(y) * w + x) * 4];
            p[0] = p[1] = p[2] = g;
            p[3] = 255;
        }
    auto png = encodePng(img, false);
    EXPECT_TRUE(png) << png.error().message;
    return png ? *png : std::vector<std::uint8_t>{};
}

bool isPng(const std::string& b) {
    return b.size() > 8 && b.compare(0, 4, "\x89PNG") == 0;
}
bool isExr(const std::string& b) {
    return b.size() > 4 && b.compare(0, 4, "\x76\x2f\x31\x01") == 0;
}
/// Bit depth of a PNG (IHDR byte 24).
int pngBitDepth(const std::string& b) {
    return b.size() > 24 ? static_cast<unsigned char>(b[24]) : -1;
}

/// Pixels whose RGB differ by more than 24 in any channel.
std::size_t pixelsDiffering(const Image8& a, const Image8& b) {
    std::size_t n = 0;
    for (std::size_t i = 0; i + 3 < a.rgba.size() && i + 3 < b.rgba.size(); i += 4)
        for (int c = 0; c < 3; ++c)
            if (std::abs(int(a.rgba[i + c]) - int(b.rgba[i + c])) > 24) {
                ++n;
                break;
            }
    return n;
}

/// Parts of a multipart/mixed body: (headers text, content), using each part's Content-Length.
struct Part {
    std::string headers, content;
};
std::vector<Part> multipartParts(const std::string& body, const std::string& boundary) {
    std::vector<Part> parts;
    const std::string delim = "--" + boundary;
    std::size_t pos = body.find(delim);
    while (pos != std::string::npos) {
        pos += delim.size();
        if (body.compare(pos, 2, "--") == 0) break; // closing delimiter
        pos += 2;                                   // CRLF
        const std::size_t headEnd = body.find("\r\n\r\n", pos);
        if (headEnd == std::string::npos) break;
        Part p;
        p.headers = body.substr(pos, headEnd - pos);
        const std::size_t start = headEnd + 4;
        std::smatch m;
        std::size_t end;
        if (std::regex_search(p.headers, m,
                              std::regex("Content-Length: *([0-9]+)", std::regex::icase)))
            end = start + std::stoul(m[1]);
        else
            end = body.find("\r\n" + delim, start);
        if (end == std::string::npos || end > body.size()) break;
        p.content = body.substr(start, end - start);
        parts.push_back(std::move(p));
        pos = body.find(delim, end);
    }
    return parts;
}

/// (METHOD, path) pairs under "paths:" of an OpenAPI YAML, by indentation.
std::set<std::pair<std::string, std::string>> openapiRoutes(const std::string& yaml) {
    std::set<std::pair<std::string, std::string>> out;
    std::istringstream in(yaml);
    std::string line, path;
    bool inPaths = false;
    const std::regex pathLine("^  (/[^ :]*):\\s*$");
    const std::regex methodLine("^    (get|put|post|patch|delete|head|options):\\s*$");
    std::smatch m;
    while (std::getline(in, line)) {
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (!line.empty() && line[0] != ' ' && line[0] != '#') {
            inPaths = line.rfind("paths:", 0) == 0;
            continue;
        }
        if (!inPaths) continue;
        if (std::regex_match(line, m, pathLine)) {
            path = m[1];
        } else if (std::regex_match(line, m, methodLine) && !path.empty()) {
            std::string method = m[1];
            std::transform(method.begin(), method.end(), method.begin(), ::toupper);
            out.insert({method, path});
        }
    }
    return out;
}

/// (METHOD, path) pairs of an OpenAPI YAML whose operation says `security: []` (no credentials).
std::set<std::pair<std::string, std::string>> openapiOpenRoutes(const std::string& yaml) {
    std::set<std::pair<std::string, std::string>> out;
    std::istringstream in(yaml);
    std::string line, path, method;
    bool inPaths = false;
    const std::regex pathLine("^  (/[^ :]*):\\s*$");
    const std::regex methodLine("^    (get|put|post|patch|delete|head|options):\\s*$");
    const std::regex openLine("^      security: \\[\\]\\s*$");
    std::smatch m;
    while (std::getline(in, line)) {
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (!line.empty() && line[0] != ' ' && line[0] != '#') {
            inPaths = line.rfind("paths:", 0) == 0;
            continue;
        }
        if (!inPaths) continue;
        if (std::regex_match(line, m, pathLine)) {
            path = m[1];
            method.clear();
        } else if (std::regex_match(line, m, methodLine)) {
            method = m[1];
            std::transform(method.begin(), method.end(), method.begin(), ::toupper);
        } else if (std::regex_match(line, openLine) && !path.empty() && !method.empty()) {
            out.insert({method, path});
        }
    }
    return out;
}

/// A route template with made-up ids filled in.
std::string fillRoute(std::string path) {
    for (auto [key, value] : {std::pair<std::string, std::string>{"{id}", "x_0000000000000000"},
                              {"{pid}", "nope"},
                              {"{map}", "bump"}})
        for (std::size_t p; (p = path.find(key)) != std::string::npos;)
            path.replace(p, key.size(), value);
    return path;
}

/// A scene's event stream read on its own thread with the given request headers, until the
/// object is destroyed (the next ping, ≤ 1 s, then ends it).
class EventStream {
  public:
    EventStream(int port, const std::string& sceneId, httplib::Headers headers) {
        thread_ = std::thread([this, port, sceneId, headers] {
            httplib::Client cli("127.0.0.1", port);
            cli.set_read_timeout(30, 0);
            auto res = cli.Get(
                kApi + "/scenes/" + sceneId + "/events", headers,
                [this](const httplib::Response& r) {
                    {
                        std::lock_guard<std::mutex> lock(mutex_);
                        status_ = r.status;
                    }
                    cv_.notify_all();
                    return r.status == 200;
                },
                [this](const char* data, std::size_t n) {
                    {
                        std::lock_guard<std::mutex> lock(mutex_);
                        text_.append(data, n);
                    }
                    cv_.notify_all();
                    return !stop_.load();
                });
            (void)res;
            {
                std::lock_guard<std::mutex> lock(mutex_);
                if (status_ == 0) status_ = -1;
            }
            cv_.notify_all();
        });
    }
    ~EventStream() {
        stop_ = true;
        thread_.join();
    }
    /// The response status once known (waits up to 10 s; 0 when none came, -1 on no answer).
    int status() {
        std::unique_lock<std::mutex> lock(mutex_);
        cv_.wait_for(lock, std::chrono::seconds(10), [&] { return status_ != 0; });
        return status_;
    }
    /// Waits up to 10 s for `what` to appear in the stream.
    bool waitFor(const std::string& what) {
        std::unique_lock<std::mutex> lock(mutex_);
        return cv_.wait_for(lock, std::chrono::seconds(10),
                            [&] { return text_.find(what) != std::string::npos; });
    }
    std::string text() {
        std::lock_guard<std::mutex> lock(mutex_);
        return text_;
    }

  private:
    std::mutex mutex_;
    std::condition_variable cv_;
    std::string text_;
    int status_ = 0;
    std::atomic<bool> stop_{false};
    std::thread thread_;
};

/// The session id a Set-Cookie header sets ("" when it sets none).
std::string sessionIdOf(const Reply& r) {
    std::smatch m;
    const std::string c = r.header("Set-Cookie");
    return std::regex_search(c, m, std::regex("^dermis_session=([^;]*)")) ? std::string(m[1]) : "";
}

httplib::Headers cookieHeader(const std::string& id) {
    return {{"Cookie", "dermis_session=" + id}};
}

ServerLimits mainLimits() {
    ServerLimits l;
    l.maxUploadBytes = kMaxUpload;
    l.maxRenderSide = 2048;
    l.queueLength = 16;
    l.maxPlacements = kMaxPlacements;
    return l;
}

// --- fixtures ------------------------------------------------------------------------------------

/// One server for the suite (no token).
class ApiHttpTest : public ::testing::Test {
  protected:
    static void SetUpTestSuite() { server_ = LiveServer::start(mainLimits(), "", error_); }
    static void TearDownTestSuite() { server_.reset(); }
    void SetUp() override {
        ASSERT_TRUE(server_ && error_.empty()) << "the server did not start: " << error_;
    }
    static Http http() { return Http(server_->port()); }

    /// Creates a scene; its id.
    static std::string createScene(const json& doc) {
        Reply r = http().post("/scenes", doc);
        EXPECT_EQ(r.status, 201) << r;
        return r.js().value("id", "");
    }
    /// Uploads a model; its id.
    static std::string uploadModel(const std::string& path) {
        Reply r = http().upload("/models?name=test", readBytes(path), "model/gltf-binary");
        EXPECT_EQ(r.status, 201) << path << ": " << r;
        return r.js().value("id", "");
    }

    static inline std::unique_ptr<LiveServer> server_;
    static inline std::string error_;
};

// ================================================================================================
// Health, info, OpenAPI
// ================================================================================================

TEST_F(ApiHttpTest, HealthInfoAndOpenapiAreServed) {
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

TEST_F(ApiHttpTest, OpenapiListsExactlyTheServedRoutes) {
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

TEST_F(ApiHttpTest, EveryRouteIsRouted) {
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

TEST_F(ApiHttpTest, AKnownPathWithAnotherMethodIs405) {
    Http h = http();
    Reply r = h.call("PATCH", "/scenes/s_0000000000000000", "{}", "application/json");
    expectError(r, 405);
    EXPECT_NE(r.header("Allow").find("GET"), std::string::npos) << r.header("Allow");
    EXPECT_NE(r.header("Allow").find("PUT"), std::string::npos) << r.header("Allow");
    expectError(h.call("DELETE", "/models"), 405);
    expectError(h.call("POST", "/health", "{}", "application/json"), 405);
}

TEST_F(ApiHttpTest, SessionWithoutAServerTokenSetsNoCookie) {
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
// Models
// ================================================================================================

TEST_F(ApiHttpTest, BuiltinModelIsListedWithItsDetails) {
    Http h = http();
    Reply list = h.get("/models");
    ASSERT_EQ(list.status, 200) << list;
    bool found = false;
    for (const json all = list.js(); const json& m : all["models"])
        found = found || m["id"] == "builtin:default";
    EXPECT_TRUE(found) << list;

    Reply r = h.get("/models/builtin:default");
    ASSERT_EQ(r.status, 200) << r;
    const json m = r.js();
    EXPECT_EQ(m["id"], "builtin:default");
    EXPECT_TRUE(m["has_uvs"].get<bool>());
    EXPECT_NEAR(m["triangles"].get<double>(), 4300, 100);
    ASSERT_TRUE(m["joints"].is_array());
    EXPECT_EQ(m["joints"].size(), 51u);
    std::set<std::string> names;
    int roots = 0;
    for (const json& j : m["joints"]) {
        ASSERT_TRUE(j["name"].is_string()) << j;
        names.insert(j["name"].get<std::string>());
        ASSERT_TRUE(j["rest_rotation"].is_array() && j["rest_rotation"].size() == 4) << j;
        double n2 = 0;
        for (const json& c : j["rest_rotation"])
            n2 += c.get<double>() * c.get<double>();
        EXPECT_NEAR(n2, 1.0, 1e-3) << j;
        if (j["parent"].is_null())
            ++roots;
        else
            EXPECT_TRUE(j["parent"].is_string()) << j;
    }
    EXPECT_EQ(roots, 1);
    for (const json& j : m["joints"])
        if (j["parent"].is_string()) EXPECT_TRUE(names.count(j["parent"].get<std::string>())) << j;
    EXPECT_TRUE(names.count("forearm.l") && names.count("spine_02") && names.count("root"));
    ASSERT_TRUE(m["clips"].is_array());
    EXPECT_EQ(m["clips"].size(), 7u);
    for (const json& c : m["clips"]) {
        EXPECT_TRUE(c["name"].is_string());
        EXPECT_GT(c["duration"].get<double>(), 0.0) << c;
    }
}

TEST_F(ApiHttpTest, CesiumManUploadsInspectsAndDeletes) {
    Http h = http();
    // A name with path tricks is only a label.
    Reply up =
        h.upload("/models?name=..%2F..%2Fetc%2Fpasswd", readBytes(kCesiumMan), "model/gltf-binary");
    ASSERT_EQ(up.status, 201) << up;
    const json created = up.js();
    const std::string id = created["id"];
    EXPECT_EQ(id.rfind("m_", 0), 0u) << id;
    EXPECT_EQ(created["joints"], 19);
    EXPECT_EQ(created["name"].get<std::string>().find('/'), std::string::npos) << created;

    Reply got = h.get("/models/" + id);
    ASSERT_EQ(got.status, 200) << got;
    const json m = got.js();
    EXPECT_EQ(m["joints"].size(), 19u);
    EXPECT_TRUE(m["has_uvs"].get<bool>());
    EXPECT_EQ(m["triangles"], 4672);
    EXPECT_GE(m["clips"].size(), 1u);

    bool listed = false;
    for (const json all = h.get("/models").js(); const json& e : all["models"])
        listed = listed || e["id"] == id;
    EXPECT_TRUE(listed);

    Reply uv = h.get("/models/" + id + "/uv-layout");
    ASSERT_EQ(uv.status, 200) << uv;
    const json layout = uv.js();
    ASSERT_TRUE(layout["edges"].is_array());
    EXPECT_GT(layout["edge_count"].get<std::size_t>(), 1000u);
    EXPECT_EQ(layout["edges"].size(), 4 * layout["edge_count"].get<std::size_t>());
    for (const json& v : layout["edges"])
        ASSERT_TRUE(v.is_number() && std::isfinite(v.get<double>()));

    Reply png = h.get("/models/" + id + "/uv-layout?format=png&size=256");
    ASSERT_EQ(png.status, 200) << png;
    EXPECT_EQ(png.header("Content-Type"), "image/png");
    auto img = decodeFrame(png.bytes());
    ASSERT_TRUE(img) << img.error().message;
    EXPECT_EQ(img->width, 256);
    EXPECT_EQ(img->height, 256);
    std::size_t lit = 0;
    for (std::size_t i = 0; i < img->rgba.size(); i += 4)
        lit += img->rgba[i] == 255;
    EXPECT_GT(lit, 1000u);

    EXPECT_EQ(h.del("/models/" + id).status, 204);
    expectError(h.get("/models/" + id), 404, "id");
    expectError(h.del("/models/" + id), 404, "id");
}

TEST_F(ApiHttpTest, GltfWithExternalFilesUploadsAsMultipart) {
    auto post = [&](const httplib::MultipartFormDataItems& items) {
        httplib::Client cli("127.0.0.1", server_->port());
        auto r = cli.Post((std::string(kApi) + "/models?name=tri").c_str(), items);
        Reply out;
        if (r) {
            out.status = r->status;
            out.body = r->body;
        }
        return out;
    };
    const auto [gltf, bin] = triangleGltf("tri.bin");
    Reply ok = post({{"gltf", gltf, "tri.gltf", "model/gltf+json"},
                     {"buffer", bin, "tri.bin", "application/octet-stream"}});
    ASSERT_EQ(ok.status, 201) << ok;
    const std::string id = ok.js()["id"];
    EXPECT_EQ(ok.js()["triangles"], 1);
    Reply got = http().get("/models/" + id);
    ASSERT_EQ(got.status, 200) << got;
    EXPECT_EQ(got.js()["vertices"], 3);
    // A scene on it renders.
    const std::string sid = createScene({{"format", "dermis.scene/1"}, {"model", id},
                                         {"render", {{"size", {64, 64}}}}});
    Reply frame = http().get("/scenes/" + sid + "/frame");
    EXPECT_EQ(frame.status, 200) << frame;
    EXPECT_EQ(http().del("/scenes/" + sid).status, 204);
    EXPECT_EQ(http().del("/models/" + id).status, 204);

    // The buffer is missing; the .gltf points outside its folder; a part name with a folder;
    // no .gltf part at all: 4xx JSON errors, nothing stored.
    const auto [escaping, bin2] = triangleGltf("../tri.bin");
    const std::vector<std::pair<std::string, httplib::MultipartFormDataItems>> bad = {
        {"missing buffer", {{"gltf", gltf, "tri.gltf", ""}}},
        {"escaping uri", {{"gltf", escaping, "tri.gltf", ""}, {"buffer", bin2, "tri.bin", ""}}},
        {"folder in a part name", {{"gltf", gltf, "tri.gltf", ""}, {"buffer", bin, "../tri.bin", ""}}},
        {"no gltf part", {{"buffer", bin, "tri.bin", ""}}},
        {"not json", {{"gltf", "not json", "tri.gltf", ""}, {"buffer", bin, "tri.bin", ""}}},
    };
    const std::size_t models = http().get("/models").js()["models"].size();
    for (const auto& [name, items] : bad) {
        Reply r = post(items);
        EXPECT_GE(r.status, 400) << name << ": " << r;
        EXPECT_LT(r.status, 500) << name << ": " << r;
        EXPECT_TRUE(r.js().contains("error")) << name << ": " << r;
    }
    EXPECT_EQ(http().get("/models").js()["models"].size(), models);
}

TEST_F(ApiHttpTest, BarbarianAndRiggedFigureUpload) {
    Http h = http();
    Reply barb = h.upload("/models", readBytes(kBarbarian), "model/gltf-binary");
    ASSERT_EQ(barb.status, 201) << barb;
    const std::string barbId = barb.js()["id"];
    Reply bm = h.get("/models/" + barbId);
    ASSERT_EQ(bm.status, 200);
    EXPECT_EQ(bm.js()["joints"].size(), 41u);
    EXPECT_GE(bm.js()["clips"].size(), 70u);

    // A scene on an uploaded model renders.
    json doc = {{"format", "dermis.scene/1"},
                {"model", barbId},
                {"heightmap", {{"size", {256, 256}}}},
                {"render", {{"size", {96, 96}}, {"msaa", 1}}}};
    const std::string sid = createScene(doc);
    Reply frame = h.get("/scenes/" + sid + "/frame");
    ASSERT_EQ(frame.status, 200) << frame;
    auto img = decodeFrame(frame.bytes());
    ASSERT_TRUE(img);
    EXPECT_EQ(img->width, 96);
    expectError(h.del("/models/" + barbId), 409, "id"); // in use
    EXPECT_EQ(h.del("/scenes/" + sid).status, 204);
    EXPECT_EQ(h.del("/models/" + barbId).status, 204);

    Reply fig = h.upload("/models", readBytes(kRiggedFigure), "model/gltf-binary");
    ASSERT_EQ(fig.status, 201) << fig;
    const std::string figId = fig.js()["id"];
    EXPECT_FALSE(fig.js()["has_uvs"].get<bool>());
    expectError(h.get("/models/" + figId + "/uv-layout"), 422, "id");
    expectError(h.get("/models/" + figId + "/uv-layout?format=png"), 422, "id");
    json withPlacement = {{"format", "dermis.scene/1"},
                          {"model", figId},
                          {"placements", {placementOf("crease", "a")}}};
    expectError(h.post("/scenes", withPlacement), 422, "/placements/0");
    // Without placements it is a valid scene.
    const std::string figScene = createScene(
        {{"format", "dermis.scene/1"}, {"model", figId}, {"heightmap", {{"size", {256, 256}}}}});
    EXPECT_EQ(h.del("/scenes/" + figScene).status, 204);
    EXPECT_EQ(h.del("/models/" + figId).status, 204);
}

// ================================================================================================
// Patterns
// ================================================================================================

TEST_F(ApiHttpTest, BuiltinPatternsAndPreviews) {
    Http h = http();
    Reply list = h.get("/patterns");
    ASSERT_EQ(list.status, 200) << list;
    std::set<std::string> builtins;
    for (const json all = list.js(); const json& p : all["patterns"])
        if (p["builtin"].get<bool>()) builtins.insert(p["id"].get<std::string>());
    EXPECT_EQ(builtins.size(), 9u);
    for (const char* id : {"crease", "stomach_wrinkles", "waist_twist", "neck_rings", "round_bulge",
                           "elongated_bulge", "clavicle", "ribs", "scapula"})
        EXPECT_TRUE(builtins.count(id)) << id;

    Reply img = h.get("/patterns/crease/image");
    ASSERT_EQ(img.status, 200) << img;
    EXPECT_EQ(img.header("Content-Type"), "image/png");
    auto dec = decodeFrame(img.bytes());
    ASSERT_TRUE(dec) << dec.error().message;
    EXPECT_EQ(dec->width, 256);
    auto small = decodeFrame(h.get("/patterns/crease/image?size=64").bytes());
    ASSERT_TRUE(small);
    EXPECT_EQ(small->width, 64);
    EXPECT_EQ(small->height, 64);
}

TEST_F(ApiHttpTest, CustomPatternUploadUseAndDelete) {
    Http h = http();
    Reply up = h.upload("/patterns?name=dome", domePng(), "image/png");
    ASSERT_EQ(up.status, 201) << up;
    const std::string pid = up.js()["id"];
    EXPECT_EQ(pid.rfind("p_", 0), 0u) << pid;
    EXPECT_EQ(up.js()["name"], "dome");
    EXPECT_EQ(up.js()["width"], 64);
    Reply preview = h.get("/patterns/" + pid + "/image?size=32");
    ASSERT_EQ(preview.status, 200) << preview;
    auto dec = decodeFrame(preview.bytes());
    ASSERT_TRUE(dec);
    EXPECT_GT(dec->rgba[(16 * 32 + 16) * 4], 200); // the dome's top is bright
    bool listed = false;
    for (const json all = h.get("/patterns").js(); const json& p : all["patterns"])
        listed = listed || (p["id"] == pid && !p["builtin"].get<bool>());
    EXPECT_TRUE(listed);

    // Directly by id, driven (the forearm bent 60° about x).
    json doc = smallScene();
    doc["placements"] = {placementOf(pid, "dome")};
    doc["pose"] = {{"joints", {{"forearm.l", {{"axis_angles", {{"x", 60}}}}}}}};
    const std::string sid = createScene(doc);
    ASSERT_FALSE(sid.empty());
    Reply bump = h.get("/scenes/" + sid + "/heightmaps/bump?format=f32");
    ASSERT_EQ(bump.status, 200) << bump;
    ASSERT_EQ(bump.body.size(), 4u * 256 * 256);
    std::vector<float> values(256 * 256);
    std::memcpy(values.data(), bump.body.data(), bump.body.size());
    EXPECT_GT(*std::max_element(values.begin(), values.end()), 0.1f);
    expectError(h.del("/patterns/" + pid), 409, "id");

    // Through the scene's alias map.
    doc["patterns"] = {{"my_dome", pid}};
    doc["placements"] = {placementOf("my_dome", "dome")};
    Reply put = h.put("/scenes/" + sid, doc);
    ASSERT_EQ(put.status, 200) << put;
    EXPECT_EQ(put.js()["scene"]["patterns"]["my_dome"], pid);
    expectError(h.del("/patterns/" + pid), 409, "id");

    // Once no scene names it, it can go.
    json unused = smallScene();
    ASSERT_EQ(h.put("/scenes/" + sid, unused).status, 200);
    EXPECT_EQ(h.del("/patterns/" + pid).status, 204);
    expectError(h.get("/patterns/" + pid + "/image"), 404, "id");
    expectError(h.del("/patterns/" + pid), 404, "id");
    EXPECT_EQ(h.del("/scenes/" + sid).status, 204);
}

// ================================================================================================
// Scenes: documents, edits, renders
// ================================================================================================

TEST_F(ApiHttpTest, SceneLifecycleWithEditsAndRenders) {
    Http h = http();
    Reply created = h.post("/scenes", {{"default_patterns", true}});
    ASSERT_EQ(created.status, 201) << created;
    const std::string id = created.js()["id"];
    EXPECT_EQ(id.rfind("s_", 0), 0u) << id;
    EXPECT_EQ(created.header("Location"), kApi + "/scenes/" + id);
    EXPECT_EQ(created.js()["revision"], 1);
    EXPECT_EQ(created.js()["scene"]["placements"].size(), 18u);
    EXPECT_EQ(created.js()["scene"]["model"], "builtin:default");

    Reply got = h.get("/scenes/" + id);
    ASSERT_EQ(got.status, 200) << got;
    EXPECT_EQ(got.js()["scene"], created.js()["scene"]);
    bool listed = false;
    for (const json all = h.get("/scenes").js(); const json& s : all["scenes"])
        listed = listed || (s["id"] == id && s["placements"] == 18);
    EXPECT_TRUE(listed);

    std::uint64_t rev = 1;
    auto expectRevision = [&](const Reply& r, int status) {
        ASSERT_EQ(r.status, status) << r;
        EXPECT_EQ(r.js()["revision"], ++rev) << r;
        EXPECT_EQ(h.get("/scenes/" + id).js()["revision"], rev);
    };

    // Replace.
    Reply put = h.put("/scenes/" + id, smallScene());
    expectRevision(put, 200);
    ASSERT_EQ(put.js()["scene"]["placements"].size(), 1u);

    // Add a placement without an id: one is generated.
    json added = placementOf("crease");
    added["joint"] = "forearm.r";
    Reply add = h.post("/scenes/" + id + "/placements", added);
    expectRevision(add, 201);
    const json pl = add.js()["scene"]["placements"];
    ASSERT_EQ(pl.size(), 2u);
    const std::string newId = pl[1]["id"];
    EXPECT_FALSE(newId.empty());
    EXPECT_NE(newId, "elbow");

    // Partial update: only the centre moves.
    Reply patched = h.patch("/scenes/" + id + "/placements/" + newId, {{"center", {0.6, 0.55}}});
    expectRevision(patched, 200);
    const json p1 = patched.js()["scene"]["placements"][1];
    EXPECT_EQ(p1["id"], newId);
    EXPECT_NEAR(p1["center"][0].get<double>(), 0.6, 1e-12);
    EXPECT_NEAR(p1["center"][1].get<double>(), 0.55, 1e-12);
    EXPECT_EQ(p1["joint"], "forearm.r");
    EXPECT_EQ(p1["pattern"], "crease");
    EXPECT_NEAR(p1["scale"][0].get<double>(), 0.2, 1e-12);

    // Reorder.
    Reply reordered = h.put("/scenes/" + id + "/placements", json::array({newId, "elbow"}));
    expectRevision(reordered, 200);
    EXPECT_EQ(reordered.js()["scene"]["placements"][0]["id"], newId);
    EXPECT_EQ(reordered.js()["scene"]["placements"][1]["id"], "elbow");

    // Remove.
    Reply removed = h.del("/scenes/" + id + "/placements/" + newId);
    expectRevision(removed, 200);
    ASSERT_EQ(removed.js()["scene"]["placements"].size(), 1u);
    EXPECT_EQ(removed.js()["scene"]["placements"][0]["id"], "elbow");

    // Pose: replace, then merge (time replaced, joints merged, null removes one).
    Reply pose = h.put("/scenes/" + id + "/pose",
                       json::parse(R"({"animation": "elbow_curl", "time": 0.25, "joints": {
                           "spine_02": {"axis_angles": {"x": 10}},
                           "neck_01": {"axis_angles": {"y": 20}}}})"));
    expectRevision(pose, 200);
    EXPECT_EQ(pose.js()["scene"]["pose"]["time"], 0.25);
    Reply merged =
        h.patch("/scenes/" + id + "/pose", json::parse(R"({"time": 0.5, "joints": {"neck_01": null,
                               "head": {"axis_angles": {"x": 5}}}})"));
    expectRevision(merged, 200);
    const json mp = merged.js()["scene"]["pose"];
    EXPECT_EQ(mp["time"], 0.5);
    EXPECT_EQ(mp["animation"], "elbow_curl");
    EXPECT_TRUE(mp["joints"].contains("spine_02")) << mp;
    EXPECT_TRUE(mp["joints"].contains("head")) << mp;
    EXPECT_FALSE(mp["joints"].contains("neck_01")) << mp;

    // Frames: size from the query, format, backend header.
    const std::string backendName = h.get("/info").js()["backend"];
    Reply png = h.get("/scenes/" + id + "/frame?width=128&height=96");
    ASSERT_EQ(png.status, 200) << png;
    EXPECT_EQ(png.header("Content-Type"), "image/png");
    EXPECT_EQ(png.header("X-Dermis-Backend"), backendName);
    auto a = decodeFrame(png.bytes());
    ASSERT_TRUE(a) << a.error().message;
    EXPECT_EQ(a->width, 128);
    EXPECT_EQ(a->height, 96);
    Reply jpeg =
        h.get("/scenes/" + id + "/frame?format=jpeg&width=120&height=80&msaa=2&yaw=30&pitch=5");
    ASSERT_EQ(jpeg.status, 200) << jpeg;
    EXPECT_EQ(jpeg.header("Content-Type"), "image/jpeg");
    EXPECT_TRUE(jpeg.hasHeader("X-Dermis-Backend"));
    auto j = decodeFrame(jpeg.bytes());
    ASSERT_TRUE(j) << j.error().message;
    EXPECT_EQ(j->width, 120);
    EXPECT_EQ(j->height, 80);

    // Two pose times give different frames (the elbow curls); the same time the same frame.
    ASSERT_EQ(h.patch("/scenes/" + id + "/pose", {{"time", 0.0}}).status, 200);
    ++rev;
    auto f0 = decodeFrame(h.get("/scenes/" + id + "/frame").bytes());
    auto f0again = decodeFrame(h.get("/scenes/" + id + "/frame").bytes());
    ASSERT_EQ(h.patch("/scenes/" + id + "/pose", {{"time", 1.0}}).status, 200);
    ++rev;
    auto f1 = decodeFrame(h.get("/scenes/" + id + "/frame").bytes());
    ASSERT_TRUE(f0 && f0again && f1);
    EXPECT_EQ(f0->width, 128); // render.size of the document
    EXPECT_GT(pixelsDiffering(*f0, *f1), 20u);
    EXPECT_EQ(pixelsDiffering(*f0, *f0again), 0u);
    // The query's time overrides the pose's without an edit.
    auto q0 = decodeFrame(h.get("/scenes/" + id + "/frame?time=0").bytes());
    ASSERT_TRUE(q0);
    EXPECT_EQ(pixelsDiffering(*f0, *q0), 0u);
    EXPECT_EQ(h.get("/scenes/" + id).js()["revision"], rev);

    // Height maps.
    for (const char* map : {"bump", "displacement"}) {
        SCOPED_TRACE(map);
        const std::string base = "/scenes/" + id + "/heightmaps/" + map;
        Reply p16 = h.get(base + "?format=png16");
        ASSERT_EQ(p16.status, 200) << p16;
        EXPECT_TRUE(isPng(p16.body));
        EXPECT_EQ(pngBitDepth(p16.body), 16);
        Reply dflt = h.get(base);
        ASSERT_EQ(dflt.status, 200) << dflt;
        EXPECT_TRUE(isPng(dflt.body));
        Reply exr = h.get(base + "?format=exr");
        ASSERT_EQ(exr.status, 200) << exr;
        EXPECT_TRUE(isExr(exr.body));
        Reply f32 = h.get(base + "?format=f32");
        ASSERT_EQ(f32.status, 200) << f32;
        EXPECT_EQ(f32.body.size(), 4u * 256 * 256);
        EXPECT_EQ(f32.header("Content-Type"), "application/octet-stream");
    }
    Reply normal = h.get("/scenes/" + id + "/heightmaps/normal");
    ASSERT_EQ(normal.status, 200) << normal;
    auto n = decodeFrame(normal.bytes());
    ASSERT_TRUE(n) << n.error().message;
    EXPECT_EQ(n->width, 256);
    EXPECT_EQ(n->height, 256);
    Reply nexr = h.get("/scenes/" + id + "/heightmaps/normal?format=exr");
    ASSERT_EQ(nexr.status, 200) << nexr;
    EXPECT_TRUE(isExr(nexr.body));

    // Delete.
    EXPECT_EQ(h.del("/scenes/" + id).status, 204);
    expectError(h.get("/scenes/" + id), 404, "id");
    expectError(h.get("/scenes/" + id + "/frame"), 404, "id");
    expectError(h.del("/scenes/" + id), 404, "id");
}

// ================================================================================================
// Server-sent events
// ================================================================================================

TEST_F(ApiHttpTest, EventsStreamHelloAndOneChangePerEdit) {
    Http h = http();
    const std::string id = createScene(smallScene());
    ASSERT_FALSE(id.empty());

    std::mutex mutex;
    std::condition_variable cv;
    std::string received;
    std::atomic<bool> stop{false};
    int streamStatus = 0;
    std::thread reader([&] {
        httplib::Client cli("127.0.0.1", server_->port());
        cli.set_read_timeout(30, 0);
        auto res = cli.Get(
            kApi + "/scenes/" + id + "/events",
            [&](const httplib::Response& r) {
                std::lock_guard<std::mutex> lock(mutex);
                streamStatus = r.status;
                return r.status == 200;
            },
            [&](const char* data, std::size_t n) {
                {
                    std::lock_guard<std::mutex> lock(mutex);
                    received.append(data, n);
                }
                cv.notify_all();
                return !stop.load();
            });
        (void)res;
        cv.notify_all();
    });
    auto waitFor = [&](auto pred) {
        std::unique_lock<std::mutex> lock(mutex);
        return cv.wait_for(lock, std::chrono::seconds(10), [&] { return pred(received); });
    };
    auto count = [](const std::string& s, const std::string& what) {
        std::size_t n = 0;
        for (std::size_t p = s.find(what); p != std::string::npos; p = s.find(what, p + 1))
            ++n;
        return n;
    };
    const bool hello = waitFor([&](const std::string& s) { return count(s, "event: hello") == 1; });
    EXPECT_TRUE(hello) << received;
    EXPECT_EQ(h.patch("/scenes/" + id + "/pose", {{"time", 0.1}}).status, 200);
    EXPECT_EQ(h.patch("/scenes/" + id + "/placements/elbow", {{"h", 0.5}}).status, 200);
    const bool changes =
        waitFor([&](const std::string& s) { return count(s, "event: change") >= 2; });
    EXPECT_TRUE(changes) << received;
    stop = true;
    reader.join(); // the next ping (≤ 1 s) ends the stream

    EXPECT_EQ(streamStatus, 200);
    // Parse the events: "event: X\ndata: {...}\n\n"; comments (": ping") are skipped.
    std::vector<std::pair<std::string, json>> events;
    std::istringstream in(received);
    std::string line, type;
    while (std::getline(in, line)) {
        if (line.rfind("event: ", 0) == 0)
            type = line.substr(7);
        else if (line.rfind("data: ", 0) == 0)
            events.push_back({type, json::parse(line.substr(6), nullptr, false)});
    }
    ASSERT_GE(events.size(), 3u) << received;
    EXPECT_EQ(events[0].first, "hello");
    EXPECT_EQ(events[0].second["revision"], 1);
    EXPECT_EQ(events[0].second["scene"], id);
    EXPECT_EQ(events[1].first, "change");
    EXPECT_EQ(events[1].second["revision"], 2);
    EXPECT_EQ(events[1].second["type"], "pose");
    EXPECT_EQ(events[2].first, "change");
    EXPECT_EQ(events[2].second["revision"], 3);
    EXPECT_EQ(events[2].second["type"], "placement_updated");
    EXPECT_EQ(events.size(), 3u) << received;

    expectError(h.get("/scenes/s_0000000000000000/events"), 404, "id");
    EXPECT_EQ(h.del("/scenes/" + id).status, 204);
}

TEST_F(ApiHttpTest, EventsStreamEndsWhenTheSceneIsDeleted) {
    Http h = http();
    const std::string id = createScene(smallScene());
    ASSERT_FALSE(id.empty());
    std::atomic<bool> gotHello{false}, ended{false};
    std::string received;
    std::thread reader([&] {
        httplib::Client cli("127.0.0.1", server_->port());
        cli.set_read_timeout(30, 0);
        auto res =
            cli.Get(kApi + "/scenes/" + id + "/events", [&](const char* data, std::size_t n) {
                received.append(data, n);
                if (received.find("event: hello") != std::string::npos) gotHello = true;
                return received.size() < 100000;
            });
        ended = true;
        (void)res;
    });
    for (int i = 0; i < 1000 && !gotHello; ++i)
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    ASSERT_TRUE(gotHello.load());
    EXPECT_EQ(h.del("/scenes/" + id).status, 204);
    for (int i = 0; i < 1000 && !ended; ++i)
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    EXPECT_TRUE(ended.load()) << "the stream did not end within 10 s of the deletion";
    reader.join();
    EXPECT_NE(received.find("\"deleted\""), std::string::npos) << received;
}

TEST_F(ApiHttpTest, EventStreamsCannotTakeEveryHttpThread) {
    // Each open stream holds an HTTP worker thread (the fixture has 24): beyond a cap, streams are
    // refused with 503 so that other requests are still served.
    Http h = http();
    const std::string id = createScene(smallScene());
    ASSERT_FALSE(id.empty());
    constexpr int kStreams = 24;
    std::mutex mutex;
    std::condition_variable cv;
    std::vector<int> statuses(kStreams, 0);
    std::vector<std::string> retryAfter(kStreams);
    std::atomic<bool> stop{false};
    std::vector<std::thread> readers;
    for (int i = 0; i < kStreams; ++i)
        readers.emplace_back([&, i] {
            httplib::Client cli("127.0.0.1", server_->port());
            cli.set_read_timeout(30, 0);
            auto res = cli.Get(
                kApi + "/scenes/" + id + "/events",
                [&](const httplib::Response& r) {
                    {
                        std::lock_guard<std::mutex> lock(mutex);
                        statuses[static_cast<std::size_t>(i)] = r.status;
                        retryAfter[static_cast<std::size_t>(i)] = r.get_header_value("Retry-After");
                    }
                    cv.notify_all();
                    return true;
                },
                [&](const char*, std::size_t) { return !stop.load(); });
            if (!res) {
                std::lock_guard<std::mutex> lock(mutex);
                if (statuses[static_cast<std::size_t>(i)] == 0)
                    statuses[static_cast<std::size_t>(i)] = -1;
            }
            cv.notify_all();
        });
    {
        std::unique_lock<std::mutex> lock(mutex);
        cv.wait_for(lock, std::chrono::seconds(10),
                    [&] { return std::count(statuses.begin(), statuses.end(), 0) == 0; });
    }
    // While the streams are open, the server answers other requests.
    httplib::Client probe("127.0.0.1", server_->port());
    probe.set_read_timeout(5, 0);
    auto health = probe.Get(kApi + "/health");
    EXPECT_TRUE(health && health->status == 200)
        << "GET /health while " << kStreams << " streams are open: "
        << (health ? std::to_string(health->status) : httplib::to_string(health.error()));
    stop = true;
    for (std::thread& t : readers)
        t.join();
    int open = 0, refused = 0;
    for (int i = 0; i < kStreams; ++i) {
        if (statuses[static_cast<std::size_t>(i)] == 200)
            ++open;
        else if (statuses[static_cast<std::size_t>(i)] == 503) {
            ++refused;
            EXPECT_FALSE(retryAfter[static_cast<std::size_t>(i)].empty());
        } else
            ADD_FAILURE() << "stream " << i << ": status " << statuses[static_cast<std::size_t>(i)];
    }
    EXPECT_GE(open, 1);
    EXPECT_GE(refused, 1);
    EXPECT_EQ(h.del("/scenes/" + id).status, 204);
}

// ================================================================================================
// Stateless batch
// ================================================================================================

TEST_F(ApiHttpTest, BatchStreamsOneImagePartPerFrame) {
    Http h = http();
    json body = {{"scene", smallScene()},
                 {"frames", json::array({{{"time", 0.2}},
                                         {{"time", 0.8}},
                                         {{"pose", {{"animation", "squat"}, {"time", 1.0}}}}})},
                 {"format", "png"}};
    Reply r = h.post("/render", body);
    ASSERT_EQ(r.status, 200) << r;
    EXPECT_EQ(r.header("X-Dermis-Frames"), "3");
    const std::string ct = r.header("Content-Type");
    std::smatch m;
    ASSERT_TRUE(std::regex_search(ct, m, std::regex("^multipart/mixed; *boundary=\"?([^\";]+)\"?")))
        << ct;
    const auto parts = multipartParts(r.body, m[1]);
    ASSERT_EQ(parts.size(), 3u) << r.body.size();
    std::vector<Image8> frames;
    for (std::size_t k = 0; k < parts.size(); ++k) {
        SCOPED_TRACE(k);
        EXPECT_NE(parts[k].headers.find("Content-Type: image/png"), std::string::npos)
            << parts[k].headers;
        EXPECT_NE(parts[k].headers.find("X-Dermis-Frame: " + std::to_string(k)), std::string::npos);
        auto img = decodeFrame({parts[k].content.begin(), parts[k].content.end()});
        ASSERT_TRUE(img) << img.error().message;
        EXPECT_EQ(img->width, 128);
        EXPECT_EQ(img->height, 128);
        frames.push_back(std::move(*img));
    }
    ASSERT_EQ(frames.size(), 3u);
    EXPECT_GT(pixelsDiffering(frames[0], frames[2]), 20u); // squat vs elbow curl

    // JPEG batches too.
    body["format"] = "jpeg";
    body["frames"] = json::array({{{"time", 0.0}}});
    Reply jr = h.post("/render", body);
    ASSERT_EQ(jr.status, 200) << jr;
    std::smatch jm;
    const std::string jct = jr.header("Content-Type");
    ASSERT_TRUE(std::regex_search(jct, jm, std::regex("boundary=\"?([^\";]+)\"?")));
    const auto jparts = multipartParts(jr.body, jm[1]);
    ASSERT_EQ(jparts.size(), 1u);
    EXPECT_NE(jparts[0].headers.find("image/jpeg"), std::string::npos);
    EXPECT_TRUE(decodeFrame({jparts[0].content.begin(), jparts[0].content.end()}));
}

// ================================================================================================
// Bad input: one table, each case answered with the JSON error and the right status
// ================================================================================================

struct BadCase {
    std::string name, method, path, contentType, body;
    std::vector<int> statuses; ///< any of these
    std::string field;         ///< expected "field" when not empty
};

std::string nested(std::size_t depth, bool closed) {
    std::string s(depth, '[');
    if (closed) s += std::string(depth, ']');
    return s;
}

TEST_F(ApiHttpTest, BadInputGetsAJsonErrorWithTheRightStatus) {
    Http h = http();
    // The state the cases refer to: a scene {S} with placements "elbow" and "knee", an uploaded
    // model {M} used by scene {SM}, an uploaded pattern {P} used by scene {SP}.
    json sceneDoc = smallScene();
    sceneDoc["placements"].push_back(placementOf("crease", "knee"));
    const std::string S = createScene(sceneDoc);
    const std::string M = uploadModel(kCesiumMan);
    const std::string SM = createScene(
        {{"format", "dermis.scene/1"}, {"model", M}, {"heightmap", {{"size", {256, 256}}}}});
    Reply pu = h.upload("/patterns?name=bad-input", domePng(), "image/png");
    ASSERT_EQ(pu.status, 201) << pu;
    const std::string P = pu.js()["id"];
    json usingP = smallScene();
    usingP["placements"] = {placementOf(P, "x")};
    const std::string SP = createScene(usingP);
    ASSERT_FALSE(S.empty() || M.empty() || SM.empty() || SP.empty());

    const std::vector<std::uint8_t> cesium = readBytes(kCesiumMan);
    std::mt19937 rng(1234);
    std::string randomBytes(4096, '\0');
    for (char& c : randomBytes)
        c = static_cast<char>(rng() & 0xff);
    std::string glbGarbage =
        "glTF" + std::string("\x02\x00\x00\x00\x00\x10\x00\x00", 8) + randomBytes;
    std::string truncatedGlb(cesium.begin(), cesium.begin() + 100);
    std::string halfGlb(cesium.begin(), cesium.begin() + static_cast<long>(cesium.size() / 2));
    const std::string gltfJson =
        R"({"asset": {"version": "2.0"}, "buffers": [{"uri": "/etc/passwd", "byteLength": 10}]})";
    std::string png = str(domePng());
    std::string corruptPng = png.substr(0, 8) + randomBytes;
    std::string truncatedPng = png.substr(0, png.size() / 2);
    std::string widePng = str(domePng(5000, 1)); // over maxImageSide (4096)
    std::string oversized(kMaxUpload + 1024, 'x');
    std::copy_n("glTF", 4, oversized.begin());

    // Scene documents with one thing wrong (built from the small scene).
    auto doc = [&](auto edit) {
        json d = smallScene();
        edit(d);
        return d.dump();
    };
    auto withPlacementField = [&](const char* key, json value) {
        return doc([&](json& d) { d["placements"][0][key] = value; });
    };
    auto replaceInDoc = [&](const std::string& from, const std::string& to) {
        std::string s = smallScene().dump();
        s.replace(s.find(from), from.size(), to);
        return s;
    };
    auto withModel = [&](const std::string& model) {
        return doc([&](json& d) { d["model"] = model; });
    };
    json manyPlacements = smallScene();
    manyPlacements["placements"] = json::array();
    for (std::size_t i = 0; i <= kMaxPlacements; ++i)
        manyPlacements["placements"].push_back(placementOf("crease", "p" + std::to_string(i)));
    auto batch = [&](json frames, json format = "png") {
        return json{
            {"scene", smallScene()}, {"frames", std::move(frames)}, {"format", std::move(format)}}
            .dump();
    };
    json tenThousand = json::array();
    for (int i = 0; i < 10000; ++i)
        tenThousand.push_back({{"time", 0}});

    const std::string J = "application/json";
    const std::string GLB = "model/gltf-binary";
    const std::string scene = "/scenes/" + S;
    // clang-format off
    const std::vector<BadCase> cases = {
        // --- malformed JSON → 400
        {"truncated JSON", "POST", "/scenes", J, R"({"model": "builtin:default", "placements": [)", {400}, "body"},
        {"trailing garbage", "POST", "/scenes", J, R"({"model": "builtin:default"} xyz)", {400}, "body"},
        {"empty body", "POST", "/scenes", J, "", {400}, "body"},
        {"BOM only", "POST", "/scenes", J, "\xEF\xBB\xBF", {400}, "body"},
        {"10000 unclosed [", "POST", "/scenes", J, nested(10000, false), {400}, "body"},
        {"NaN literal", "POST", "/scenes", J, replaceInDoc("\"theta_min\"", "\"h\": NaN, \"theta_min\""), {400}, "body"},
        {"Infinity literal", "POST", "/scenes", J, R"({"model": "builtin:default", "render": {"camera": {"yaw": Infinity}}})", {400}, "body"},
        {"-Infinity literal", "PUT", scene, J, R"({"model": "builtin:default", "pose": {"time": -Infinity}})", {400}, "body"},
        {"single quotes", "POST", "/scenes", J, "{'model': 'builtin:default'}", {400}, "body"},
        {"comment", "POST", "/scenes", J, R"({"model": "builtin:default" /* hi */})", {400}, "body"},
        {"invalid UTF-8", "POST", "/scenes", J, "{\"model\": \"\xff\xfe\"}", {400}, "body"},
        {"truncated PUT", "PUT", scene, J, R"({"model": )", {400}, "body"},
        {"truncated placement", "POST", scene + "/placements", J, R"({"pattern": "crease", )", {400}, "body"},
        {"truncated pose patch", "PATCH", scene + "/pose", J, R"({"time": 0.5)", {400}, "body"},
        {"truncated placement patch", "PATCH", scene + "/placements/elbow", J, "{\"h\": ", {400}, "body"},
        {"truncated reorder", "PUT", scene + "/placements", J, R"(["elbow", )", {400}, "body"},
        {"truncated batch", "POST", "/render", J, R"({"scene": {)", {400}, "body"},
        {"deeply nested valid JSON", "POST", "/scenes", J, nested(100000, true), {400}, "body"},
        {"deeply nested in a field", "POST", "/scenes", J, "{\"model\": \"builtin:default\", \"x\": " + nested(100000, true) + "}", {400}, "body"},
        // --- valid JSON of the wrong shape or type → 422
        {"body is an array", "POST", "/scenes", J, "[]", {422}, ""},
        {"body is a string", "POST", "/scenes", J, "\"scene\"", {422}, ""},
        {"placements: 5", "POST", "/scenes", J, doc([](json& d) { d["placements"] = 5; }), {422}, "/placements"},
        {"center: \"x\"", "POST", "/scenes", J, withPlacementField("center", "x"), {422}, "/placements/0/center"},
        {"h: \"1\"", "POST", "/scenes", J, withPlacementField("h", "1"), {422}, "/placements/0/h"},
        {"heightmap size a string", "POST", "/scenes", J, doc([](json& d) { d["heightmap"]["size"] = "big"; }), {422}, "/heightmap/size"},
        {"default_patterns a string", "POST", "/scenes", J, R"({"default_patterns": "yes"})", {422}, "/default_patterns"},
        {"default_patterns on another model", "POST", "/scenes", J, "{\"default_patterns\": true, \"model\": \"" + M + "\"}", {422}, "/default_patterns"},
        {"unsupported format version", "POST", "/scenes", J, doc([](json& d) { d["format"] = "dermis.scene/2"; }), {422}, "/format"},
        {"3-element rotation", "PUT", scene + "/pose", J, R"({"joints": {"head": {"rotation": [0, 0, 1]}}})", {422}, "/pose/joints/head/rotation"},
        {"pose is an array", "PUT", scene + "/pose", J, "[1, 2]", {422}, "/pose"},
        {"pose patch joints: 5", "PATCH", scene + "/pose", J, R"({"joints": 5})", {422}, "/pose/joints"},
        {"placement is a number", "POST", scene + "/placements", J, "42", {422}, ""},
        {"duplicate placement id", "POST", scene + "/placements", J, placementOf("crease", "elbow").dump(), {422}, "/placements/2/id"},
        {"render msaa 3 in the document", "PUT", scene, J, doc([](json& d) { d["render"]["msaa"] = 3; }), {422}, "/render/msaa"},
        {"render size 0", "PUT", scene, J, doc([](json& d) { d["render"]["size"] = {0, 128}; }), {422}, "/render/size/0"},
        // --- non-finite and out-of-range numbers
        {"center 1e999", "POST", "/scenes", J, replaceInDoc("[0.3,0.4]", "[1e999,0.4]"), {400, 422}, ""},
        {"h -1e999", "POST", "/scenes", J, replaceInDoc("\"theta_min\"", "\"h\": -1e999, \"theta_min\""), {400, 422}, ""},
        {"theta_min == theta_max", "POST", "/scenes", J, withPlacementField("theta_max", 0), {422}, "/placements/0/theta_max"},
        {"negative h", "POST", "/scenes", J, withPlacementField("h", -1), {422}, "/placements/0/h"},
        {"zero scale", "POST", "/scenes", J, withPlacementField("scale", json::array({0, 0.1})), {422}, "/placements/0/scale/0"},
        {"negative pose time", "PATCH", scene + "/pose", J, R"({"time": -1})", {422}, "/pose/time"},
        // --- unknown names → 404
        {"unknown pattern", "POST", "/scenes", J, withPlacementField("pattern", "no_such_pattern"), {404}, "/placements/0/pattern"},
        {"unknown joint", "POST", "/scenes", J, withPlacementField("joint", "tail_07"), {404}, "/placements/0/joint"},
        {"unknown clip", "POST", "/scenes", J, doc([](json& d) { d["pose"]["animation"] = "moonwalk"; }), {404}, "/pose/animation"},
        {"unknown pose joint", "PATCH", scene + "/pose", J, R"({"joints": {"tail_07": {"axis_angles": {"x": 5}}}})", {404}, "/pose/joints/tail_07"},
        {"unknown model id", "POST", "/scenes", J, withModel("m_0000000000000000"), {404}, "/model"},
        {"model ../../etc/passwd", "POST", "/scenes", J, withModel("../../etc/passwd"), {404, 422}, "/model"},
        {"model /etc/passwd", "POST", "/scenes", J, withModel("/etc/passwd"), {404, 422}, "/model"},
        {"model file:///etc/passwd", "POST", "/scenes", J, withModel("file:///etc/passwd"), {404, 422}, "/model"},
        {"model builtin:../x", "PUT", scene, J, withModel("builtin:../x"), {404, 422}, "/model"},
        {"model default.glb", "PUT", scene, J, withModel("models/default.glb"), {404, 422}, "/model"},
        {"pattern alias to a path", "POST", "/scenes", J, doc([](json& d) { d["patterns"] = {{"evil", "/etc/passwd"}}; d["placements"][0]["pattern"] = "evil"; }), {404}, "/patterns/evil"},
        {"pattern alias to a relative path", "POST", "/scenes", J, doc([](json& d) { d["patterns"] = {{"evil", "../patterns/crease.png"}}; }), {404}, "/patterns/evil"},
        {"pattern alias to a built-in", "POST", "/scenes", J, doc([](json& d) { d["patterns"] = {{"c", "crease"}}; }), {404, 422}, "/patterns/c"},
        {"base map path", "POST", "/scenes", J, doc([](json& d) { d["heightmap"]["base"] = "/etc/passwd"; }), {404}, "/heightmap/base"},
        {"unknown scene GET", "GET", "/scenes/s_0000000000000000", "", "", {404}, "id"},
        {"unknown scene PUT", "PUT", "/scenes/s_0000000000000000", J, smallScene().dump(), {404}, "id"},
        {"unknown scene DELETE", "DELETE", "/scenes/s_0000000000000000", "", "", {404}, "id"},
        {"unknown scene frame", "GET", "/scenes/s_0000000000000000/frame", "", "", {404}, "id"},
        {"unknown scene heightmap", "GET", "/scenes/s_0000000000000000/heightmaps/bump", "", "", {404}, "id"},
        {"unknown scene placement", "POST", "/scenes/s_0000000000000000/placements", J, placementOf("crease").dump(), {404}, "id"},
        {"unknown scene pose", "PATCH", "/scenes/s_0000000000000000/pose", J, "{}", {404}, "id"},
        {"unknown placement PATCH", "PATCH", scene + "/placements/nope", J, R"({"h": 2})", {404}, "pid"},
        {"unknown placement DELETE", "DELETE", scene + "/placements/nope", "", "", {404}, "pid"},
        {"changing a placement id", "PATCH", scene + "/placements/elbow", J, R"({"id": "other"})", {422}, "/id"},
        {"patch sets an invalid value", "PATCH", scene + "/placements/elbow", J, R"({"h": -2})", {422}, "/placements/0/h"},
        {"reorder missing an id", "PUT", scene + "/placements", J, R"(["elbow"])", {422}, ""},
        {"reorder duplicate ids", "PUT", scene + "/placements", J, R"(["elbow", "elbow"])", {422}, "/1"},
        {"reorder unknown id", "PUT", scene + "/placements", J, R"(["elbow", "nope"])", {404}, "/1"},
        {"reorder not an array", "PUT", scene + "/placements", J, R"({"order": ["elbow", "knee"]})", {422}, ""},
        {"reorder non-string id", "PUT", scene + "/placements", J, R"(["elbow", 7])", {422}, "/1"},
        // --- sign-in
        {"session with no body", "POST", "/session", J, "", {400}, "body"},
        {"session with no body or type", "POST", "/session", "", "", {415}, "body"},
        {"session non-JSON", "POST", "/session", J, "token=abc", {400}, "body"},
        {"session as a form", "POST", "/session", "application/x-www-form-urlencoded", "token=abc", {415}, "body"},
        {"session token not a string", "POST", "/session", J, R"({"token": 12345})", {422}, "/token"},
        {"session token null", "POST", "/session", J, R"({"token": null})", {422}, "/token"},
        {"session token an array", "POST", "/session", J, R"({"token": ["s3cret"]})", {422}, "/token"},
        {"session without token", "POST", "/session", J, R"({"password": "s3cret"})", {422}, "/token"},
        {"session body an array", "POST", "/session", J, R"(["s3cret"])", {422}, ""},
        {"session body a string", "POST", "/session", J, R"("s3cret")", {422}, ""},
        {"session nested deep", "POST", "/session", J, nested(100000, true), {400}, "body"},
        // --- frame and map parameters
        {"width=100000", "GET", scene + "/frame?width=100000", "", "", {413, 422}, "width"},
        {"width=99999999999", "GET", scene + "/frame?width=99999999999", "", "", {413, 422}, "width"},
        {"heightmap size 99999²", "PUT", scene, J, doc([](json& d) { d["heightmap"]["size"] = {99999, 99999}; }), {413, 422}, "/heightmap/size/0"},
        {"render size over the limit", "PUT", scene, J, doc([](json& d) { d["render"]["size"] = {4096, 64}; }), {413}, "/render/size/0"},
        {"width=0", "GET", scene + "/frame?width=0", "", "", {422}, "width"},
        {"height=-5", "GET", scene + "/frame?height=-5", "", "", {422}, "height"},
        {"msaa=3", "GET", scene + "/frame?msaa=3", "", "", {422}, "msaa"},
        {"pitch=200", "GET", scene + "/frame?pitch=200", "", "", {422}, "pitch"},
        {"width=abc", "GET", scene + "/frame?width=abc", "", "", {422}, "width"},
        {"width=12px", "GET", scene + "/frame?width=12px", "", "", {422}, "width"},
        {"yaw=nan", "GET", scene + "/frame?yaw=nan", "", "", {422}, "yaw"},
        {"yaw=inf", "GET", scene + "/frame?yaw=inf", "", "", {422}, "yaw"},
        {"distance=-1", "GET", scene + "/frame?distance=-1", "", "", {422}, "distance"},
        {"time=-1", "GET", scene + "/frame?time=-1", "", "", {422}, "time"},
        {"format=gif", "GET", scene + "/frame?format=gif", "", "", {422}, "format"},
        {"unknown heightmap", "GET", scene + "/heightmaps/roughness", "", "", {404}, "map"},
        {"bad heightmap format", "GET", scene + "/heightmaps/bump?format=tiff", "", "", {422}, "format"},
        {"normal map as f32", "GET", scene + "/heightmaps/normal?format=f32", "", "", {422}, "format"},
        {"uv-layout format=svg", "GET", "/models/builtin:default/uv-layout?format=svg", "", "", {422}, "format"},
        {"uv-layout size=0", "GET", "/models/builtin:default/uv-layout?format=png&size=0", "", "", {422}, "size"},
        {"pattern image size=0", "GET", "/patterns/crease/image?size=0", "", "", {422}, "size"},
        {"pattern image size=99999", "GET", "/patterns/crease/image?size=99999", "", "", {413, 422}, "size"},
        // --- uploads
        {"first 100 bytes of a .glb", "POST", "/models", GLB, truncatedGlb, {400, 415, 422}, "body"},
        {"half a .glb", "POST", "/models", GLB, halfGlb, {400, 415, 422}, "body"},
        {"random bytes as .glb", "POST", "/models", GLB, randomBytes, {400, 415}, "body"},
        {"glTF + garbage", "POST", "/models", GLB, glbGarbage, {400, 415, 422}, "body"},
        {"empty .glb", "POST", "/models", GLB, "", {400, 415}, "body"},
        {".gltf JSON body", "POST", "/models", GLB, gltfJson, {415}, "body"},
        {".gltf JSON body as model/gltf+json", "POST", "/models", "model/gltf+json", gltfJson, {415}, "body"},
        {"application/json to POST /models", "POST", "/models", J, str(cesium), {415}, "body"},
        {"text/plain to POST /scenes", "POST", "/scenes", "text/plain", smallScene().dump(), {415}, "body"},
        {"no content type to POST /scenes", "POST", "/scenes", "", smallScene().dump(), {415}, "body"},
        {"text/plain to PATCH pose", "PATCH", scene + "/pose", "text/plain", "{}", {415}, "body"},
        {"text/plain to POST /patterns", "POST", "/patterns", "text/plain", png, {415}, "body"},
        {"corrupt PNG", "POST", "/patterns", "image/png", corruptPng, {400, 415}, "body"},
        {"truncated PNG", "POST", "/patterns", "image/png", truncatedPng, {400, 415}, "body"},
        {"random bytes as image", "POST", "/patterns", "image/png", randomBytes, {400, 415}, "body"},
        {"empty image", "POST", "/patterns", "image/png", "", {400, 415}, "body"},
        {"image wider than the limit", "POST", "/patterns", "image/png", widePng, {413}, "body"},
        {"oversized model upload", "POST", "/models", GLB, oversized, {413}, "body"},
        {"oversized pattern upload", "POST", "/patterns", "image/png", oversized, {413}, "body"},
        {"oversized scene", "POST", "/scenes", J, oversized, {413}, "body"},
        // --- batch
        {"batch frames empty", "POST", "/render", J, batch(json::array()), {422}, "/frames"},
        {"batch frames not an array", "POST", "/render", J, batch({{"time", 0}}), {422}, "/frames"},
        {"batch 10000 frames", "POST", "/render", J, batch(tenThousand), {413}, "/frames"},
        {"batch frame without time or pose", "POST", "/render", J, batch(json::array({json::object()})), {422}, "/frames/0"},
        {"batch frame negative time", "POST", "/render", J, batch(json::array({{{"time", -2}}})), {422}, "/frames/0/time"},
        {"batch frame time a string", "POST", "/render", J, batch(json::array({{{"time", "0"}}})), {422}, "/frames/0/time"},
        {"batch frame pose unknown joint", "POST", "/render", J, batch(json::parse(R"([{"time": 0}, {"pose": {"joints": {"tail_07": {"axis_angles": {"x": 1}}}}}])")), {404}, "/frames/1/pose/joints/tail_07"},
        {"batch bad format", "POST", "/render", J, batch(json::array({{{"time", 0}}}), "gif"), {422}, "/format"},
        {"batch without scene", "POST", "/render", J, R"({"frames": [{"time": 0}]})", {422}, "/scene"},
        {"batch scene unknown model", "POST", "/render", J, R"({"scene": {"format": "dermis.scene/1", "model": "/etc/passwd"}, "frames": [{"time": 0}]})", {404}, "/scene/model"},
        {"batch is an array", "POST", "/render", J, "[]", {422}, ""},
        // --- conflicts and limits
        {"delete builtin:default", "DELETE", "/models/builtin:default", "", "", {409}, "id"},
        {"delete a built-in pattern", "DELETE", "/patterns/crease", "", "", {409}, "id"},
        {"delete a model in use", "DELETE", "/models/" + M, "", "", {409}, "id"},
        {"delete a pattern in use", "DELETE", "/patterns/" + P, "", "", {409}, "id"},
        {"delete an unknown pattern", "DELETE", "/patterns/p_0000000000000000", "", "", {404}, "id"},
        {"delete an unknown model", "DELETE", "/models/m_0000000000000000", "", "", {404}, "id"},
        {"placements over the limit", "PUT", scene, J, manyPlacements.dump(), {413}, "/placements"},
        // --- odd ids in the URL: never a file read
        {"model %2e%2e", "GET", "/models/%2e%2e", "", "", {404}, ""},
        {"model ..%2f..%2fetc%2fpasswd", "GET", "/models/..%2f..%2fetc%2fpasswd", "", "", {404}, ""},
        {"model builtin:..%2fdefault", "GET", "/models/builtin:..%2fdefault", "", "", {404}, ""},
        {"model builtin:default.glb", "GET", "/models/builtin:default.glb", "", "", {404}, "id"},
        {"pattern %2e%2e%2fmanifest.json", "GET", "/patterns/%2e%2e%2fmanifest.json/image", "", "", {404}, ""},
        {"pattern crease.png", "GET", "/patterns/crease.png/image", "", "", {404}, "id"},
        {"pattern ..", "DELETE", "/patterns/..", "", "", {404}, ""},
        {"scene %2e%2e", "GET", "/scenes/%2e%2e", "", "", {404}, ""},
        {"scene ../models", "GET", "/scenes/..%2Fmodels", "", "", {404}, ""},
        {"scene id with NUL", "GET", "/scenes/s_%00", "", "", {400, 404}, ""},
        {"scene file name", "GET", "/scenes/" + S + ".json", "", "", {404}, "id"},
    };
    // clang-format on
    EXPECT_GE(cases.size(), 60u);

    for (const BadCase& c : cases) {
        SCOPED_TRACE(c.name + " (" + c.method + " " + c.path.substr(0, 80) + ")");
        Reply r = h.call(c.method, c.path, c.body, c.contentType);
        ASSERT_NE(r.status, -1) << r;
        EXPECT_TRUE(std::find(c.statuses.begin(), c.statuses.end(), r.status) != c.statuses.end())
            << "expected " << ::testing::PrintToString(c.statuses) << ", got " << r;
        expectError(r, r.status, c.field);
        Reply health = h.get("/health");
        ASSERT_EQ(health.status, 200) << "after " << c.name << ": " << health;
    }

    // Nothing changed: the scene is as created, the uploads are still there.
    Reply after = h.get("/scenes/" + S);
    ASSERT_EQ(after.status, 200);
    EXPECT_EQ(after.js()["revision"], 1) << "a failed edit changed the scene";
    EXPECT_EQ(after.js()["scene"]["placements"].size(), 2u);
    EXPECT_EQ(h.get("/models/" + M).status, 200);
    EXPECT_EQ(h.get("/patterns/" + P + "/image").status, 200);
    for (const std::string& id : {S, SM, SP})
        EXPECT_EQ(h.del("/scenes/" + id).status, 204);
    EXPECT_EQ(h.del("/models/" + M).status, 204);
    EXPECT_EQ(h.del("/patterns/" + P).status, 204);
    std::cout << "[ ApiHttpTest ] " << cases.size() << " bad-input cases\n";
}

// ================================================================================================
// Authentication (a second server, with a token)
// ================================================================================================

class ApiHttpAuthTest : public ::testing::Test {
  protected:
    static constexpr const char* kToken = "s3cret-t0ken";
    static void SetUpTestSuite() { server_ = LiveServer::start(mainLimits(), kToken, error_); }
    static void TearDownTestSuite() { server_.reset(); }
    void SetUp() override {
        ASSERT_TRUE(server_ && error_.empty()) << "the server did not start: " << error_;
    }
    static inline std::unique_ptr<LiveServer> server_;
    static inline std::string error_;
};

TEST_F(ApiHttpAuthTest, EveryRouteButTheOpenOnesNeedsTheBearerToken) {
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

TEST_F(ApiHttpAuthTest, SessionCookieAuthorisesTheApiAndTheEventStream) {
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

TEST_F(ApiHttpAuthTest, WrongTokensAndForgedCookiesAre401) {
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

class ApiHttpSessionLimitTest : public ::testing::Test {
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

TEST_F(ApiHttpSessionLimitTest, TheOldestSessionIsEvictedAndSessionsExpire) {
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
// Back-pressure (a fourth server, with a render queue of 1)
// ================================================================================================

class ApiHttpQueueTest : public ::testing::Test {
  protected:
    static void SetUpTestSuite() {
        ServerLimits l = mainLimits();
        l.queueLength = 1;
        server_ = LiveServer::start(l, "", error_);
    }
    static void TearDownTestSuite() { server_.reset(); }
    void SetUp() override {
        ASSERT_TRUE(server_ && error_.empty()) << "the server did not start: " << error_;
    }
    static inline std::unique_ptr<LiveServer> server_;
    static inline std::string error_;
};

TEST_F(ApiHttpQueueTest, AFullQueueAnswers503WithRetryAfter) {
    Http h(server_->port());
    const std::string id = h.post("/scenes", {{"default_patterns", true}}).js().value("id", "");
    ASSERT_FALSE(id.empty());
    constexpr int kClients = 8;
    std::vector<Reply> replies(kClients);
    std::vector<std::thread> threads;
    std::atomic<int> ready{0};
    for (int i = 0; i < kClients; ++i)
        threads.emplace_back([&, i] {
            ++ready;
            while (ready < kClients)
                std::this_thread::yield();
            replies[static_cast<std::size_t>(i)] =
                h.get("/scenes/" + id + "/frame?width=1024&height=1024&msaa=4");
        });
    for (std::thread& t : threads)
        t.join();
    int ok = 0, busy = 0;
    for (const Reply& r : replies) {
        if (r.status == 200) {
            ++ok;
            auto img = decodeFrame(r.bytes());
            ASSERT_TRUE(img);
            EXPECT_EQ(img->width, 1024);
        } else {
            ++busy;
            expectError(r, 503);
            EXPECT_EQ(r.js()["error"]["code"], "unavailable") << r;
            EXPECT_FALSE(r.header("Retry-After").empty()) << r;
        }
    }
    EXPECT_GE(ok, 1);
    std::cout << "[ ApiHttpQueueTest ] " << ok << " × 200, " << busy << " × 503\n";
    // Once the burst is over, renders go through again.
    EXPECT_EQ(h.get("/scenes/" + id + "/frame?width=64&height=64").status, 200);
    Reply info = h.get("/info");
    EXPECT_EQ(info.js()["render_queue"], 0);
}

} // namespace
