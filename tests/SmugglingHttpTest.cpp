// SmugglingHttpTest — no request smuggling (issue #27, item 1): whenever an answer is sent
// before its request's body was read to the end, the connection is closed and the rest of the
// body never runs as a request. Raw sockets against a server in this process; each body carries
// a second request (a DELETE of a scene) where the server stops reading:
//   * a multipart POST /render with more than 1024 parts (cpp-httplib's multipart limit: 400);
//   * a POST refused 401 in pre-routing (a server with a token) before its body is read;
//   * a GET whose Content-Length body httplib does not read for that method.
// Each: exactly one answer comes back, the connection is closed after it, and the scene is still
// there. Before the fix the DELETE ran (the scene was gone) and a second answer came back.
#include "HttpTestFixture.hpp"
#include "LoopbackSocket.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>

using namespace dermis;
using namespace dermis::test;
using namespace dermis::test::http;

namespace {

using Clock = std::chrono::steady_clock;

/// Sends `bytes` on a fresh connection to 127.0.0.1:port (as much as the server takes within
/// 5 s) and reads until the server closes or 5 s pass. {everything read, closed by the server}.
std::pair<std::string, bool> exchange(int port, const std::string& bytes) {
    const int s = connectLoopback(port);
    if (s < 0) return {"", false};
    const auto until = Clock::now() + std::chrono::seconds(5);
    std::size_t sent = 0;
    std::string got;
    bool closed = false;
    char buf[65536];
    while (Clock::now() < until && !closed) {
        pollfd p{s, static_cast<short>(POLLIN | (sent < bytes.size() ? POLLOUT : 0)), 0};
        if (::poll(&p, 1, 100) <= 0) continue;
        if (p.revents & POLLIN) {
            const ssize_t r = ::recv(s, buf, sizeof buf, 0);
            if (r <= 0) closed = true;
            else got.append(buf, static_cast<std::size_t>(r));
        }
        if ((p.revents & POLLOUT) && sent < bytes.size()) {
            const ssize_t w = ::send(s, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
            if (w > 0) sent += static_cast<std::size_t>(w);
            else sent = bytes.size(); // the server stopped reading: nothing more to send
        }
        if (p.revents & (POLLERR | POLLHUP)) closed = true;
    }
    ::close(s);
    return {got, closed};
}

/// How many HTTP answers a byte stream holds (status lines at the start or after a blank line).
int answers(const std::string& stream) {
    int n = 0;
    for (std::size_t at = stream.find("HTTP/1.1 "); at != std::string::npos; at = stream.find("HTTP/1.1 ", at + 1))
        if (at == 0 || stream.compare(at - 2, 2, "\r\n") == 0) ++n;
    return n;
}

std::string smuggled(const std::string& sceneId, const std::string& auth = "") {
    return "DELETE " + kApi + "/scenes/" + sceneId + " HTTP/1.1\r\nHost: 127.0.0.1\r\n" + auth +
           "Content-Length: 0\r\n\r\n";
}

/// A multipart/form-data body of `parts` parts, each holding `content`.
std::string multipart(int parts, const std::string& boundary, const std::string& content) {
    std::string body;
    for (int i = 0; i < parts; ++i)
        body += "--" + boundary + "\r\nContent-Disposition: form-data; name=\"p" + std::to_string(i) +
                "\"\r\n\r\n" + content + "\r\n";
    return body + "--" + boundary + "--\r\n";
}

} // namespace

class SmugglingHttpTest : public SharedServerTest {};

TEST_F(SmugglingHttpTest, MultipartPastThePartLimitClosesTheConnection) {
    const std::string id = createScene(smallScene());
    const std::string boundary = "dermisboundary";
    // Every part's content is the second request: wherever httplib stops, what follows starts it.
    const std::string body = multipart(1100, boundary, smuggled(id));
    const std::string req = "POST " + kApi + "/render HTTP/1.1\r\nHost: 127.0.0.1\r\n"
                            "Content-Type: multipart/form-data; boundary=" + boundary + "\r\n"
                            "Content-Length: " + std::to_string(body.size()) + "\r\n\r\n" + body;
    const auto [got, closed] = exchange(server_->port(), req);
    EXPECT_EQ(answers(got), 1) << got.substr(0, 2000);
    EXPECT_NE(got.find("HTTP/1.1 4"), std::string::npos) << got.substr(0, 400);
    EXPECT_NE(got.find("Connection: close"), std::string::npos) << got.substr(0, 400);
    EXPECT_TRUE(closed) << "the server closed the connection after its answer";
    EXPECT_EQ(http().get("/scenes/" + id).status, 200) << "the smuggled DELETE did not run";
}

TEST_F(SmugglingHttpTest, GetWithAnUnreadBodyClosesTheConnection) {
    const std::string id = createScene(smallScene());
    const std::string body = smuggled(id);
    const std::string req = "GET " + kApi + "/health HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Length: " +
                            std::to_string(body.size()) + "\r\n\r\n" + body;
    const auto [got, closed] = exchange(server_->port(), req);
    EXPECT_LE(answers(got), 1) << got.substr(0, 2000);
    EXPECT_TRUE(closed);
    EXPECT_EQ(http().get("/scenes/" + id).status, 200) << "the smuggled DELETE did not run";
}

class SmugglingHttpAuthTest : public ::testing::Test {
  protected:
    static constexpr const char* kToken = "smuggling-test-token-0123456789";
    static void SetUpTestSuite() { server_ = LiveServer::start(mainLimits(), kToken, error_); }
    static void TearDownTestSuite() { server_.reset(); }
    void SetUp() override { ASSERT_TRUE(server_ && error_.empty()) << error_; }
    static inline std::unique_ptr<LiveServer> server_;
    static inline std::string error_;
};

TEST_F(SmugglingHttpAuthTest, RefusedInPreRoutingBeforeTheBodyClosesTheConnection) {
    Http authed(server_->port(), kToken);
    Reply created = authed.post("/scenes", smallScene());
    ASSERT_EQ(created.status, 201) << created;
    const std::string id = created.js().value("id", "");
    // The body (never read: 401 comes first) is a request with the token.
    const std::string body = smuggled(id, std::string("Authorization: Bearer ") + kToken + "\r\n");
    const std::string req = "POST " + kApi + "/scenes HTTP/1.1\r\nHost: 127.0.0.1\r\n"
                            "Content-Type: application/json\r\nContent-Length: " +
                            std::to_string(body.size()) + "\r\n\r\n" + body;
    const auto [got, closed] = exchange(server_->port(), req);
    EXPECT_EQ(answers(got), 1) << got.substr(0, 2000);
    EXPECT_NE(got.find("HTTP/1.1 401"), std::string::npos) << got.substr(0, 400);
    EXPECT_NE(got.find("Connection: close"), std::string::npos) << got.substr(0, 400);
    EXPECT_TRUE(closed);
    EXPECT_EQ(authed.get("/scenes/" + id).status, 200) << "the smuggled DELETE did not run";
}
