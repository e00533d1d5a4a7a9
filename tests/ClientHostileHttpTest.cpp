// ClientHostileHttpTest — the `dermis` client (issue #27, items 9–11) as a child process against a
// small hostile server in this test (raw sockets on 127.0.0.1, one scripted answer per case):
//   * an endless JSON body: exit 3 with "over 64 MiB", the client's peak RSS stays small (before:
//     16.8 GB and bad_alloc, exit 2);
//   * an answer trickling a byte every 200 ms: exit 3 at --deadline (before: never ended), and at
//     --max-time for the command;
//   * `dermis frame` given a redirect (with a PNG body), a 2-byte image/png, a PNG under the wrong
//     content type, 2 MB of headers before a 2-byte body, a 200 that breaks off: exit 1 or 3 and
//     no file, no part file (before: each became f.png, exit 0); a real PNG is written (exit 0).
#include "BuildPaths.hpp"
#include "TestFiles.hpp"

#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <thread>
#include <vector>

using namespace dermis::test;
using Clock = std::chrono::steady_clock;

namespace {

const std::string kClient = dermis::build::clientExe();

bool sendAll(int s, const std::string& bytes) {
    std::size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t w = ::send(s, bytes.data() + done, bytes.size() - done, MSG_NOSIGNAL);
        if (w <= 0) return false;
        done += static_cast<std::size_t>(w);
    }
    return true;
}

