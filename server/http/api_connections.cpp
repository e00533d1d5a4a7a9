// Dermis HTTP shell — connections (issue #12): GuardedServer replaces httplib's fixed thread pool
// and its per-connection loop. httplib still parses and routes each request
// (Server::process_request); what a connection may cost is decided here:
//   * one thread per connection (Threads), at most Limits::maxConnections; past it the oldest
//     connection that never sent a whole request head is shut to make room, else 503, closed;
//   * per peer address at most Limits::maxPerAddress connections: a new one past the cap evicts
//     that address's oldest connection that is idle or still sending its head; when none is,
//     the new one is answered 503 and closed;
//   * the whole request head must arrive within Limits::headSeconds (one byte a second does not
//     keep a connection alive), the next keep-alive request start within Limits::idleSeconds;
//   * every body is counted while it streams (GuardedStream): past bodyLimit(req) the read fails,
//     the answer is 413 and the connection is closed (Content-Length past it is refused before
//     any of the body is read, in Api's pre-routing handler);
//   * every read and write must make progress within Limits::stallSeconds (serve --timeout); a
//     connection whose answer could not be written for that long (the client stopped reading)
//     is reset, which frees what the kernel still holds for it;
//   * an answer sent before its request's body was read to the end (an early refusal: 401 in
//     pre-routing, 413, a multipart body httplib gave up on, …) closes the connection: what is
//     left of the body is dropped, never parsed as the next request (request smuggling);
//   * closeAll() (Api::stop) shuts every connection, so stopping never waits for a slow client.
#include "api_internal.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <limits>
#include <thread>

namespace dermis::api_detail {

namespace {

using Clock = std::chrono::steady_clock;

/// Waits until `sock` is readable (or writable); false on timeout, error or hang-up only.
bool waitFor(int sock, short events, int timeoutMs) {
    pollfd p{sock, events, 0};
    for (;;) {
        const int r = ::poll(&p, 1, std::max(0, timeoutMs));
        if (r < 0 && errno == EINTR) continue;
        return r > 0 && (p.revents & (events | POLLHUP | POLLERR)) != 0;
    }
}

int msUntil(Clock::time_point t) {
    const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(t - Clock::now()).count();
    return ms <= 0 ? 0 : static_cast<int>(std::min<long long>(ms, 1 << 30));
}

/// A socket stream with a head deadline, a body budget and a progress timeout (see the file
/// comment). Reads are buffered (httplib reads the head one byte at a time).
/// The numeric address and port of a socket's other end (`peer`) or its own; empty and 0 when
/// the socket has none (closed, not connected).
void addressOf(int sock, bool peer, std::string& ip, int& port) {
    sockaddr_storage a{};
    socklen_t n = sizeof a;
    ip.clear();
    port = 0;
    auto* sa = reinterpret_cast<sockaddr*>(&a);
    if ((peer ? ::getpeername(sock, sa, &n) : ::getsockname(sock, sa, &n)) != 0) return;
    char text[INET6_ADDRSTRLEN] = {};
    if (a.ss_family == AF_INET) {
        const auto* in = reinterpret_cast<const sockaddr_in*>(&a);
        ::inet_ntop(AF_INET, &in->sin_addr, text, sizeof text);
        port = ntohs(in->sin_port);
    } else if (a.ss_family == AF_INET6) {
        const auto* in = reinterpret_cast<const sockaddr_in6*>(&a);
        ::inet_ntop(AF_INET6, &in->sin6_addr, text, sizeof text);
        port = ntohs(in->sin6_port);
    }
    ip = text;
}

class GuardedStream final : public httplib::Stream {
public:
    GuardedStream(int sock, std::string ip, int port, int stallSeconds)
        : sock_(sock), ip_(std::move(ip)), port_(port), stallMs_(stallSeconds * 1000) {}

