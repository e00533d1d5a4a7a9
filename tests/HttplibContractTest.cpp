// HttplibContractTest — pins what GuardedServer (server/http/private/api_internal.hpp,
// api_connections.cpp) takes from cpp-httplib beyond its public API, so that a new Debian version
// of the library fails here, loudly and by name, instead of quietly changing how connections are
// limited, timed and closed (docs/architecture.md "The HTTP layer and cpp-httplib").
//
// GuardedServer overrides the protected Server::process_and_close_socket with its own keep-alive
// loop (head/idle/stall deadlines, per-address caps, shedding, Connection: close after an early
// answer), calls the protected Server::process_request, reads the protected members
// keep_alive_max_count_ and payload_max_length_, and implements httplib::Stream (GuardedStream).
// The library's own request parsing and routing stay httplib's. When this test fails after an
// upgrade: read the new Server::process_and_close_socket and process_request, bring
// GuardedServer's loop in line, run SmugglingHttpTest, SlowClientHttpTest and FairShareHttpTest,
// then update the pins below.
#include <httplib.h>

#include <gtest/gtest.h>

#include <cstddef>
#include <functional>
#include <string>
#include <type_traits>

namespace {

/// Reaches the protected members GuardedServer uses, with the types it uses them as.
struct Probe : httplib::Server {
    using Server::keep_alive_max_count_;
    using Server::payload_max_length_;
    using Server::process_request;
};

using ProcessRequest = bool (httplib::Server::*)(httplib::Stream&, bool, bool&,
                                                 const std::function<void(httplib::Request&)>&);
static_assert(std::is_same_v<decltype(&Probe::process_request), ProcessRequest>,
              "httplib::Server::process_request changed: GuardedServer's keep-alive loop calls it");
// Server::process_and_close_socket is a private virtual: its address cannot be taken here, but
// GuardedServer declares its own with `override`, so a changed signature fails that build.
static_assert(std::is_same_v<decltype(Probe::keep_alive_max_count_), size_t>);
static_assert(std::is_same_v<decltype(Probe::payload_max_length_), size_t>);

/// Implements exactly the Stream interface GuardedStream implements: a new pure virtual makes
/// this class abstract and the static_assert below fails.
struct MinimalStream final : httplib::Stream {
    bool is_readable() const override { return false; }
    bool is_writable() const override { return false; }
    ssize_t read(char*, size_t) override { return -1; }
    ssize_t write(const char*, size_t) override { return -1; }
    void get_remote_ip_and_port(std::string&, int&) const override {}
    void get_local_ip_and_port(std::string&, int&) const override {}
    socket_t socket() const override { return INVALID_SOCKET; }
};
static_assert(!std::is_abstract_v<MinimalStream>,
              "httplib::Stream gained a method: GuardedStream must implement it");

} // namespace

TEST(HttplibContractTest, VersionIsTheOneGuardedServerWasWrittenFor) {
    EXPECT_STREQ(CPPHTTPLIB_VERSION, "0.11.4")
        << "cpp-httplib changed version: GuardedServer re-implements Server::process_and_close_socket "
           "of 0.11.4 (server/http/api_connections.cpp). Review it against the new library, run the "
           "connection suites (SmugglingHttpTest, SlowClientHttpTest, FairShareHttpTest), then update "
           "this pin.";
}

TEST(HttplibContractTest, ProtectedMembersKeepTheirMeaning) {
    // GuardedServer bounds its loop by keep_alive_max_count_ and a body by payload_max_length_
    // unless its own bodyLimit says otherwise: both must still be set through the public setters.
    Probe server;
    server.set_keep_alive_max_count(7);
    server.set_payload_max_length(12345);
    EXPECT_EQ(server.keep_alive_max_count_, 7u);
    EXPECT_EQ(server.payload_max_length_, 12345u);
}

TEST(HttplibContractTest, ProcessRequestReadsOneRequestFromTheStream) {
    // process_request on a stream holding one request: the handler runs, the answer is written,
    // and setup_request sees the parsed request first (GuardedServer sets the body limit there).
    struct BufferStream final : httplib::Stream {
        std::string in, out;
        std::size_t pos = 0;
        bool is_readable() const override { return pos < in.size(); }
        bool is_writable() const override { return true; }
        ssize_t read(char* p, size_t n) override {
            const std::size_t k = std::min(n, in.size() - pos);
            in.copy(p, k, pos);
            pos += k;
            return static_cast<ssize_t>(k);
        }
        ssize_t write(const char* p, size_t n) override {
            out.append(p, n);
            return static_cast<ssize_t>(n);
        }
        void get_remote_ip_and_port(std::string& ip, int& port) const override { ip = "127.0.0.1", port = 1; }
        void get_local_ip_and_port(std::string& ip, int& port) const override { ip = "127.0.0.1", port = 2; }
        socket_t socket() const override { return INVALID_SOCKET; }
    };
    Probe server;
    server.Post("/echo", [](const httplib::Request& req, httplib::Response& res) {
        res.set_content("got " + req.body, "text/plain");
    });
    BufferStream strm;
    strm.in = "POST /echo HTTP/1.1\r\nHost: x\r\nContent-Length: 5\r\n\r\nhello";
    std::string seenPath;
    bool closed = false;
    const bool ok = server.process_request(strm, true, closed,
                                           [&](httplib::Request& req) { seenPath = req.path; });
    EXPECT_TRUE(ok);
    EXPECT_EQ(seenPath, "/echo");
    EXPECT_NE(strm.out.find("HTTP/1.1 200"), std::string::npos) << strm.out;
    EXPECT_NE(strm.out.find("got hello"), std::string::npos) << strm.out;
    EXPECT_NE(strm.out.find("Connection: close"), std::string::npos) << strm.out;
}