/// A server on 127.0.0.1 that reads each request's head and runs `answer(socket)`, one
/// connection at a time, until destroyed.
class HostileServer {
public:
    explicit HostileServer(std::function<void(int)> answer) : answer_(std::move(answer)) {
        listen_ = ::socket(AF_INET, SOCK_STREAM, 0);
        const int one = 1;
        ::setsockopt(listen_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
        sockaddr_in a{};
        a.sin_family = AF_INET;
        a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        ::bind(listen_, reinterpret_cast<sockaddr*>(&a), sizeof a);
        ::listen(listen_, 16);
        socklen_t n = sizeof a;
        ::getsockname(listen_, reinterpret_cast<sockaddr*>(&a), &n);
        port_ = ntohs(a.sin_port);
        thread_ = std::thread([this] { loop(); });
    }
    ~HostileServer() {
        stop_ = true;
        ::shutdown(listen_, SHUT_RDWR);
        ::close(listen_);
        thread_.join();
    }
    int port() const { return port_; }
    std::string url() const { return "http://127.0.0.1:" + std::to_string(port_); }
    /// True while the test runs: answers that go on forever stop when it turns false.
    bool running() const { return !stop_; }

private:
    void loop() {
        while (!stop_) {
            pollfd p{listen_, POLLIN, 0};
            if (::poll(&p, 1, 100) <= 0) continue;
            const int s = ::accept(listen_, nullptr, nullptr);
            if (s < 0) continue;
            std::string head;
            char c;
            while (head.find("\r\n\r\n") == std::string::npos && ::recv(s, &c, 1, 0) == 1) head += c;
            answer_(s);
            ::shutdown(s, SHUT_RDWR);
            ::close(s);
        }
    }
    std::function<void(int)> answer_;
    int listen_ = -1;
    int port_ = 0;
    std::atomic<bool> stop_{false};
    std::thread thread_;
};

struct ClientRun {
    int code = -1;
    std::string err;
    double seconds = 0;
    long maxRssKb = 0;
};

/// Runs the client with `args`; its exit code, stderr, wall time and peak RSS.
ClientRun runClient(const std::vector<std::string>& args, const std::string& dir) {
    const std::string errPath = dir + "/stderr.txt";
    const auto t0 = Clock::now();
    const pid_t pid = ::fork();
    if (pid == 0) {
        const int fd = ::open(errPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        ::dup2(fd, 2);
        const int null = ::open("/dev/null", O_WRONLY);
        ::dup2(null, 1);
        std::vector<char*> argv{const_cast<char*>(kClient.c_str())};
        for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
        argv.push_back(nullptr);
        ::execv(kClient.c_str(), argv.data());
        ::_exit(127);
    }
    ClientRun r;
    int status = 0;
    rusage use{};
    ::wait4(pid, &status, 0, &use);
    r.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    r.maxRssKb = use.ru_maxrss;
    std::ifstream in(errPath);
    r.err.assign(std::istreambuf_iterator<char>(in), {});
    return r;
}

const std::string kPngBytes = std::string("\x89PNG\r\n\x1a\n", 8) + std::string(200, 'p');

std::string answerHead(int status, const std::string& type, long length, const std::string& extra = "") {
    std::string h = "HTTP/1.1 " + std::to_string(status) + (status == 200 ? " OK" : " Other") + "\r\n";
    if (!type.empty()) h += "Content-Type: " + type + "\r\n";
    if (length >= 0) h += "Content-Length: " + std::to_string(length) + "\r\n";
    return h + extra + "Connection: close\r\n\r\n";
}

bool noFiles(const std::string& dir) {
    return !std::filesystem::exists(dir + "/out/f.png") && !std::filesystem::exists(dir + "/out/f.png.dermis-part");
}

} // namespace

TEST(ClientHostileHttpTest, AnEndlessJsonAnswerStopsAt64MiBWithExit3) {
    TempDir dir;
    HostileServer server([&](int s) {
        if (!sendAll(s, answerHead(200, "application/json", -1))) return;
        const std::string chunk(1 << 20, 'x');
        for (int i = 0; i < 4096 && server.running(); ++i) // up to 4 GiB; the client stops first
            if (!sendAll(s, chunk)) return;
    });
    const ClientRun r = runClient({"--server", server.url(), "health"}, dir.str());
    EXPECT_EQ(r.code, 3) << r.err;
    EXPECT_NE(r.err.find("over 64 MiB"), std::string::npos) << r.err;
    EXPECT_LT(r.maxRssKb, 400 * 1024) << "peak RSS " << r.maxRssKb << " KB";
    std::cout << "[ figures ] endless answer: exit " << r.code << " after " << r.seconds << " s, peak RSS "
              << r.maxRssKb / 1024 << " MB\n";
}

TEST(ClientHostileHttpTest, ATricklingAnswerEndsAtTheDeadline) {
    TempDir dir;
    HostileServer server([&](int s) {
        if (!sendAll(s, answerHead(200, "application/json", 1000))) return;
        for (int i = 0; i < 1000 && server.running(); ++i) {
            if (!sendAll(s, " ")) return;
            std::this_thread::sleep_for(std::chrono::milliseconds(200));
        }
    });
    const ClientRun r = runClient({"--server", server.url(), "--deadline", "2", "health"}, dir.str());
    EXPECT_EQ(r.code, 3) << r.err;
    EXPECT_NE(r.err.find("--deadline"), std::string::npos) << r.err;
    EXPECT_GE(r.seconds, 1.9);
    EXPECT_LT(r.seconds, 8.0) << "a deadline of 2 s (the answer alone would take 200 s)";
    const ClientRun m = runClient({"--server", server.url(), "--max-time", "1.5", "health"}, dir.str());
    EXPECT_EQ(m.code, 3) << m.err;
    EXPECT_NE(m.err.find("--max-time"), std::string::npos) << m.err;
    EXPECT_LT(m.seconds, 8.0);
    std::cout << "[ figures ] trickle: --deadline 2 ended after " << r.seconds << " s, --max-time 1.5 after "
              << m.seconds << " s\n";
}

TEST(ClientHostileHttpTest, FrameWritesOnlyARealImage) {
    TempDir dir;
    std::string next;
    HostileServer server([&](int s) { sendAll(s, next); });
    const std::vector<std::string> args = {"--server", server.url(), "--retries", "0", "frame", "s1", "-o",
                                           dir.str() + "/out/f.png"};
    struct Case {
        const char* what;
        std::string answer;
        int code;
        const char* says;
    };
    const std::string pad = [] {
        std::string h;
        for (int i = 0; h.size() < (2u << 20); ++i) h += "X-Pad-" + std::to_string(i) + ": " + std::string(100, 'a') + "\r\n";
        return h;
    }();
    const std::vector<Case> cases = {
        {"a redirect with a PNG body", answerHead(302, "image/png", long(kPngBytes.size()), "Location: http://elsewhere/f.png\r\n") + kPngBytes, 1, "redirect"},
        {"a 2-byte image/png", answerHead(200, "image/png", 2) + "ok", 1, "not a image/png"},
        {"a PNG as text/html", answerHead(200, "text/html", long(kPngBytes.size())) + kPngBytes, 1, "text/html"},
        {"2 MB of headers, then 2 bytes", answerHead(200, "image/png", 2, pad) + "ok", 1, "not a image/png"},
        {"a PNG cut short", answerHead(200, "image/png", 5000) + kPngBytes, 3, "cannot connect"},
    };
    for (const Case& c : cases) {
        next = c.answer;
        const ClientRun r = runClient(args, dir.str());
        EXPECT_EQ(r.code, c.code) << c.what << ": " << r.err;
        EXPECT_NE(r.err.find(c.says), std::string::npos) << c.what << ": " << r.err;
        EXPECT_TRUE(noFiles(dir.str())) << c.what << ": no file, no part file";
    }
    next = answerHead(200, "image/png", long(kPngBytes.size())) + kPngBytes;
    const ClientRun ok = runClient(args, dir.str());
    EXPECT_EQ(ok.code, 0) << ok.err;
    std::ifstream in(dir.str() + "/out/f.png", std::ios::binary);
    const std::string got((std::istreambuf_iterator<char>(in)), {});
    EXPECT_EQ(got, kPngBytes);
    EXPECT_FALSE(std::filesystem::exists(dir.str() + "/out/f.png.dermis-part"));
}