    /// A request head starts: it must be complete by `deadline`.
    void beginHead(Clock::time_point deadline) {
        inHead_ = true;
        headDeadline_ = deadline;
        bodyRead_ = 0;
        declared_ = 0;
        chunked_ = false;
        overLimit_ = false;
    }
    /// The head is complete: at most `budget` body bytes follow.
    void beginBody(std::size_t budget) {
        inHead_ = false;
        bodyBudget_ = budget;
    }
    bool overLimit() const { return overLimit_; }
    std::size_t bodyBudget() const { return bodyBudget_; }
    /// Body bytes of the current request read so far.
    std::size_t bodyRead() const { return bodyRead_; }
    /// The current request's declared body: its Content-Length (0 without one), or chunked.
    void declareBody(std::size_t length, bool chunked) {
        declared_ = length;
        chunked_ = chunked;
    }
    /// True when fewer bytes than the declared Content-Length were read.
    bool shortOfContentLength() const { return !chunked_ && bodyRead_ < declared_; }
    bool chunked() const { return chunked_; }
    bool closeAfter = false;
    /// True when bytes already received wait in the buffer.
    bool buffered() const { return off_ < len_; }

    bool is_readable() const override { return off_ < len_ || waitFor(sock_, POLLIN, stallMs_); }
    bool is_writable() const override { return waitFor(sock_, POLLOUT, stallMs_); }

    ssize_t read(char* ptr, std::size_t size) override {
        if (overLimit_) return -1;
        if (!inHead_ && bodyRead_ + size > bodyBudget_) {
            size = bodyBudget_ - bodyRead_ + 1; // one byte past the budget is enough to know
        }
        ssize_t n = 0;
        if (off_ < len_) {
            n = static_cast<ssize_t>(std::min(size, len_ - off_));
            std::memcpy(ptr, buf_ + off_, static_cast<std::size_t>(n));
            off_ += static_cast<std::size_t>(n);
        } else {
            int timeout = stallMs_;
            if (inHead_) {
                timeout = std::min(timeout, msUntil(headDeadline_));
                if (timeout == 0) return -1; // the head took too long
            }
            if (!waitFor(sock_, POLLIN, timeout)) return -1;
            const bool direct = !inHead_ && size >= sizeof buf_;
            const ssize_t r = ::recv(sock_, direct ? ptr : buf_, direct ? size : sizeof buf_, 0);
            if (r <= 0) return r < 0 ? -1 : 0;
            if (direct) {
                n = r;
            } else {
                off_ = 0;
                len_ = static_cast<std::size_t>(r);
                n = static_cast<ssize_t>(std::min(size, len_));
                std::memcpy(ptr, buf_, static_cast<std::size_t>(n));
                off_ = static_cast<std::size_t>(n);
            }
        }
        if (!inHead_) {
            bodyRead_ += static_cast<std::size_t>(n);
            if (bodyRead_ > bodyBudget_) {
                overLimit_ = true;
                closeAfter = true;
                return -1;
            }
        }
        return n;
    }

    ssize_t write(const char* ptr, std::size_t size) override {
        if (!waitFor(sock_, POLLOUT, stallMs_)) {
            writeStalled_ = true;
            return -1;
        }
        const ssize_t r = ::send(sock_, ptr, size, MSG_NOSIGNAL);
        if (r < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) writeStalled_ = true;
        return r < 0 ? -1 : r;
    }
    /// An answer could not be written for stallSeconds: the client stopped reading.
    bool writeStalled() const { return writeStalled_; }

