#include "http/api.hpp"

#include <httplib.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <regex>

namespace dermis {

using json = nlohmann::json;

namespace {

const std::string kPrefix = "/api/v1";

/// The one mapping from error codes to HTTP statuses.
int statusOf(ErrorCode code) {
    switch (code) {
    case ErrorCode::InvalidArgument: return 422;
    case ErrorCode::NotFound: return 404;
    case ErrorCode::Parse: return 400;
    case ErrorCode::Io: return 500;
    case ErrorCode::Unsupported: return 415;
    case ErrorCode::Conflict: return 409;
    case ErrorCode::TooLarge: return 413;
    case ErrorCode::Unavailable: return 503;
    case ErrorCode::Internal: return 500;
    }
    return 500;
}

void sendJson(httplib::Response& res, int status, const json& body) {
    res.status = status;
    res.set_content(body.dump(), "application/json");
}

void sendError(httplib::Response& res, int status, const std::string& code,
               const std::string& message, const std::string& field) {
    if (status == 503) res.set_header("Retry-After", "1");
    sendJson(res, status, {{"error", {{"code", code}, {"message", message}, {"field", field}}}});
}

void sendError(httplib::Response& res, const Error& e) {
    sendError(res, statusOf(e.code), errorCodeName(e.code), e.message, e.field);
}

/// Scene documents: an unsupported "format" version is an invalid value (422), not a media type.
void sendDocError(httplib::Response& res, const Error& e) {
    if (e.code == ErrorCode::Unsupported) {
        sendError(res, 422, errorCodeName(e.code), e.message, e.field);
        return;
    }
    sendError(res, e);
}

bool hasContentType(const httplib::Request& req, std::initializer_list<const char*> types) {
    std::string ct = req.get_header_value("Content-Type");
    ct = ct.substr(0, ct.find(';'));
    ct.erase(std::remove(ct.begin(), ct.end(), ' '), ct.end());
    std::transform(ct.begin(), ct.end(), ct.begin(), [](unsigned char c) { return std::tolower(c); });
    for (const char* t : types) {
        const std::string want = t;
        if (want.back() == '*' ? ct.rfind(want.substr(0, want.size() - 1), 0) == 0 : ct == want)
            return true;
    }
    return false;
}

/// Deepest nesting of arrays and objects any request body may have (the deepest valid body, a
/// batch frame's pose joint, nests 7). nlohmann::json copies values recursively, so a body nested
/// a hundred thousand levels deep overflowed a handler thread's stack (a crash) once parsed.
constexpr int kMaxJsonDepth = 64;

/// True when the JSON text opens more than `limit` arrays/objects at once (strings skipped). Does
/// not validate: malformed text is left to the parser.
bool nestedDeeperThan(const std::string& text, int limit) {
    int depth = 0;
    bool inString = false, escaped = false;
    for (const char c : text) {
        if (inString) {
            if (escaped) escaped = false;
            else if (c == '\\') escaped = true;
            else if (c == '"') inString = false;
        } else if (c == '"') {
            inString = true;
        } else if (c == '[' || c == '{') {
            if (++depth > limit) return true;
        } else if (c == ']' || c == '}') {
            --depth;
        }
    }
    return false;
}

/// Parses a JSON body; false (and the answer sent) when the type or syntax is wrong.
bool jsonBody(const httplib::Request& req, httplib::Response& res, json& out) {
    if (!hasContentType(req, {"application/json"})) {
        sendError(res, 415, "unsupported", "dermis-server: body: expected Content-Type application/json", "body");
        return false;
    }
    if (nestedDeeperThan(req.body, kMaxJsonDepth)) {
        sendError(res, 400, "parse_error",
                  "dermis-server: body: JSON nested deeper than " + std::to_string(kMaxJsonDepth) + " levels",
                  "body");
        return false;
    }
    out = json::parse(req.body, nullptr, false);
    if (out.is_discarded()) {
        sendError(res, 400, "parse_error", "dermis-server: body: malformed JSON", "body");
        return false;
    }
    return true;
}

std::vector<std::uint8_t> bytesOf(const std::string& s) { return {s.begin(), s.end()}; }

/// Query parameter helpers: false (and a 422 sent) when present but malformed.
bool intParam(const httplib::Request& req, httplib::Response& res, const char* name,
              std::optional<int>& out) {
    if (!req.has_param(name)) return true;
    const std::string v = req.get_param_value(name);
    char* end = nullptr;
    errno = 0;
    const long n = std::strtol(v.c_str(), &end, 10);
    if (v.empty() || *end != '\0' || errno == ERANGE || n < -1000000000L || n > 1000000000L) {
        sendError(res, 422, "invalid_argument", std::string("dermis-server: ") + name + ": not an integer: \"" + v + "\"", name);
        return false;
    }
    out = static_cast<int>(n);
    return true;
}

bool numberParam(const httplib::Request& req, httplib::Response& res, const char* name,
                 std::optional<double>& out) {
    if (!req.has_param(name)) return true;
    const std::string v = req.get_param_value(name);
    char* end = nullptr;
    const double d = std::strtod(v.c_str(), &end);
    if (v.empty() || *end != '\0' || !std::isfinite(d)) {
        sendError(res, 422, "invalid_argument", std::string("dermis-server: ") + name + ": not a finite number: \"" + v + "\"", name);
        return false;
    }
    out = d;
    return true;
}

void sendImage(httplib::Response& res, EncodedImage&& img) {
    res.status = 200;
    if (!img.backend.empty()) res.set_header("X-Dermis-Backend", img.backend);
    res.body.assign(img.bytes.begin(), img.bytes.end());
    res.set_header("Content-Type", img.contentType);
}

bool constantTimeEquals(const std::string& a, const std::string& b) {
    unsigned char diff = a.size() == b.size() ? 0 : 1;
    for (std::size_t i = 0; i < a.size(); ++i)
        diff |= static_cast<unsigned char>(a[i] ^ b[i % std::max<std::size_t>(1, b.size())]);
    return diff == 0;
}

} // namespace

const std::vector<Route>& Api::routes() {
    static const std::vector<Route> r = {
        {"GET", "/health"},
        {"GET", "/info"},
        {"GET", "/openapi.yaml"},
        {"GET", "/models"},
        {"POST", "/models"},
        {"GET", "/models/{id}"},
        {"DELETE", "/models/{id}"},
        {"GET", "/models/{id}/uv-layout"},
        {"GET", "/patterns"},
        {"POST", "/patterns"},
        {"GET", "/patterns/{id}/image"},
        {"DELETE", "/patterns/{id}"},
        {"GET", "/scenes"},
        {"POST", "/scenes"},
        {"GET", "/scenes/{id}"},
        {"PUT", "/scenes/{id}"},
        {"DELETE", "/scenes/{id}"},
        {"POST", "/scenes/{id}/placements"},
        {"PUT", "/scenes/{id}/placements"},
        {"PATCH", "/scenes/{id}/placements/{pid}"},
        {"DELETE", "/scenes/{id}/placements/{pid}"},
        {"PUT", "/scenes/{id}/pose"},
        {"PATCH", "/scenes/{id}/pose"},
        {"GET", "/scenes/{id}/frame"},
        {"GET", "/scenes/{id}/heightmaps/{map}"},
        {"GET", "/scenes/{id}/events"},
        {"POST", "/render"},
    };
    return r;
}

namespace {

/// The methods served for `path` (a request path under /api/v1), comma-separated; "" when the path
/// is no route at all. Path parameters match what the routes accept.
std::string allowedMethods(const std::string& path) {
    if (path.rfind(kPrefix, 0) != 0) return "";
    const std::string rest = path.substr(kPrefix.size());
    static const std::vector<std::pair<std::regex, std::string>> templates = [] {
        std::vector<std::pair<std::regex, std::string>> out;
        for (const Route& r : Api::routes()) {
            std::string re;
            for (std::size_t i = 0; i < r.path.size(); ++i) {
                if (r.path[i] == '{') { // a path parameter
                    re += "[A-Za-z0-9_:.-]+";
                    i = r.path.find('}', i);
                } else {
                    if (r.path[i] == '.') re += '\\';
                    re += r.path[i];
                }
            }
            out.emplace_back(std::regex(re), r.method);
        }
        return out;
    }();
    std::string allow;
    for (const auto& [re, method] : templates)
        if (std::regex_match(rest, re) && allow.find(method) == std::string::npos)
            allow += (allow.empty() ? "" : ", ") + method;
    return allow;
}

} // namespace

struct Api::Impl {
    Service& svc;
    ApiOptions opt;
    httplib::Server server;
    std::atomic<bool> stopping{false};
    /// Open event streams. Each holds an HTTP worker thread for as long as it is open, so at most
    /// half the workers may stream; more are refused with 503 (otherwise a few dozen open editor
    /// tabs, or one client, would leave no thread to answer anything else: a hang).
    std::atomic<int> streams{0};
    int maxStreams() const { return std::max(1, opt.threads / 2); }

