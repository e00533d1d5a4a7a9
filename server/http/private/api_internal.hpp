// Dermis HTTP shell — private to server/http: what the route families share.
//
// Layout: api.cpp holds the plumbing (the error mapping, body and query parsing, the route table,
// authentication, registration with httplib, Api's methods); each route family adds its routes
// to the one RouteTable from its own file:
//   api_system.cpp   /health, /info, /openapi.yaml
//   api_session.cpp  /session (browser sign-in) and the SessionStore
//   api_models.cpp   /models…            api_patterns.cpp  /patterns…
//   api_scenes.cpp   /scenes, placements, pose, history, presence
//   api_inspect.cpp  pick, drivers, probe, activation, lint, a placement's outline
//   api_renders.cpp  frames, frame diffs, height maps, sweeps, focus, turntable, the batch (/render)
//   api_events.cpp   /scenes/{id}/events (the service's typed events framed as server-sent events)
//   api_connections.cpp  connection limits, request heads and bodies, lingering close
// Registration with httplib, Api::routes() (checked against openapi.yaml by RoutesHttpTest), the
// 405 Allow lists and the open-route check of authentication all read that table, so a route
// exists in all of them or in none.
//
// Not a public header: it includes httplib, which only server/http links.
#pragma once

#include "http/api.hpp"

#include <httplib.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <initializer_list>
#include <map>
#include <mutex>
#include <optional>
#include <regex>
#include <string>
#include <vector>