    void get_remote_ip_and_port(std::string& ip, int& port) const override {
        ip = ip_;
        port = port_;
    }
    void get_local_ip_and_port(std::string& ip, int& port) const override {
        addressOf(sock_, false, ip, port);
    }
    socket_t socket() const override { return sock_; }

private:
    int sock_;
    std::string ip_;
    int port_;
    int stallMs_;
    char buf_[4096];
    std::size_t off_ = 0, len_ = 0;
    bool inHead_ = true;
    Clock::time_point headDeadline_{};
    std::size_t bodyBudget_ = 0, bodyRead_ = 0;
    std::size_t declared_ = 0;
    bool chunked_ = false;
    bool overLimit_ = false;
    bool writeStalled_ = false;
};

thread_local GuardedStream* tCurrent = nullptr; ///< the stream of this thread's connection
thread_local bool tRefuse = false;              ///< set while Threads runs a task inline: refuse

void peerOf(int sock, std::string& ip, int& port) { addressOf(sock, true, ip, port); }

/// Answers 503 without waiting (the socket is new: its send buffer is empty) and closes.
void refuse(int sock) {
    static const std::string body =
        R"({"error":{"code":"unavailable","message":"dermis-server: too many connections","field":""}})";
    const std::string answer = "HTTP/1.1 503 Service Unavailable\r\nContent-Type: application/json\r\n"
                               "Retry-After: 1\r\nConnection: close\r\nContent-Length: " +
                               std::to_string(body.size()) + "\r\n\r\n" + body;
    (void)::send(sock, answer.data(), answer.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
    ::shutdown(sock, SHUT_RDWR);
    ::close(sock);
}

} // namespace

struct GuardedServer::Conn {
    int sock;
    std::string ip;
    std::atomic<bool> idle{true};      ///< waiting for a request or reading its head: evictable
    std::atomic<bool> headDone{false}; ///< one request head arrived whole on this connection
};

/// One thread per connection, at most maxConnections at once; past it the task runs inline on
/// the accepting thread with tRefuse set (process_and_close_socket then refuses at once).
struct GuardedServer::Threads final : httplib::TaskQueue {
    explicit Threads(GuardedServer& s) : server(s) {}
    void enqueue(std::function<void()> fn) override {
        {
            std::lock_guard<std::mutex> lock(server.mutex_);
            // Full: the oldest connection that never sent a whole request head makes room (a
            // handful of addresses trickling heads cannot keep every slot; nginx sheds the same
            // way). Its thread ends at once; until it has, up to kShedSlack threads run over.
            const bool room = server.threads_ < server.limits.maxConnections ||
                              (server.threads_ < server.limits.maxConnections + kShedSlack && server.shedUnfinishedHead());
            if (room && !server.closing_) {
                ++server.threads_;
                std::thread([this, fn = std::move(fn)] {
                    fn();
                    std::lock_guard<std::mutex> l(server.mutex_);
                    if (--server.threads_ == 0) server.idle_.notify_all();
                }).detach();
                return;
            }
        }
        tRefuse = true;
        fn();
        tRefuse = false;
    }
    /// Called when listening ends: shuts every connection and waits for their threads (a handler
    /// still running, a render say, is waited for; a slow client is not).
    void shutdown() override {
        server.closeAll();
        server.waitIdle(std::chrono::hours(24));
    }
    GuardedServer& server;
};

GuardedServer::GuardedServer() {
    new_task_queue = [this] { return new Threads(*this); };
}

GuardedServer::~GuardedServer() {
    closeAll();
    waitIdle(std::chrono::hours(24));
}

void GuardedServer::widenBacklog() {
    const int sock = svr_sock_;
    if (sock >= 0) ::listen(sock, SOMAXCONN);
}

void GuardedServer::closeAll() {
    std::lock_guard<std::mutex> lock(mutex_);
    closing_ = true;
    for (Conn* c : conns_) ::shutdown(c->sock, SHUT_RDWR);
}

bool GuardedServer::waitIdle(std::chrono::milliseconds timeout) {
    std::unique_lock<std::mutex> lock(mutex_);
    return idle_.wait_for(lock, timeout, [this] { return threads_ == 0; });
}

bool GuardedServer::bodyOverLimit() {
    return tCurrent && tCurrent->overLimit();
}

void GuardedServer::closeAfterAnswer(const Req& req) {
    if (tCurrent) tCurrent->closeAfter = true;
    // The request object is process_request's own (not const there): its Connection header is
    // what httplib reads to answer "Connection: close".
    auto& headers = const_cast<Req&>(req).headers;
    headers.erase("Connection");
    headers.emplace("Connection", "close");
}

bool GuardedServer::bodyUnread(const Req& req) {
    (void)req;
    return tCurrent && (tCurrent->chunked() || tCurrent->shortOfContentLength());
}

namespace {

/// The request's declared body: {Content-Length (0 when absent or malformed), chunked}.
std::pair<std::size_t, bool> declaredBody(const httplib::Request& req) {
    const std::string te = req.get_header_value("Transfer-Encoding");
    std::string lower(te);
    std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    if (lower.find("chunked") != std::string::npos) return {0, true};
    const std::string v = req.get_header_value("Content-Length");
    if (v.empty()) return {0, false};
    char* end = nullptr;
    errno = 0;
    const unsigned long long n = std::strtoull(v.c_str(), &end, 10);
    if (*end != '\0' || errno == ERANGE) return {std::numeric_limits<std::size_t>::max(), false};
    return {static_cast<std::size_t>(n), false};
}

} // namespace

bool GuardedServer::shedUnfinishedHead() {
    for (Conn* o : conns_) // oldest first
        if (!o->headDone && o->idle) {
            ::shutdown(o->sock, SHUT_RDWR); // its thread sees the hang-up and closes it
            o->idle = false;                // shed once
            ++shed_;
            return true;
        }
    return false;
}

std::uint64_t GuardedServer::shedCount() {
    std::lock_guard<std::mutex> lock(mutex_);
    return shed_;
}

bool GuardedServer::admit(Conn& c) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (closing_) return false;
    int same = 0;
    Conn* oldestIdle = nullptr;
    for (Conn* o : conns_) {
        if (o->ip != c.ip) continue;
        ++same;
        if (!oldestIdle && o->idle) oldestIdle = o;
    }
    if (same >= limits.maxPerAddress) {
        if (!oldestIdle) return false;
        ::shutdown(oldestIdle->sock, SHUT_RDWR); // its thread sees the hang-up and closes it
        oldestIdle->idle = false;                // evicted once
    }
    conns_.push_back(&c);
    return true;
}

void GuardedServer::forget(Conn& c) {
    std::lock_guard<std::mutex> lock(mutex_);
    conns_.erase(std::remove(conns_.begin(), conns_.end(), &c), conns_.end());
}

bool GuardedServer::process_and_close_socket(socket_t sock) {
    if (tRefuse) {
        refuse(sock);
        return false;
    }
    const auto accepted = Clock::now();
    Conn conn{sock, {}};
    int port = 0;
    peerOf(sock, conn.ip, port);
    if (!admit(conn)) {
        refuse(sock);
        return false;
    }
    GuardedStream strm(sock, conn.ip, port, limits.stallSeconds);
    tCurrent = &strm;
    bool ret = false;
    bool first = true;
    for (std::size_t count = keep_alive_max_count_; count > 0; --count) {
        conn.idle = true;
        const auto deadline = first ? accepted + std::chrono::seconds(limits.headSeconds)
                                    : Clock::now() + std::chrono::seconds(limits.idleSeconds);
        if (!strm.buffered() && !waitFor(sock, POLLIN, msUntil(deadline))) break;
        strm.beginHead(first ? deadline : Clock::now() + std::chrono::seconds(limits.headSeconds));
        first = false;
        bool closed = false;
        const bool closeConnection = count == 1;
        ret = process_request(strm, closeConnection, closed, [&](httplib::Request& req) {
            conn.idle = false;
            conn.headDone = true;
            strm.beginBody(bodyLimit ? bodyLimit(req) : payload_max_length_);
            const auto [length, chunked] = declaredBody(req);
            strm.declareBody(length, chunked);
        });
        // An answer that left part of its body unread (whatever sent it): the rest is not a request.
        if (strm.shortOfContentLength()) strm.closeAfter = true;
        if (!ret || closed || closeConnection || strm.closeAfter) break;
    }
    tCurrent = nullptr;
    forget(conn);
    if (strm.closeAfter) {
        // The answer was sent before the body was read: stop sending, then read (and drop) what
        // the client still sends, at most the body's budget and 2 s, until it pauses for 200 ms,
        // so that a client that writes all of its body before reading gets the answer rather
        // than a reset. Nothing of it is kept.
        ::shutdown(sock, SHUT_WR);
        char drop[16384];
        const auto until = Clock::now() + std::chrono::seconds(2);
        const std::size_t budget = std::max<std::size_t>(strm.bodyBudget(), 1u << 20);
        std::size_t dropped = 0;
        while (dropped < budget && waitFor(sock, POLLIN, std::min(200, msUntil(until)))) {
            const ssize_t r = ::recv(sock, drop, sizeof drop, 0);
            if (r <= 0) break;
            dropped += static_cast<std::size_t>(r);
        }
    }
    if (strm.writeStalled()) {
        // The client stopped reading: reset rather than close, so that the kernel drops what is
        // still queued for it at once (a graceful close would keep up to the socket's send
        // buffer, megabytes, in an orphaned socket probing a zero window for minutes).
        const linger abort{1, 0};
        ::setsockopt(sock, SOL_SOCKET, SO_LINGER, &abort, sizeof abort);
    } else {
        ::shutdown(sock, SHUT_RDWR);
    }
    ::close(sock);
    return ret;
}

} // namespace dermis::api_detail
