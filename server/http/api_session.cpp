// Dermis HTTP shell — browser sessions. A page cannot add an Authorization header to an <img>
// or an EventSource, so a browser trades the server's token once for a session cookie:
//   POST /session {"token": "…"}  right token: 204 + Set-Cookie: dermis_session=<32 hex digits>;
//                                 HttpOnly; SameSite=Strict; Path=/api/v1; Max-Age=<lifetime>
//                                 wrong token: 401; no token configured: 204 without a cookie
//   DELETE /session               forgets the cookie's session, clears the cookie (204)
// Both routes are open (they need no credentials). The cookie is HttpOnly (no script reads it)
// and SameSite=Strict (no other site's page sends it). It has no Secure attribute: the server
// speaks plain HTTP (put TLS in front of it when it is reachable from elsewhere).
#include "api_internal.hpp"

#include <sys/random.h>

#include <cerrno>

namespace dermis::api_detail {

// --- SessionStore --------------------------------------------------------------------------------

namespace {

/// 16 bytes from the kernel's CSPRNG as 32 lower-case hex digits; nullopt when it gives none.
std::optional<std::string> randomId128() {
    unsigned char bytes[16];
    std::size_t got = 0;
    while (got < sizeof bytes) {
        const ssize_t n = getrandom(bytes + got, sizeof bytes - got, 0);
        if (n < 0) {
            if (errno == EINTR) continue;
            return std::nullopt;
        }
        got += static_cast<std::size_t>(n);
    }
    static const char hex[] = "0123456789abcdef";
    std::string id;
    for (const unsigned char b : bytes) {
        id += hex[b >> 4];
        id += hex[b & 15];
    }
    return id;
}

} // namespace

SessionStore::SessionStore(std::size_t capacity, std::chrono::seconds maxAge)
    : capacity_(std::max<std::size_t>(1, capacity)), maxAge_(maxAge) {}

void SessionStore::pruneExpired(std::chrono::steady_clock::time_point now) {
    // Every session lives equally long, so the oldest (front) expire first.
    while (!entries_.empty() && entries_.front().expires <= now)
        entries_.pop_front();
}

Result<std::string> SessionStore::create() {
    auto id = randomId128();
    if (!id)
        return makeError(ErrorCode::Internal, "dermis::SessionStore::create", "",
                         "the system has no random numbers to give (getrandom failed)");
    const auto now = std::chrono::steady_clock::now();
    std::lock_guard<std::mutex> lock(mutex_);
    pruneExpired(now);
    while (entries_.size() >= capacity_)
        entries_.pop_front(); // the oldest session is forgotten
    entries_.push_back({*id, now + maxAge_});
    return *id;
}

bool SessionStore::valid(const std::string& id) const {
    const auto now = std::chrono::steady_clock::now();
    std::lock_guard<std::mutex> lock(mutex_);
    bool found = false;
    for (const Entry& e : entries_) // no early exit: every live id is compared
        found |= constantTimeEquals(id, e.id) && e.expires > now;
    return found;
}

void SessionStore::remove(const std::string& id) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (auto it = entries_.begin(); it != entries_.end();) {
        if (constantTimeEquals(id, it->id))
            it = entries_.erase(it);
        else
            ++it;
    }
}

std::size_t SessionStore::size() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return entries_.size();
}

// --- cookies -------------------------------------------------------------------------------------