namespace dermis {

namespace api_detail {

using json = nlohmann::json;
using Req = httplib::Request;
using Res = httplib::Response;

/// Every route lives under this prefix.
inline const std::string kPrefix = "/api/v1";

// --- answers (api.cpp) ---------------------------------------------------------------------------

/// The one mapping from error codes to HTTP statuses.
int statusOf(ErrorCode code);
void sendJson(Res& res, int status, const json& body);
/// {"error": {"code", "message", "field"}} with `status` (503 also gets Retry-After: 1).
void sendError(Res& res, int status, const std::string& code, const std::string& message,
               const std::string& field);
void sendError(Res& res, const Error& e);
/// Scene documents: an unsupported "format" version is an invalid value (422), not a media type.
void sendDocError(Res& res, const Error& e);
/// A 200 answer with the image's bytes, Content-Type and X-Dermis-Backend.
void sendImage(Res& res, EncodedImage&& img);

// --- requests (api.cpp) --------------------------------------------------------------------------

/// True when the Content-Type (parameters ignored, case-insensitive) is one of `types`; "image/*"
/// matches by prefix.
bool hasContentType(const Req& req, std::initializer_list<const char*> types);
/// Parses a JSON body; false (and the answer sent: 415 wrong type, 400 malformed or nested deeper
/// than 64 levels) when it cannot.
bool jsonBody(const Req& req, Res& res, json& out);
/// Same for JSON text that is not the body (a multipart part): errors name `field`.
bool jsonText(const std::string& text, const std::string& field, Res& res, json& out);
std::vector<std::uint8_t> bytesOf(const std::string& s);
/// Query parameters: true when absent (out untouched) or well-formed; false (and a 422 sent) when
/// present but malformed.
bool intParam(const Req& req, Res& res, const char* name, std::optional<int>& out);
bool numberParam(const Req& req, Res& res, const char* name, std::optional<double>& out);
/// "true" / "false" (also "1" / "0").
bool boolParam(const Req& req, Res& res, const char* name, std::optional<bool>& out);
/// A revision number ≥ 1 (service parseRevisionNumber: the one parse of a revision number).
bool revisionParam(const Req& req, Res& res, const char* name, std::optional<std::uint64_t>& out);
/// The camera's `target=x,y,z` (three finite numbers, comma-separated; api_renders.cpp).
/// False (and the 422 sent, field "target") when malformed.
bool targetParam(const Req& req, Res& res, std::optional<std::array<double, 3>>& out);
/// The edit context of a request (SPEC §6 Concurrency): `If-Match: "r<N>"` (or `*`: any) and
/// `X-Dermis-Client`. False (and a 400 sent, field "If-Match" / "X-Dermis-Client") for a weak,
/// malformed or multiple ETag or a client name over 64 characters or not printable ASCII.
bool editContext(const Req& req, Res& res, EditContext& out);
/// `"r<revision>"`, the ETag of a scene at that revision.
std::string sceneEtag(std::uint64_t revision);
/// Sets the ETag header from an answer's "revision" (when it has one).
void setEtag(Res& res, const json& answer);
/// Compares without an early exit (the time depends only on the lengths).
bool constantTimeEquals(const std::string& a, const std::string& b);

// --- the route table (api.cpp) -------------------------------------------------------------------

/// A route's handler. Path parameters are req.matches[1], [2]… in template order.
using Handler = std::function<void(Api::Impl& api, const Req& req, Res& res)>;

enum class Access {
    Credentials, ///< the bearer token or a session cookie, when the server has a token
    Open,        ///< anyone (OpenAPI `security: []`)
};

struct RouteDef {
    Route route; ///< method, OpenAPI path template, open
    Handler handler;
};

/// Routes in the order their families add them. Not thread-safe while being built; routeTable()
/// builds the one table once and only reads it afterwards.
class RouteTable {
public:
    /// Adds a route that needs credentials. `method` is GET, POST, PUT, PATCH or DELETE; `path` an
    /// OpenAPI template under the prefix ("/scenes/{id}"). Throws std::logic_error on another
    /// method or a duplicate (a programming error, found by every test).
    void add(const std::string& method, const std::string& path, Handler handler) {
        add(method, path, std::move(handler), Access::Credentials);
    }
    /// Adds a route anyone may call (OpenAPI `security: []`).
    void addOpen(const std::string& method, const std::string& path, Handler handler) {
        add(method, path, std::move(handler), Access::Open);
    }
    const std::vector<RouteDef>& defs() const { return defs_; }

private:
    void add(const std::string& method, const std::string& path, Handler handler, Access access);
    std::vector<RouteDef> defs_;
};

/// The table of every route (built on first use from the install functions below).
const RouteTable& routeTable();

/// The regular expression of a path template: each "{name}" becomes one capture group of
/// [A-Za-z0-9_:.-]+ (no '/', so never a path trick), '.' is literal. Without the prefix.
std::string pathRegex(const std::string& pathTemplate);

// One install function per route family: each adds its routes to the table.
void installSystemRoutes(RouteTable& table);
void installSessionRoutes(RouteTable& table);
void installModelRoutes(RouteTable& table);
void installPatternRoutes(RouteTable& table);
void installEnvironmentRoutes(RouteTable& table);
void installSceneRoutes(RouteTable& table);
void installRenderRoutes(RouteTable& table);
void installInspectRoutes(RouteTable& table);
void installEventRoutes(RouteTable& table);

// --- browser sessions (api_session.cpp) ----------------------------------------------------------

/// The cookie that carries a session id.
inline const std::string kSessionCookie = "dermis_session";

/// Browser sessions opened by POST /session: random 128-bit ids (32 lower-case hex digits, from
/// getrandom(2)), each valid until it expires, is removed or is evicted — at most `capacity` at
/// once, the oldest forgotten first. In memory only (a restart signs everyone out).
/// Thread-safe (one mutex). Lookups compare against every live id without an early exit, so the
/// time taken does not tell how much of a guess was right.
class SessionStore {
public:
    SessionStore(std::size_t capacity, std::chrono::seconds maxAge);
    /// Opens a session; its id. Fails (Internal) only when the system has no randomness to give.
    Result<std::string> create();
    /// True for the id of a live (not expired, not removed, not evicted) session.
    bool valid(const std::string& id) const;
    /// Forgets the session (nothing when there is none).
    void remove(const std::string& id);
    std::size_t size() const;

private:
    struct Entry {
        std::string id;
        std::chrono::steady_clock::time_point expires;
    };
    void pruneExpired(std::chrono::steady_clock::time_point now); ///< caller holds mutex_
    const std::size_t capacity_;
    const std::chrono::seconds maxAge_;
    mutable std::mutex mutex_;
    std::deque<Entry> entries_; ///< oldest first
};

/// Per-address back-off after failed sign-ins (issue #27: 11,500 guesses a second were checked):
/// an address's first `freeFailures` failures cost nothing; then it must wait 2^(n − free) s (at
/// most 60 s) after its n-th failure, and every credentialed attempt inside the wait is answered
/// 429 with Retry-After without its credentials being looked at (so a right guess inside the wait
/// tells nothing). A success forgets the address; so do 10 minutes without a failure. At most
/// 4096 addresses are tracked (the stalest forgotten first). Thread-safe (one mutex).
class AuthThrottle {
public:
    explicit AuthThrottle(int freeFailures) : free_(std::max(0, freeFailures)) {}
    /// Whole seconds `ip` must still wait before its credentials are checked (0: check them now).
    int waitSeconds(const std::string& ip);
    /// A failed attempt of `ip`.
    void failed(const std::string& ip);
    /// A successful attempt of `ip`: its failures are forgotten.
    void succeeded(const std::string& ip);

private:
    struct Entry {
        int failures = 0;
        std::chrono::steady_clock::time_point last, until;
    };
    const int free_;
    std::mutex mutex_;
    std::map<std::string, Entry> byAddress_;
};

/// Answers 429 `too_many_requests` with Retry-After: `wait` seconds before this address's
/// credentials are looked at again (AuthThrottle).
void tooManyFailures(Res& res, int wait, const std::string& field);

/// The values of cookie `name` in the request's Cookie headers (all of them: a browser may send
/// more than one), at most 16.
std::vector<std::string> cookieValues(const Req& req, const std::string& name);

// --- connections (api_connections.cpp) ----------------------------------------------------------

/// httplib's server with its connection handling replaced (issue #12): one thread per connection
/// (no fixed pool for slow clients to fill), a deadline for the whole request head, a cap per
/// peer address, a byte budget for every body enforced while it streams, a progress timeout on
/// every write, and a stop() that shuts every open connection instead of waiting for it.
/// Requests themselves are still parsed and routed by httplib (Server::process_request).
class GuardedServer : public httplib::Server {
public:
    struct Limits {
        int headSeconds = 10;  ///< the whole request head (line and headers) within this
        int idleSeconds = 5;   ///< keep-alive: the next request starts within this
        int stallSeconds = 30; ///< every read or write of a body makes progress within this
        int maxConnections = 1024; ///< open at once; past it a connection is answered 503, closed
        int maxPerAddress = 256;   ///< open at once per peer address (see process_and_close_socket)
    };
    Limits limits;
    /// The most body bytes (as sent, chunk framing included) a request may send; set before
    /// serving. Past it the read fails and the request is answered 413 and closed.
    std::function<std::size_t(const Req&)> bodyLimit;

