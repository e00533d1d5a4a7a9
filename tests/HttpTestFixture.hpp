// HttpTestFixture — what the FooHttpTest suites share: a real dermis::Service + dermis::Api served
// on 127.0.0.1 (any free port) from a thread of the test process, with a GL context on the backend
// named by $DERMIS_TEST_GL (LiveServer), real cpp-httplib clients over loopback, each request on a
// fresh connection (Http, Reply), the JSON error shape every failure answers (expectError), small
// scene documents and images, multipart/mixed parsing, the routes an OpenAPI YAML lists, a scene's
// event stream read on its own thread, session cookies, the limits the main server runs with, and
// the suite fixture with one such server (SharedServerTest). Header-only: everything is inline in
// dermis::test::http, so that any number of test files can include it.
#pragma once

#include "BuildPaths.hpp"
#include "TestFiles.hpp"
#include "http/api.hpp"
#include "io/frame_io.hpp"
#include "service/service.hpp"

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

namespace dermis::test::http {

using nlohmann::json;

inline const std::string kTestModels = dermis::build::testModelsDir();
inline const std::string kApi = "/api/v1";
inline const std::string kCesiumMan = kTestModels + "/CesiumMan/CesiumMan.glb";
inline const std::string kBarbarian = kTestModels + "/KayKitBarbarian/Barbarian.glb";
inline const std::string kRiggedFigure = kTestModels + "/RiggedFigure/RiggedFigure.glb";
inline constexpr std::size_t kMaxUpload = 8u << 20;
inline constexpr std::size_t kMaxPlacements = 24; // the default pattern set has 18

inline GlBackend testBackend() {
    const char* env = std::getenv("DERMIS_TEST_GL");
    if (!env || !*env) return GlBackend::Auto;
    auto b = glBackendFromString(env);
    return b ? *b : GlBackend::Auto;
}

inline std::string str(const std::vector<std::uint8_t>& b) {
    return {b.begin(), b.end()};
}
inline std::string fileText(const std::string& path) {
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
    /// The data folder (absolute): no answer of the server may contain it.
    std::string dataDir() const { return dir_.str(); }

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

inline std::ostream& operator<<(std::ostream& os, const Reply& r) {
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
inline void expectError(const Reply& r, int status, const std::string& field = "") {
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
inline json smallScene() {
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
inline json placementOf(const std::string& pattern, const std::string& id = "") {
    json p = {{"pattern", pattern},   {"center", {0.5, 0.5}}, {"scale", {0.2, 0.2}},
              {"joint", "forearm.l"}, {"axis", "x"},          {"theta_min", 0},
              {"theta_max", 90}};
    if (!id.empty()) p["id"] = id;
    return p;
}

/// A 64×64 grey dome as PNG bytes (first channel: 128 = height 0, 255 = 1).
inline std::vector<std::uint8_t> domePng(int w = 64, int h = 64) {
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

inline bool isPng(const std::string& b) {
    return b.size() > 8 && b.compare(0, 4, "\x89PNG") == 0;
}
inline bool isExr(const std::string& b) {
    return b.size() > 4 && b.compare(0, 4, "\x76\x2f\x31\x01") == 0;
}
/// Bit depth of a PNG (IHDR byte 24).
inline int pngBitDepth(const std::string& b) {
    return b.size() > 24 ? static_cast<unsigned char>(b[24]) : -1;
}

/// Pixels whose RGB differ by more than 24 in any channel.
inline std::size_t pixelsDiffering(const Image8& a, const Image8& b) {
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
inline std::vector<Part> multipartParts(const std::string& body, const std::string& boundary) {
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

/// The parts of a multipart/mixed answer (the boundary from its Content-Type); none when the
/// answer is not multipart/mixed.
inline std::vector<Part> multipartAnswerParts(const Reply& r) {
    const std::string ct = r.header("Content-Type");
    std::smatch m;
    if (!std::regex_search(ct, m, std::regex("^multipart/mixed; *boundary=\"?([^\";]+)\"?")))
        return {};
    return multipartParts(r.body, m[1]);
}

/// (METHOD, path) pairs under "paths:" of an OpenAPI YAML, by indentation.
inline std::set<std::pair<std::string, std::string>> openapiRoutes(const std::string& yaml) {
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
inline std::set<std::pair<std::string, std::string>> openapiOpenRoutes(const std::string& yaml) {
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
inline std::string fillRoute(std::string path) {
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
inline std::string sessionIdOf(const Reply& r) {
    std::smatch m;
    const std::string c = r.header("Set-Cookie");
    return std::regex_search(c, m, std::regex("^dermis_session=([^;]*)")) ? std::string(m[1]) : "";
}

inline httplib::Headers cookieHeader(const std::string& id) {
    return {{"Cookie", "dermis_session=" + id}};
}

inline ServerLimits mainLimits() {
    ServerLimits l;
    l.maxUploadBytes = kMaxUpload;
    l.maxRenderSide = 2048;
    l.queueLength = 16;
    l.maxPlacements = kMaxPlacements;
    return l;
}

// --- fixtures ------------------------------------------------------------------------------------

/// One server for the suite (no token, mainLimits()), started before its first test and stopped
/// after its last; each file derives its suite from it (`class FooHttpTest : public
/// SharedServerTest {};`).
class SharedServerTest : public ::testing::Test {
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
    /// Uploads a model; its id. Models are content-addressed: the same bytes uploaded by an
    /// earlier test of the shared server answer 200 with the same id (`fresh` = 201 required).
    static std::string uploadModel(const std::string& path, bool fresh = true) {
        Reply r = http().upload("/models?name=test", readBytes(path), "model/gltf-binary");
        if (fresh) EXPECT_EQ(r.status, 201) << path << ": " << r;
        else EXPECT_TRUE(r.status == 200 || r.status == 201) << path << ": " << r;
        return r.js().value("id", "");
    }

    static inline std::unique_ptr<LiveServer> server_;
    static inline std::string error_;
};

} // namespace dermis::test::http
