// FairShareHttpTest — one client cannot take the server (issue #27, item 3), on raw sockets from
// two loopback addresses (127.0.0.1 the attacker, 127.0.0.2 a normal client; Linux routes all of
// 127/8 to lo):
//   * event streams: the attacker asks for 16 (more than the server's 12 with the fixture's 24
//     threads); past the per-address cap (half: 6) it is refused 503, and the normal client's
//     stream opens (before: the attacker held all 12 and the normal client got 503);
//   * connections: the attacker fills --max-connections 40 with request heads it never finishes;
//     the normal client is still answered (the oldest unfinished head is shed; before: 503 for as
//     long as the attack lasted).
#include "HttpTestFixture.hpp"
#include "LoopbackSocket.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

using namespace dermis;
using namespace dermis::test;
using namespace dermis::test::http;

namespace {

/// A connection to 127.0.0.1:port from source address `from` (e.g. "127.0.0.2"); -1 on failure.
int connectFrom(int port, const char* from) { return connectLoopback(port, from); }

/// Sends `request` and reads until the answer's head is complete (or 5 s); the status, 0 if none.
int statusOf(int s, const std::string& request) {
    if (::send(s, request.data(), request.size(), MSG_NOSIGNAL) != static_cast<ssize_t>(request.size())) return 0;
    std::string got;
    char buf[4096];
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(5);
    while (got.find("\r\n\r\n") == std::string::npos && std::chrono::steady_clock::now() < until) {
        pollfd p{s, POLLIN, 0};
        if (::poll(&p, 1, 100) <= 0) continue;
        const ssize_t r = ::recv(s, buf, sizeof buf, 0);
        if (r <= 0) break;
        got.append(buf, static_cast<std::size_t>(r));
    }
    return got.rfind("HTTP/1.1 ", 0) == 0 ? std::atoi(got.c_str() + 9) : 0;
}

std::string get(const std::string& path) {
    return "GET " + kApi + path + " HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n";
}

} // namespace

class FairShareHttpTest : public ::testing::Test {
  protected:
    static void SetUpTestSuite() {
        ApiOptions opt;
        opt.maxConnections = 40;
        server_ = LiveServer::start(mainLimits(), "", error_, opt);
    }
    static void TearDownTestSuite() { server_.reset(); }
    void SetUp() override { ASSERT_TRUE(server_ && error_.empty()) << error_; }
    static inline std::unique_ptr<LiveServer> server_;
    static inline std::string error_;
};

TEST_F(FairShareHttpTest, EventStreamsHaveAPerAddressCap) {
    Http http(server_->port());
    Reply created = http.post("/scenes", smallScene());
    ASSERT_EQ(created.status, 201) << created;
    const std::string events = get("/scenes/" + created.js()["id"].get<std::string>() + "/events");
    std::vector<int> attacker;
    int open = 0, refused = 0;
    for (int i = 0; i < 16; ++i) {
        const int s = connectFrom(server_->port(), "127.0.0.1");
        ASSERT_GE(s, 0);
        attacker.push_back(s);
        const int status = statusOf(s, events);
        open += status == 200;
        refused += status == 503;
    }
    EXPECT_EQ(open, 6) << "half of the 12 streams (24 threads) per address";
    EXPECT_EQ(refused, 10);
    const int normal = connectFrom(server_->port(), "127.0.0.2");
    ASSERT_GE(normal, 0) << "127.0.0.2 is on lo";
    EXPECT_EQ(statusOf(normal, events), 200) << "another address still gets a stream";
    std::cout << "[ figures ] 16 stream requests from one address: " << open << " open, " << refused
              << " refused 503; another address: open\n";
    ::close(normal);
    for (int s : attacker) ::close(s);
}

TEST_F(FairShareHttpTest, UnfinishedHeadsAreShedForNewConnections) {
    std::vector<int> attacker;
    for (int i = 0; i < 40; ++i) {
        const int s = connectFrom(server_->port(), "127.0.0.1");
        ASSERT_GE(s, 0);
        const std::string partial = "GET " + kApi + "/health HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Slow: ";
        ::send(s, partial.data(), partial.size(), MSG_NOSIGNAL);
        attacker.push_back(s);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(300)); // every one admitted, in its head
    int answered = 0;
    for (int i = 0; i < 5; ++i) {
        const int normal = connectFrom(server_->port(), "127.0.0.2");
        ASSERT_GE(normal, 0);
        answered += statusOf(normal, get("/health")) == 200;
        ::close(normal);
    }
    EXPECT_EQ(answered, 5) << "a normal client is answered while 40 unfinished heads fill the server";
    std::cout << "[ figures ] 40 unfinished heads (--max-connections 40): " << answered
              << " of 5 normal requests answered\n";
    for (int s : attacker) ::close(s);
}