    GuardedServer();
    ~GuardedServer() override;
    /// After bind: lets the kernel queue SOMAXCONN connections not yet accepted (httplib listens
    /// with a backlog of 5: a burst of connections otherwise waits for SYN retries, 1 s each).
    void widenBacklog();
    /// Shuts every open connection (their threads end soon); new ones are closed at once.
    void closeAll();
    /// Waits (up to `timeout`) until no connection thread runs; true when none does.
    bool waitIdle(std::chrono::milliseconds timeout);
    /// On a handler's thread: true when the current request's body went past its limit.
    static bool bodyOverLimit();
    /// On a handler's thread: answer this request with Connection: close, then close (its body,
    /// if any, is not read).
    static void closeAfterAnswer(const Req& req);
    /// On a handler's thread: true when the current request's body may not have been read to its
    /// end — fewer bytes than its Content-Length were read, or it is chunked (whose end is not
    /// tracked here; callers ask only for answers sent early, i.e. errors). Bytes left unread
    /// must never be parsed as the next request (request smuggling): answer and close.
    static bool bodyUnread(const Req& req);
    /// Connections shut so far to make room for new ones (tests, /info).
    std::uint64_t shedCount();

    struct Conn;
    struct Threads;

private:
    bool process_and_close_socket(socket_t sock) override;
    bool admit(Conn& c);
    void forget(Conn& c);

    std::mutex mutex_;
    std::condition_variable idle_;
    /// Caller holds mutex_: shuts the oldest connection still in its first request head; false
    /// when there is none.
    bool shedUnfinishedHead();
    static constexpr int kShedSlack = 64; ///< threads over maxConnections while shed ones end
    std::uint64_t shed_ = 0;              ///< connections shed so far (mutex_)
    std::vector<Conn*> conns_; ///< open connections, oldest first
    int threads_ = 0;          ///< connection threads running
    bool closing_ = false;
};

} // namespace api_detail

/// The server: options, the httplib server, state shared by the handlers.
struct Api::Impl {
    Service& svc;
    ApiOptions opt;
    api_detail::GuardedServer server;
    std::atomic<bool> stopping{false};
    /// Open event streams. Each holds an HTTP worker thread for as long as it is open, so at most
    /// half the workers may stream; more are refused with 503 (otherwise a few dozen open editor
    /// tabs, or one client, would leave no thread to answer anything else: a hang).
    std::atomic<int> streams{0};
    std::mutex streamsMutex;
    std::map<std::string, int> streamsByAddress; ///< open streams per peer address (streamsMutex)
    api_detail::SessionStore sessions;
    api_detail::AuthThrottle authThrottle{opt.authFreeFailures};

    Impl(Service& s, ApiOptions o);
    int maxStreams() const { return std::max(1, opt.threads / 2); }
    int maxStreamsPerAddress() const {
        return opt.maxStreamsPerAddress > 0 ? std::min(opt.maxStreamsPerAddress, maxStreams())
                                            : std::max(1, maxStreams() / 2);
    }
    /// Takes an event-stream slot for peer `ip`: "" when taken, else why not (the global or
    /// the per-address cap). Each taken slot is given back once with giveStream.
    std::string takeStream(const std::string& ip);
    void giveStream(const std::string& ip);
    /// Configures the server and registers every route of the table.
    void install();
    /// The methods served for `path` (under the prefix), comma-separated; "" when no route.
    std::string allowedMethods(const std::string& path) const;
    /// True when `path` (under the prefix) needs no credentials: an open route of `method`, or a
    /// path all of whose routes are open (so that a wrong method there answers 405, not 401).
    bool isOpen(const std::string& method, const std::string& path) const;
    /// The most body bytes `req`'s route takes: the upload limit for POST /models and
    /// POST /patterns, the smaller of it and opt.maxJsonBytes for every other request.
    std::size_t bodyLimitOf(const api_detail::Req& req) const;
    /// True when the request carries the bearer token or the cookie of a live session.
    bool authorized(const api_detail::Req& req) const;

private:
    struct Matcher {
        std::regex re; ///< pathRegex of the route's template
        const api_detail::RouteDef* def;
    };
    std::vector<Matcher> matchers_; ///< one per route of the table
};

} // namespace dermis