namespace {

std::string trimmed(const std::string& s) {
    const std::size_t b = s.find_first_not_of(" \t");
    if (b == std::string::npos) return "";
    return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

/// The Set-Cookie value for session `id` (empty id and max age 0: clears the cookie).
std::string sessionCookie(const std::string& id, int maxAgeSeconds) {
    return kSessionCookie + "=" + id + "; HttpOnly; SameSite=Strict; Path=" + kPrefix +
           "; Max-Age=" + std::to_string(maxAgeSeconds);
}

} // namespace

std::vector<std::string> cookieValues(const Req& req, const std::string& name) {
    constexpr std::size_t kMaxValues = 16;
    std::vector<std::string> out;
    const auto range = req.headers.equal_range("Cookie");
    for (auto it = range.first; it != range.second && out.size() < kMaxValues; ++it) {
        const std::string& header = it->second;
        std::size_t pos = 0;
        while (pos < header.size() && out.size() < kMaxValues) {
            std::size_t end = header.find(';', pos);
            if (end == std::string::npos) end = header.size();
            const std::string pair = header.substr(pos, end - pos);
            const std::size_t eq = pair.find('=');
            if (eq != std::string::npos && trimmed(pair.substr(0, eq)) == name)
                out.push_back(trimmed(pair.substr(eq + 1)));
            pos = end + 1;
        }
    }
    return out;
}

// --- failed sign-ins --------------------------------------------------------------------------------

int AuthThrottle::waitSeconds(const std::string& ip) {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = byAddress_.find(ip);
    if (it == byAddress_.end()) return 0;
    const auto now = std::chrono::steady_clock::now();
    if (it->second.until <= now) return 0;
    const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(it->second.until - now).count();
    return static_cast<int>((ms + 999) / 1000);
}

void AuthThrottle::failed(const std::string& ip) {
    using namespace std::chrono;
    std::lock_guard<std::mutex> lock(mutex_);
    const auto now = steady_clock::now();
    // Forget addresses quiet for 10 minutes; past 4096, the stalest.
    for (auto it = byAddress_.begin(); it != byAddress_.end();)
        it = now - it->second.last > minutes(10) && it->first != ip ? byAddress_.erase(it) : std::next(it);
    while (byAddress_.size() >= 4096 && !byAddress_.count(ip)) {
        auto stalest = std::min_element(byAddress_.begin(), byAddress_.end(),
                                        [](const auto& a, const auto& b) { return a.second.last < b.second.last; });
        byAddress_.erase(stalest);
    }
    Entry& e = byAddress_[ip];
    if (now - e.last > minutes(10)) e.failures = 0;
    ++e.failures;
    e.last = now;
    if (e.failures > free_) e.until = now + seconds(std::min(60, 1 << std::min(6, e.failures - free_ - 1)));
}

void AuthThrottle::succeeded(const std::string& ip) {
    std::lock_guard<std::mutex> lock(mutex_);
    byAddress_.erase(ip);
}

// --- routes --------------------------------------------------------------------------------------

void installSessionRoutes(RouteTable& t) {
    t.addOpen("POST", "/session", [](Api::Impl& a, const Req& req, Res& res) {
        json body;
        if (!jsonBody(req, res, body)) return;
        if (!body.is_object())
            return sendError(res, 422, "invalid_argument",
                             "dermis-server: body: expected an object {\"token\": \"…\"}", "");
        const auto token = body.find("token");
        if (token == body.end() || !token->is_string())
            return sendError(res, 422, "invalid_argument",
                             "dermis-server: /token: expected a string", "/token");
        res.set_header("Cache-Control", "no-store");
        if (a.opt.token.empty()) { // every route is open: nothing to sign in to
            res.status = 204;
            return;
        }
        if (const int wait = a.authThrottle.waitSeconds(req.remote_addr); wait > 0)
            return tooManyFailures(res, wait, "/token");
        if (!constantTimeEquals(token->get<std::string>(), a.opt.token)) {
            a.authThrottle.failed(req.remote_addr);
            res.set_header("WWW-Authenticate", "Bearer");
            return sendError(res, 401, "unauthorized", "dermis-server: /token: wrong token",
                             "/token");
        }
        a.authThrottle.succeeded(req.remote_addr);
        auto id = a.sessions.create();
        if (!id) return sendError(res, id.error());
        res.set_header("Set-Cookie", sessionCookie(*id, std::max(1, a.opt.sessionMaxAgeSeconds)));
        res.status = 204;
    });
    t.addOpen("DELETE", "/session", [](Api::Impl& a, const Req& req, Res& res) {
        for (const std::string& id : cookieValues(req, kSessionCookie))
            a.sessions.remove(id);
        res.set_header("Set-Cookie", sessionCookie("", 0));
        res.set_header("Cache-Control", "no-store");
        res.status = 204;
    });
}

} // namespace dermis::api_detail
