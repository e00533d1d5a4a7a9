// Dermis HTTP shell — the plumbing every route family shares: the error mapping, body and query
// parsing, the route table, authentication (bearer token or session cookie), registration with
// httplib and Api's own methods. The routes themselves live in api_<family>.cpp.
#include "api_internal.hpp"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>

namespace dermis {

namespace api_detail {

// --- answers -------------------------------------------------------------------------------------

int statusOf(ErrorCode code) {
    switch (code) {
    case ErrorCode::InvalidArgument:
        return 422;
    case ErrorCode::NotFound:
        return 404;
    case ErrorCode::Parse:
        return 400;
    case ErrorCode::Io:
        return 500;
    case ErrorCode::Unsupported:
        return 415;
    case ErrorCode::Conflict:
        return 409;
    case ErrorCode::StaleRevision:
        return 412;
    case ErrorCode::TooLarge:
        return 413;
    case ErrorCode::Unavailable:
        return 503;
    case ErrorCode::Internal:
        return 500;
    case ErrorCode::MissingContent:
        return 409;
    case ErrorCode::Gone:
        return 410;
    }
    return 500;
}

void sendJson(Res& res, int status, const json& body) {
    res.status = status;
    res.set_content(body.dump(), "application/json");
}

void sendError(Res& res, int status, const std::string& code, const std::string& message,
               const std::string& field) {
    if (status == 503 && !res.has_header("Retry-After")) res.set_header("Retry-After", "1"); // one: a route may have set its own
    sendJson(res, status, {{"error", {{"code", code}, {"message", message}, {"field", field}}}});
}

void tooManyFailures(Res& res, int wait, const std::string& field) {
    res.set_header("Retry-After", std::to_string(wait));
    sendError(res, 429, "too_many_requests",
              "dermis-server: too many failed sign-ins from this address: try again in " + std::to_string(wait) + " s",
              field);
}

void sendError(Res& res, const Error& e) {
    if (e.currentRevision) { // 412: the body also says which revision is current
        sendJson(res, statusOf(e.code),
                 {{"error", {{"code", errorCodeName(e.code)}, {"message", e.message}, {"field", e.field}}},
                  {"revision", *e.currentRevision}});
        return;
    }
    if (e.code == ErrorCode::MissingContent) { // 409: the body lists what to send
        sendJson(res, 409,
                 {{"error", {{"code", errorCodeName(e.code)}, {"message", e.message}, {"field", e.field}}},
                  {"missing", e.missing}});
        return;
    }
    sendError(res, statusOf(e.code), errorCodeName(e.code), e.message, e.field);
}

void sendDocError(Res& res, const Error& e) {
    if (e.code == ErrorCode::Unsupported) {
        sendError(res, 422, errorCodeName(e.code), e.message, e.field);
        return;
    }
    sendError(res, e);
}

void sendImage(Res& res, EncodedImage&& img) {
    res.status = 200;
    if (!img.backend.empty()) res.set_header("X-Dermis-Backend", img.backend);
    if (!img.antiAliasing.empty()) res.set_header("X-Dermis-AA", img.antiAliasing);
    if (img.changedPixels >= 0) res.set_header("X-Dermis-Changed-Pixels", std::to_string(img.changedPixels));
    res.body.assign(img.bytes.begin(), img.bytes.end());
    res.set_header("Content-Type", img.contentType);
}

// --- requests ------------------------------------------------------------------------------------

bool hasContentType(const Req& req, std::initializer_list<const char*> types) {
    std::string ct = req.get_header_value("Content-Type");
    ct = ct.substr(0, ct.find(';'));
    ct.erase(std::remove(ct.begin(), ct.end(), ' '), ct.end());
    std::transform(ct.begin(), ct.end(), ct.begin(),
                   [](unsigned char c) { return std::tolower(c); });
    for (const char* t : types) {
        const std::string want = t;
        if (want.back() == '*' ? ct.rfind(want.substr(0, want.size() - 1), 0) == 0 : ct == want)
            return true;
    }
    return false;
}

std::string sceneEtag(std::uint64_t revision) {
    return "\"r" + std::to_string(revision) + "\"";
}

void setEtag(Res& res, const json& answer) {
    if (auto r = answer.find("revision"); r != answer.end() && r->is_number_unsigned())
        res.set_header("ETag", sceneEtag(r->get<std::uint64_t>()));
}

bool editContext(const Req& req, Res& res, EditContext& out) {
    if (req.has_header("If-Match")) {
        std::string v = req.get_header_value("If-Match");
        while (!v.empty() && (v.front() == ' ' || v.front() == '\t')) v.erase(v.begin());
        while (!v.empty() && (v.back() == ' ' || v.back() == '\t')) v.pop_back();
        if (v != "*") {
            std::uint64_t revision = 0;
            bool ok = v.size() >= 4 && v.size() <= 24 && v.compare(0, 2, "\"r") == 0 &&
                      v.back() == '"';
            for (std::size_t k = 2; ok && k + 1 < v.size(); ++k) {
                ok = std::isdigit(static_cast<unsigned char>(v[k])) && revision < 100000000000000000ull;
                revision = revision * 10 + static_cast<std::uint64_t>(v[k] - '0');
            }
            if (!ok) { // "r0" is well-formed: no scene is at revision 0, so it is a 412, not a 400
                sendError(res, 400, "parse_error",
                          "dermis::Api: If-Match: expected one strong ETag \"r<revision>\" as "
                          "the scene's ETag header gives it (or *), got " +
                              v.substr(0, 64),
                          "If-Match");
                return false;
            }
            out.ifMatch = revision;
        }
    }
    out.client = req.get_header_value("X-Dermis-Client");
    if (auto why = checkClientName(out.client); !why.empty()) {
        sendError(res, 400, "parse_error", "dermis::Api: X-Dermis-Client: " + why, "X-Dermis-Client");
        return false;
    }
    return true;
}

namespace {

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
            if (escaped)
                escaped = false;
            else if (c == '\\')
                escaped = true;
            else if (c == '"')
                inString = false;
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

} // namespace

bool jsonText(const std::string& text, const std::string& field, Res& res, json& out) {
    if (nestedDeeperThan(text, kMaxJsonDepth)) {
        sendError(res, 400, "parse_error",
                  "dermis-server: " + field + ": JSON nested deeper than " + std::to_string(kMaxJsonDepth) +
                      " levels",
                  field);
        return false;
    }
    out = json::parse(text, nullptr, false);
    if (out.is_discarded()) {
        sendError(res, 400, "parse_error", "dermis-server: " + field + ": malformed JSON", field);
        return false;
    }
    return true;
}

bool jsonBody(const Req& req, Res& res, json& out) {
    if (!hasContentType(req, {"application/json"})) {
        sendError(res, 415, "unsupported",
                  "dermis-server: body: expected Content-Type application/json", "body");
        return false;
    }
    return jsonText(req.body, "body", res, out);
}

std::vector<std::uint8_t> bytesOf(const std::string& s) {
    return {s.begin(), s.end()};
}

bool intParam(const Req& req, Res& res, const char* name, std::optional<int>& out) {
    if (!req.has_param(name)) return true;
    const std::string v = req.get_param_value(name);
    char* end = nullptr;
    errno = 0;
    const long n = std::strtol(v.c_str(), &end, 10);
    if (v.empty() || *end != '\0' || errno == ERANGE || n < -1000000000L || n > 1000000000L) {
        sendError(res, 422, "invalid_argument",
                  std::string("dermis-server: ") + name + ": not an integer: \"" + v + "\"", name);
        return false;
    }
    out = static_cast<int>(n);
    return true;
}

bool boolParam(const Req& req, Res& res, const char* name, std::optional<bool>& out) {
    if (!req.has_param(name)) return true;
    const std::string v = req.get_param_value(name);
    if (v == "true" || v == "1") out = true;
    else if (v == "false" || v == "0") out = false;
    else {
        sendError(res, 422, "invalid_argument",
                  std::string("dermis::Api: ") + name + ": must be true or false, not \"" + v + "\"", name);
        return false;
    }
    return true;
}

bool revisionParam(const Req& req, Res& res, const char* name, std::optional<std::uint64_t>& out) {
    if (!req.has_param(name)) return true;
    const auto n = parseRevisionNumber(req.get_param_value(name));
    if (!n) {
        sendError(res, 422, "invalid_argument",
                  std::string("dermis::Api: ") + name + ": must be a revision number >= 1", name);
        return false;
    }
    out = *n;
    return true;
}

bool numberParam(const Req& req, Res& res, const char* name, std::optional<double>& out) {
    if (!req.has_param(name)) return true;
    const std::string v = req.get_param_value(name);
    char* end = nullptr;
    const double d = std::strtod(v.c_str(), &end);
    if (v.empty() || *end != '\0' || !std::isfinite(d)) {
        sendError(res, 422, "invalid_argument",
                  std::string("dermis-server: ") + name + ": not a finite number: \"" + v + "\"",
                  name);
        return false;
    }
    out = d;
    return true;
}

bool constantTimeEquals(const std::string& a, const std::string& b) {
    unsigned char diff = a.size() == b.size() ? 0 : 1;
    for (std::size_t i = 0; i < a.size(); ++i)
        diff |= static_cast<unsigned char>(a[i] ^ b[i % std::max<std::size_t>(1, b.size())]);
    return diff == 0;
}

// --- the route table -----------------------------------------------------------------------------

void RouteTable::add(const std::string& method, const std::string& path, Handler handler,
                     Access access) {
    static const char* const kMethods[] = {"GET", "POST", "PUT", "PATCH", "DELETE"};
    if (std::find(std::begin(kMethods), std::end(kMethods), method) == std::end(kMethods))
        throw std::logic_error("dermis::RouteTable::add: " + method + " " + path +
                               ": unsupported method");
    for (const RouteDef& d : defs_)
        if (d.route.method == method && d.route.path == path)
            throw std::logic_error("dermis::RouteTable::add: " + method + " " + path +
                                   ": added twice");
    defs_.push_back({Route{method, path, access == Access::Open}, std::move(handler)});
}

const RouteTable& routeTable() {
    static const RouteTable table = [] {
        RouteTable t;
        installSystemRoutes(t);
        installSessionRoutes(t);
        installModelRoutes(t);
        installPatternRoutes(t);
        installEnvironmentRoutes(t);
        installSceneRoutes(t);
        installRenderRoutes(t);
        installInspectRoutes(t);
        installEventRoutes(t);
        return t;
    }();
    return table;
}

std::string pathRegex(const std::string& pathTemplate) {
    std::string re;
    for (std::size_t i = 0; i < pathTemplate.size(); ++i) {
        if (pathTemplate[i] == '{') { // a path parameter, up to its '}'
            re += "([A-Za-z0-9_:.-]+)";
            i = pathTemplate.find('}', i);
            if (i == std::string::npos) break;
        } else {
            if (pathTemplate[i] == '.') re += '\\';
            re += pathTemplate[i];
        }
    }
    return re;
}

} // namespace api_detail

using namespace api_detail;

const std::vector<Route>& Api::routes() {
    static const std::vector<Route> r = [] {
        std::vector<Route> out;
        for (const RouteDef& d : routeTable().defs())
            out.push_back(d.route);
        return out;
    }();
    return r;
}

// --- Api::Impl -----------------------------------------------------------------------------------

Api::Impl::Impl(Service& s, ApiOptions o)
    : svc(s), opt(std::move(o)),
      sessions(static_cast<std::size_t>(std::max(1, opt.maxSessions)),
               std::chrono::seconds(std::max(1, opt.sessionMaxAgeSeconds))) {}

std::string Api::Impl::allowedMethods(const std::string& path) const {
    std::string allow;
    for (const Matcher& m : matchers_)
        if (std::regex_match(path, m.re) && allow.find(m.def->route.method) == std::string::npos)
            allow += (allow.empty() ? "" : ", ") + m.def->route.method;
    return allow;
}

bool Api::Impl::isOpen(const std::string& method, const std::string& path) const {
    bool any = false, allOpen = true;
    for (const Matcher& m : matchers_) {
        if (!std::regex_match(path, m.re)) continue;
        if (m.def->route.method == method) return m.def->route.open;
        any = true;
        allOpen = allOpen && m.def->route.open;
    }
    return any && allOpen;
}

std::size_t Api::Impl::bodyLimitOf(const Req& req) const {
    const std::size_t upload = svc.limits().maxUploadBytes;
    // Uploads (patterns, models, environments), and batches that carry their content (multipart,
    // SPEC §7), at the upload limit.
    const bool isUpload = req.method == "POST" &&
                          (req.path == kPrefix + "/patterns" || req.path == kPrefix + "/models" ||
                           req.path == kPrefix + "/environments" ||
                           (req.path == kPrefix + "/render" && hasContentType(req, {"multipart/form-data"})));
    return isUpload ? upload : std::min(upload, opt.maxJsonBytes);
}

bool Api::Impl::authorized(const Req& req) const {
    const std::string auth = req.get_header_value("Authorization");
    if (auth.rfind("Bearer ", 0) == 0 && constantTimeEquals(auth.substr(7), opt.token)) return true;
    for (const std::string& id : cookieValues(req, kSessionCookie))
        if (sessions.valid(id)) return true;
    return false;
}

void Api::Impl::install() {
    GuardedServer& s = server;
    s.limits.headSeconds = std::max(1, opt.headSeconds);
    s.limits.stallSeconds = svc.limits().requestTimeoutSeconds;
    s.limits.maxConnections = std::max(1, opt.maxConnections);
    s.limits.maxPerAddress = std::max(1, opt.maxConnectionsPerAddress);
    // Every body is limited while it streams (chunked ones too): uploads at the upload limit,
    // everything else at the JSON limit. The budget leaves room for chunk framing; the exact
    // size of a Content-Length body is checked before it is read (pre-routing, below).
    s.bodyLimit = [this](const Req& req) {
        const std::size_t limit = bodyLimitOf(req);
        return limit + limit / 16 + 4096;
    };
    s.set_tcp_nodelay(true);
    s.set_payload_max_length(svc.limits().maxUploadBytes);
    s.set_read_timeout(svc.limits().requestTimeoutSeconds, 0);
    s.set_write_timeout(svc.limits().requestTimeoutSeconds, 0);
    s.set_keep_alive_max_count(1000);

    // Authentication: with a token set, every route but the open ones needs the bearer token or
    // a live session's cookie. Unknown paths under the prefix need them too (no probing).
    s.set_pre_routing_handler([this](const Req& req, Res& res) {
        // A Content-Length past the route's limit is answered before any of the body is read.
        if (req.has_header("Content-Length")) {
            const std::string v = req.get_header_value("Content-Length");
            char* end = nullptr;
            errno = 0;
            const unsigned long long n = std::strtoull(v.c_str(), &end, 10);
            const std::size_t limit = bodyLimitOf(req);
            if (!v.empty() && *end == '\0' && (errno == ERANGE || n > limit)) {
                GuardedServer::closeAfterAnswer(req);
                sendError(res, 413, "too_large",
                          "dermis-server: body: Content-Length " + v + " is over the limit of " +
                              std::to_string(limit) + " bytes for " + req.method + " " + req.path,
                          "body");
                return httplib::Server::HandlerResponse::Handled;
            }
        }
        if (opt.token.empty() || req.path.rfind(kPrefix, 0) != 0)
            return httplib::Server::HandlerResponse::Unhandled;
        if (isOpen(req.method, req.path.substr(kPrefix.size())))
            return httplib::Server::HandlerResponse::Unhandled;
        // Credentials are guesses until proven: an address that failed too often waits first,
        // and inside its wait they are not even looked at (AuthThrottle).
        const bool credentialed = req.has_header("Authorization") || !cookieValues(req, kSessionCookie).empty();
        if (credentialed) {
            if (const int wait = authThrottle.waitSeconds(req.remote_addr); wait > 0) {
                tooManyFailures(res, wait, "Authorization");
                return httplib::Server::HandlerResponse::Handled;
            }
        }
        if (authorized(req)) return httplib::Server::HandlerResponse::Unhandled;
        if (credentialed) authThrottle.failed(req.remote_addr);
        res.set_header("WWW-Authenticate", "Bearer");
        sendError(res, 401, "unauthorized",
                  "dermis-server: a valid bearer token (or a session cookie from POST " + kPrefix +
                      "/session) is required",
                  "Authorization");
        return httplib::Server::HandlerResponse::Handled;
    });
    // Statuses httplib produces itself (404 no route, 413 payload, 400 bad request) get JSON too.
    // A known path asked with a method it does not serve is 405 with Allow, not "no such route".
    s.set_error_handler([this](const Req& req, Res& res) {
        // Every error answered before its request's body was read to the end (401 in
        // pre-routing, a multipart body httplib gave up on, …) closes the connection: the rest of
        // the body must never run as the next request (request smuggling).
        if (GuardedServer::bodyUnread(req)) GuardedServer::closeAfterAnswer(req);
        if (!res.body.empty()) return;
        if (GuardedServer::bodyOverLimit()) { // a streamed body went past its limit: 413, close
            GuardedServer::closeAfterAnswer(req);
            res.status = 413;
        }
        if (res.status == 413) GuardedServer::closeAfterAnswer(req);
        if (res.status == 404 && req.path.rfind(kPrefix, 0) == 0) {
            const std::string allow = allowedMethods(req.path.substr(kPrefix.size()));
            if (!allow.empty()) {
                res.set_header("Allow", allow);
                sendError(res, 405, "method_not_allowed",
                          "dermis-server: " + req.method + " " + req.path +
                              ": method not allowed (allowed: " + allow + ")",
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
                      (status == 404   ? "no such route"
                       : status == 413 ? "body over the limit of " +
                                                 std::to_string(bodyLimitOf(req)) + " bytes"
                                       : "bad request"),
                  status == 413 ? "body" : "");
    });
    s.set_exception_handler([](const Req&, Res& res, std::exception_ptr ep) {
        std::string what = "unexpected failure";
        try {
            if (ep) std::rethrow_exception(ep);
        } catch (const std::exception& e) {
            what = e.what();
        } catch (...) {
        }
        sendError(res, 500, "internal", "dermis-server: " + what, "");
    });

    // Every route of the table, its regex derived from its template.
    for (const RouteDef& d : routeTable().defs()) {
        const std::string re = pathRegex(d.route.path);
        matchers_.push_back({std::regex(re), &d});
        const std::string pattern = kPrefix + re;
        httplib::Server::Handler h = [this, &d](const Req& req, Res& res) {
            d.handler(*this, req, res);
        };
        const std::string& m = d.route.method;
        if (m == "GET")
            s.Get(pattern, std::move(h));
        else if (m == "POST")
            s.Post(pattern, std::move(h));
        else if (m == "PUT")
            s.Put(pattern, std::move(h));
        else if (m == "PATCH")
            s.Patch(pattern, std::move(h));
        else if (m == "DELETE")
            s.Delete(pattern, std::move(h));
    }

    if (!opt.webDir.empty() && std::filesystem::is_directory(opt.webDir))
        s.set_mount_point("/", opt.webDir);
}

// --- Api -----------------------------------------------------------------------------------------

Api::Api(Service& service, ApiOptions options)
    : impl_(std::make_unique<Impl>(service, std::move(options))) {
    impl_->install();
}

Api::~Api() {
    stop();
}

Result<int> Api::bind() {
    int port = impl_->opt.port;
    if (port == 0) {
        port = impl_->server.bind_to_any_port(impl_->opt.bind);
        if (port <= 0)
            return makeError(ErrorCode::Io, "dermis::Api::bind", "--bind",
                             "cannot bind " + impl_->opt.bind);
        impl_->server.widenBacklog();
        return port;
    }
    if (!impl_->server.bind_to_port(impl_->opt.bind, port))
        return makeError(ErrorCode::Io, "dermis::Api::bind", "--port",
                         "cannot bind " + impl_->opt.bind + ":" + std::to_string(port));
    impl_->server.widenBacklog();
    return port;
}

void Api::run() {
    impl_->server.listen_after_bind();
}

void Api::stop() {
    if (!impl_) return;
    impl_->stopping = true;
    impl_->svc.closeSubscriptions();
    impl_->server.stop();
    impl_->server.closeAll(); // slow clients are not waited for
}

} // namespace dermis