    Impl(Service& s, ApiOptions o) : svc(s), opt(std::move(o)) {}
    void install();
};

void Api::Impl::install() {
    httplib::Server& s = server;
    const int threads = opt.threads;
    s.new_task_queue = [threads] { return new httplib::ThreadPool(static_cast<std::size_t>(threads)); };
    s.set_tcp_nodelay(true);
    s.set_payload_max_length(svc.limits().maxUploadBytes);
    s.set_read_timeout(svc.limits().requestTimeoutSeconds, 0);
    s.set_write_timeout(svc.limits().requestTimeoutSeconds, 0);
    s.set_keep_alive_max_count(1000);

    // Authentication: every route but /health needs the bearer token when one is set.
    s.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
        if (opt.token.empty() || req.path == kPrefix + "/health")
            return httplib::Server::HandlerResponse::Unhandled;
        if (req.path.rfind(kPrefix, 0) != 0) return httplib::Server::HandlerResponse::Unhandled;
        const std::string auth = req.get_header_value("Authorization");
        if (auth.rfind("Bearer ", 0) != 0 || !constantTimeEquals(auth.substr(7), opt.token)) {
            res.set_header("WWW-Authenticate", "Bearer");
            sendError(res, 401, "unauthorized", "dermis-server: a valid bearer token is required",
                      "Authorization");
            return httplib::Server::HandlerResponse::Handled;
        }
        return httplib::Server::HandlerResponse::Unhandled;
    });
    // Statuses httplib produces itself (404 no route, 413 payload, 400 bad request) get JSON too.
    // A known path asked with a method it does not serve is 405 with Allow, not "no such route".
    s.set_error_handler([](const httplib::Request& req, httplib::Response& res) {
        if (!res.body.empty()) return;
        if (res.status == 404) {
            const std::string allow = allowedMethods(req.path);
            if (!allow.empty()) {
                res.set_header("Allow", allow);
                sendError(res, 405, "method_not_allowed",
                          "dermis-server: " + req.method + " " + req.path + ": method not allowed (allowed: " +
                              allow + ")",
                          "");
                return;
            }
        }
        const std::string code = res.status == 404   ? "not_found"
                                 : res.status == 413 ? "too_large"
                                 : res.status == 405 ? "method_not_allowed"
                                                     : "bad_request";
        const int status = res.status;
        sendError(res, status, code,
                  "dermis-server: " + req.method + " " + req.path + ": " +
                      (status == 404 ? "no such route" : status == 413 ? "body too large" : "bad request"),
                  status == 413 ? "body" : "");
    });
    s.set_exception_handler([](const httplib::Request&, httplib::Response& res, std::exception_ptr ep) {
        std::string what = "unexpected failure";
        try {
            if (ep) std::rethrow_exception(ep);
        } catch (const std::exception& e) {
            what = e.what();
        } catch (...) {
        }
        sendError(res, 500, "internal", "dermis-server: " + what, "");
    });

    const std::string P = kPrefix;
    const std::string ID = "([A-Za-z0-9_:.-]+)";

    s.Get(P + "/health", [](const httplib::Request&, httplib::Response& res) {
        sendJson(res, 200, {{"status", "ok"}});
    });
    s.Get(P + "/info", [this](const httplib::Request&, httplib::Response& res) { sendJson(res, 200, svc.info()); });
    s.Get(P + "/openapi.yaml", [](const httplib::Request&, httplib::Response& res) {
        res.set_content(std::string(openapiYaml()), "application/yaml");
    });

    // --- models
    s.Get(P + "/models", [this](const httplib::Request&, httplib::Response& res) { sendJson(res, 200, svc.listModels()); });
    s.Post(P + "/models", [this](const httplib::Request& req, httplib::Response& res) {
        if (req.is_multipart_form_data()) {
            // A .gltf and its external files: part "gltf" (or the part whose file name ends in
            // .gltf) and one part per buffer/image, named by its file name (the URI in the .gltf).
            std::vector<UploadFile> files;
            std::string gltfName;
            for (const auto& [field, part] : req.files) {
                const std::string name = part.filename.empty() ? field : part.filename;
                files.push_back({name, bytesOf(part.content)});
                const bool isGltf = name.size() > 5 && name.compare(name.size() - 5, 5, ".gltf") == 0;
                if (field == "gltf" || (gltfName.empty() && isGltf)) gltfName = name;
            }
            auto r = svc.addModelFiles(files, gltfName, req.get_param_value("name"));
            if (!r) return sendError(res, r.error());
            return sendJson(res, 201, *r);
        }
        if (!hasContentType(req, {"model/gltf-binary", "application/octet-stream"}))
            return sendError(res, 415, "unsupported",
                             "dermis-server: body: expected Content-Type model/gltf-binary, or "
                             "multipart/form-data with a .gltf and its files", "body");
        auto r = svc.addModel(bytesOf(req.body), req.get_param_value("name"));
        if (!r) {
            Error e = r.error();
            if (e.field.empty() && e.code == ErrorCode::Parse) e.field = "body"; // undecodable bytes
            return sendError(res, e);
        }
        sendJson(res, 201, *r);
    });
    s.Get(P + "/models/" + ID, [this](const httplib::Request& req, httplib::Response& res) {
        auto r = svc.getModel(req.matches[1]);
        if (!r) return sendError(res, r.error());
        sendJson(res, 200, *r);
    });
    s.Delete(P + "/models/" + ID, [this](const httplib::Request& req, httplib::Response& res) {
        auto r = svc.deleteModel(req.matches[1]);
        if (!r) return sendError(res, r.error());
        res.status = 204;
    });
    s.Get(P + "/models/" + ID + "/uv-layout", [this](const httplib::Request& req, httplib::Response& res) {
        const std::string format = req.has_param("format") ? req.get_param_value("format") : "json";
        if (format == "json") {
            auto r = svc.uvLayout(req.matches[1]);
            if (!r) return sendError(res, r.error());
            return sendJson(res, 200, *r);
        }
        if (format != "png") return sendError(res, 422, "invalid_argument", "dermis-server: format: must be png or json", "format");
        std::optional<int> size;
        if (!intParam(req, res, "size", size)) return;
        auto r = svc.uvLayoutPng(req.matches[1], size.value_or(1024));
        if (!r) return sendError(res, r.error());
        sendImage(res, std::move(*r));
    });

    // --- patterns
    s.Get(P + "/patterns", [this](const httplib::Request&, httplib::Response& res) { sendJson(res, 200, svc.listPatterns()); });
    s.Post(P + "/patterns", [this](const httplib::Request& req, httplib::Response& res) {
        if (!hasContentType(req, {"image/*", "application/octet-stream"}))
            return sendError(res, 415, "unsupported", "dermis-server: body: expected an image Content-Type", "body");
        auto r = svc.addPattern(bytesOf(req.body), req.get_param_value("name"));
        if (!r) {
            Error e = r.error();
            if (e.code == ErrorCode::Parse) return sendError(res, 415, "unsupported", e.message, "body");
            return sendError(res, e);
        }
        sendJson(res, 201, *r);
    });
    s.Get(P + "/patterns/" + ID + "/image", [this](const httplib::Request& req, httplib::Response& res) {
        std::optional<int> size;
        if (!intParam(req, res, "size", size)) return;
        auto r = svc.patternImage(req.matches[1], size.value_or(256));
        if (!r) return sendError(res, r.error());
        sendImage(res, std::move(*r));
    });
    s.Delete(P + "/patterns/" + ID, [this](const httplib::Request& req, httplib::Response& res) {
        auto r = svc.deletePattern(req.matches[1]);
        if (!r) return sendError(res, r.error());
        res.status = 204;
    });

    // --- scenes
    s.Get(P + "/scenes", [this](const httplib::Request&, httplib::Response& res) { sendJson(res, 200, svc.listScenes()); });
    s.Post(P + "/scenes", [this](const httplib::Request& req, httplib::Response& res) {
        json body;
        if (!jsonBody(req, res, body)) return;
        auto r = svc.createScene(body);
        if (!r) return sendDocError(res, r.error());
        res.set_header("Location", kPrefix + "/scenes/" + (*r)["id"].get<std::string>());
        sendJson(res, 201, *r);
    });
    s.Get(P + "/scenes/" + ID, [this](const httplib::Request& req, httplib::Response& res) {
        auto r = svc.getScene(req.matches[1]);
        if (!r) return sendError(res, r.error());
        sendJson(res, 200, *r);
    });
    s.Put(P + "/scenes/" + ID, [this](const httplib::Request& req, httplib::Response& res) {
        json body;
        if (!jsonBody(req, res, body)) return;
        auto r = svc.replaceScene(req.matches[1], body);
        if (!r) return sendDocError(res, r.error());
        sendJson(res, 200, *r);
    });
    s.Delete(P + "/scenes/" + ID, [this](const httplib::Request& req, httplib::Response& res) {
        auto r = svc.deleteScene(req.matches[1]);
        if (!r) return sendError(res, r.error());
        res.status = 204;
    });
    s.Post(P + "/scenes/" + ID + "/placements", [this](const httplib::Request& req, httplib::Response& res) {
        json body;
        if (!jsonBody(req, res, body)) return;
        auto r = svc.addPlacement(req.matches[1], body);
        if (!r) return sendDocError(res, r.error());
        sendJson(res, 201, *r);
    });
    s.Put(P + "/scenes/" + ID + "/placements", [this](const httplib::Request& req, httplib::Response& res) {
        json body;
        if (!jsonBody(req, res, body)) return;
        auto r = svc.reorderPlacements(req.matches[1], body);
        if (!r) return sendDocError(res, r.error());
        sendJson(res, 200, *r);
    });
    s.Patch(P + "/scenes/" + ID + "/placements/" + ID, [this](const httplib::Request& req, httplib::Response& res) {
        json body;
        if (!jsonBody(req, res, body)) return;
        auto r = svc.patchPlacement(req.matches[1], req.matches[2], body);
        if (!r) return sendDocError(res, r.error());
        sendJson(res, 200, *r);
    });
    s.Delete(P + "/scenes/" + ID + "/placements/" + ID, [this](const httplib::Request& req, httplib::Response& res) {
        auto r = svc.deletePlacement(req.matches[1], req.matches[2]);
        if (!r) return sendDocError(res, r.error());
        sendJson(res, 200, *r);
    });
    s.Put(P + "/scenes/" + ID + "/pose", [this](const httplib::Request& req, httplib::Response& res) {
        json body;
        if (!jsonBody(req, res, body)) return;
        auto r = svc.putPose(req.matches[1], body);
        if (!r) return sendDocError(res, r.error());
        sendJson(res, 200, *r);
    });
    s.Patch(P + "/scenes/" + ID + "/pose", [this](const httplib::Request& req, httplib::Response& res) {
        json body;
        if (!jsonBody(req, res, body)) return;
        auto r = svc.patchPose(req.matches[1], body);
        if (!r) return sendDocError(res, r.error());
        sendJson(res, 200, *r);
    });
    s.Get(P + "/scenes/" + ID + "/frame", [this](const httplib::Request& req, httplib::Response& res) {
        FrameParams p;
        if (req.has_param("format")) p.format = req.get_param_value("format");
        if (!intParam(req, res, "width", p.width) || !intParam(req, res, "height", p.height) ||
            !intParam(req, res, "msaa", p.msaa) || !numberParam(req, res, "yaw", p.yaw) ||
            !numberParam(req, res, "pitch", p.pitch) || !numberParam(req, res, "distance", p.distance) ||
            !numberParam(req, res, "time", p.time))
            return;
        auto r = svc.frame(req.matches[1], p);
        if (!r) return sendError(res, r.error());
        sendImage(res, std::move(*r));
    });
    s.Get(P + "/scenes/" + ID + "/heightmaps/" + ID, [this](const httplib::Request& req, httplib::Response& res) {
        const std::string map = req.matches[2];
        const std::string format = req.has_param("format") ? req.get_param_value("format")
                                                           : (map == "normal" ? "png" : "png16");
        auto r = svc.heightmap(req.matches[1], map, format);
        if (!r) return sendError(res, r.error());
        sendImage(res, std::move(*r));
    });
    s.Get(P + "/scenes/" + ID + "/events", [this](const httplib::Request& req, httplib::Response& res) {
        const std::string id = req.matches[1];
        if (streams.fetch_add(1) >= maxStreams()) {
            streams.fetch_sub(1);
            return sendError(res, 503, "unavailable",
                             "dermis-server: " + std::to_string(maxStreams()) +
                                 " event streams are open, the most this server keeps; retry later",
                             "");
        }
        auto sub = svc.subscribe(id);
        if (!sub) {
            streams.fetch_sub(1);
            return sendError(res, sub.error());
        }
        res.set_header("Cache-Control", "no-cache");
        auto subscription = *sub;
        res.set_chunked_content_provider(
            "text/event-stream",
            [this, subscription](std::size_t, httplib::DataSink& sink) {
                if (stopping) return false;
                auto e = subscription->next(1000);
                if (!e) {
                    if (subscription->closed()) {
                        sink.done();
                        return true;
                    }
                    static const std::string ping = ": ping\n\n";
                    return sink.write(ping.data(), ping.size());
                }
                return sink.write(e->data(), e->size());
            },
            [this, id, subscription](bool) { // runs once, when the response is destroyed
                svc.unsubscribe(id, subscription);
                streams.fetch_sub(1);
            });
    });

    // --- stateless batch: frames streamed as multipart/mixed parts as they finish
    s.Post(P + "/render", [this](const httplib::Request& req, httplib::Response& res) {
        json body;
        if (!jsonBody(req, res, body)) return;
        auto job = svc.batch(body);
        if (!job) return sendDocError(res, job.error());
        auto shared = std::make_shared<Service::BatchJob>(std::move(*job));
        const std::string boundary = "dermis-frame-boundary";
        res.set_header("X-Dermis-Frames", std::to_string(shared->frames));
        res.set_chunked_content_provider(
            "multipart/mixed; boundary=" + boundary,
            [shared, boundary, next = std::make_shared<std::size_t>(0)](std::size_t, httplib::DataSink& sink) {
                const std::size_t k = (*next)++;
                if (k >= shared->frames) {
                    const std::string end = "--" + boundary + "--\r\n";
                    sink.write(end.data(), end.size());
                    sink.done();
                    return true;
                }
                auto img = shared->render(k);
                std::string part = "--" + boundary + "\r\n";
                if (!img) {
                    const json err = {{"error", {{"code", errorCodeName(img.error().code)},
                                                 {"message", img.error().message},
                                                 {"field", img.error().field}}}};
                    part += "Content-Type: application/json\r\nX-Dermis-Frame: " + std::to_string(k) +
                            "\r\n\r\n" + err.dump() + "\r\n--" + boundary + "--\r\n";
                    sink.write(part.data(), part.size());
                    sink.done();
                    return true;
                }
                part += "Content-Type: " + img->contentType + "\r\nX-Dermis-Frame: " + std::to_string(k) +
                        "\r\nX-Dermis-Backend: " + img->backend + "\r\nContent-Length: " +
                        std::to_string(img->bytes.size()) + "\r\n\r\n";
                part.append(img->bytes.begin(), img->bytes.end());
                part += "\r\n";
                return sink.write(part.data(), part.size());
            });
    });

    if (!opt.webDir.empty() && std::filesystem::is_directory(opt.webDir)) s.set_mount_point("/", opt.webDir);
}

Api::Api(Service& service, ApiOptions options) : impl_(std::make_unique<Impl>(service, std::move(options))) {
    impl_->install();
}

Api::~Api() { stop(); }

Result<int> Api::bind() {
    int port = impl_->opt.port;
    if (port == 0) {
        port = impl_->server.bind_to_any_port(impl_->opt.bind);
        if (port <= 0)
            return makeError(ErrorCode::Io, "dermis::Api::bind", "--bind", "cannot bind " + impl_->opt.bind);
        return port;
    }
    if (!impl_->server.bind_to_port(impl_->opt.bind, port))
        return makeError(ErrorCode::Io, "dermis::Api::bind", "--port",
                         "cannot bind " + impl_->opt.bind + ":" + std::to_string(port));
    return port;
}

void Api::run() { impl_->server.listen_after_bind(); }

void Api::stop() {
    if (!impl_) return;
    impl_->stopping = true;
    impl_->svc.closeSubscriptions();
    impl_->server.stop();
}

} // namespace dermis
