// ServerProcessHttpTest — dermis-server as a real process on 127.0.0.1 (a GL context through
// $DERMIS_TEST_GL): every acknowledged edit survives kill -9 and a restart on the same data
// directory; 8 concurrent clients mixing edits and renders for 2,000 requests get no 5xx other
// than 503 back-pressure, and the server's memory stops growing.
#include "BuildPaths.hpp"
#include "ProcessStats.hpp"
#include "TestFiles.hpp"

#include <gtest/gtest.h>
#include <httplib.h>
#include <nlohmann/json.hpp>

#include <atomic>
#include <fcntl.h>
#include <chrono>
#include <csignal>
#include <cstring>
#include <fstream>
#include <mutex>
#include <random>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>
#include <vector>

using namespace dermis::test;
using nlohmann::json;

namespace {

std::string backend() {
    const char* env = std::getenv("DERMIS_TEST_GL");
    return env && *env ? env : "auto";
}

/// A dermis-server child process serving `dataDir` on a free port.
class ServerProcess {
public:
    explicit ServerProcess(const std::string& dataDir, const std::string& logPath,
                           std::vector<std::string> extra = {})
        : log_(logPath) {
        pid_ = ::fork();
        if (pid_ == 0) {
            const int fd = ::open(logPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
            ::dup2(fd, 1);
            ::dup2(fd, 2);
            const std::string gl = backend();
            // Under AddressSanitizer, keep freed memory from piling up in its quarantine (the
            // memory test measures the server, not the sanitizer).
            if (const char* asan = std::getenv("ASAN_OPTIONS"))
                ::setenv("ASAN_OPTIONS", (std::string(asan) + ":quarantine_size_mb=4").c_str(), 1);
            std::vector<std::string> args = {dermis::build::serverExe(),
                                             "serve",
                                             "--port",
                                             "0",
                                             "--data",
                                             dataDir,
                                             "--gl",
                                             gl,
                                             "--queue",
                                             "64"};
            args.insert(args.end(), extra.begin(), extra.end());
            std::vector<char*> argv;
            for (std::string& x : args) argv.push_back(x.data());
            argv.push_back(nullptr);
            ::execv(dermis::build::serverExe(), argv.data());
            ::_exit(127);
        }
        // Wait for "serving http://127.0.0.1:<port>/".
        for (int i = 0; i < 600 && port_ == 0; ++i) {
            std::this_thread::sleep_for(std::chrono::milliseconds(50));
            std::ifstream in(logPath);
            std::string text((std::istreambuf_iterator<char>(in)), {});
            const auto at = text.find("serving http://127.0.0.1:");
            if (at != std::string::npos) port_ = std::atoi(text.c_str() + at + 25);
            int status = 0;
            if (::waitpid(pid_, &status, WNOHANG) == pid_) {
                pid_ = -1;
                break;
            }
        }
    }
    ~ServerProcess() { kill(SIGKILL); }
    int port() const { return port_; }
    pid_t pid() const { return pid_; }
    void kill(int sig) {
        if (pid_ <= 0) return;
        ::kill(pid_, sig);
        int status = 0;
        ::waitpid(pid_, &status, 0);
        pid_ = -1;
    }
    std::string log() const {
        std::ifstream in(log_);
        return std::string((std::istreambuf_iterator<char>(in)), {});
    }
    /// Resident memory of the process in kB (from /proc), −1 if unknown.
    long rssKb() const { return residentKb(pid_); }

private:
    pid_t pid_ = -1;
    int port_ = 0;
    std::string log_;
};

httplib::Client client(int port) {
    httplib::Client c("127.0.0.1", port);
    c.set_read_timeout(60, 0);
    c.set_connection_timeout(5, 0);
    c.set_tcp_nodelay(true);
    return c;
}

/// Uploads a one-triangle .gltf with an external buffer (multipart); the model id.
std::string uploadTriangleGltf(httplib::Client& c) {
    const auto [gltf, bin] = triangleGltf("tri.bin");
    auto r = c.Post("/api/v1/models", httplib::MultipartFormDataItems{{"gltf", gltf, "tri.gltf", ""},
                                                                       {"buffer", bin, "tri.bin", ""}});
    EXPECT_TRUE(r);
    if (!r) return "";
    EXPECT_EQ(r->status, 201) << r->body;
    return json::parse(r->body, nullptr, false).value("id", "");
}

json createScene(httplib::Client& c) {
    auto r = c.Post("/api/v1/scenes",
                    R"({"default_patterns": true, "heightmap": {"size": [256, 256]},
                        "render": {"size": [128, 128], "msaa": 1}})",
                    "application/json");
    EXPECT_TRUE(r);
    if (!r) return {};
    EXPECT_EQ(r->status, 201) << r->body;
    return json::parse(r->body, nullptr, false);
}

// Lower limits do not stop a fresh server (issue #25): the default scene breaks
// --max-render-side 512 and --max-placements 1, so the server starts without it, says why, and
// serves; without such limits a fresh data folder gets its one default scene.
TEST(ServerProcessHttpTest, LowerLimitsStartAFreshServerWithoutTheDefaultScene) {
    struct Case {
        std::vector<std::string> flags;
        bool defaultScene;
    };
    for (const Case& c : {Case{{"--max-render-side", "512"}, false}, Case{{"--max-placements", "1"}, false},
                          Case{{}, true}}) {
        TempDir dir;
        ServerProcess server(dir / "data", dir / "log.txt", c.flags);
        const std::string what = c.flags.empty() ? "no limits" : c.flags[0];
        ASSERT_GT(server.port(), 0) << what << ": the server did not start:\n" << server.log();
        httplib::Client h = client(server.port());
        auto health = h.Get("/api/v1/health");
        ASSERT_TRUE(health) << what;
        EXPECT_EQ(health->status, 200) << what;
        auto list = h.Get("/api/v1/scenes");
        ASSERT_TRUE(list) << what;
        const json scenes = json::parse(list->body, nullptr, false)["scenes"];
        EXPECT_EQ(scenes.size(), c.defaultScene ? 1u : 0u) << what << ": " << list->body;
        const std::string log = server.log();
        EXPECT_EQ(log.find("warning: no default scene") != std::string::npos, !c.defaultScene) << what << ":\n" << log;
        EXPECT_EQ(log.find("/frame") != std::string::npos, c.defaultScene) << what << ": the first scene's frame URL";
        if (!c.defaultScene) { // and a scene within the limits can still be made
            auto made = h.Post("/api/v1/scenes",
                               R"({"format": "dermis.scene/1", "model": "builtin:default", "placements": [],
                                   "heightmap": {"size": [256, 256]}, "render": {"size": [128, 128], "msaa": 1}})",
                               "application/json");
            ASSERT_TRUE(made) << what;
            EXPECT_EQ(made->status, 201) << what << ": " << made->body;
        }
    }
}

TEST(ServerProcessHttpTest, AcknowledgedEditsSurviveKillDashNine) {
    TempDir dir;
    const std::string data = dir / "data";
    struct Ack {
        std::string scene;
        std::uint64_t revision;
        double time;
    };
    std::vector<Ack> acks;
    std::vector<std::string> scenes;
    std::string gltfModel;
    {
        ServerProcess server(data, dir / "log1.txt");
        ASSERT_GT(server.port(), 0) << server.log();
        httplib::Client c = client(server.port());
        gltfModel = uploadTriangleGltf(c);
        ASSERT_FALSE(gltfModel.empty());
        for (int s = 0; s < 3; ++s) {
            json created = createScene(c);
            ASSERT_TRUE(created.contains("id"));
            scenes.push_back(created["id"]);
        }
        // A stream of pose edits on the three scenes; kill -9 lands in the middle of it.
        std::atomic<bool> stop{false};
        std::mutex m;
        std::thread editor([&] {
            httplib::Client ec = client(server.port());
            for (int i = 0; !stop; ++i) {
                const std::string sid = scenes[static_cast<std::size_t>(i) % scenes.size()];
                const double t = 0.01 * i;
                auto r = ec.Patch("/api/v1/scenes/" + sid + "/pose", json{{"time", t}}.dump(),
                                  "application/json");
                if (!r) break; // the server is gone
                if (r->status != 200) continue;
                json body = json::parse(r->body, nullptr, false);
                std::lock_guard<std::mutex> lock(m);
                acks.push_back({sid, body["revision"].get<std::uint64_t>(), t});
            }
        });
        // Kill once at least 1.5 s have passed and more than 20 edits are acknowledged (on a
        // loaded machine, under sanitizers, edits are slow: wait up to 60 s for them).
        const auto start = std::chrono::steady_clock::now();
        for (;;) {
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
            std::size_t n = 0;
            {
                std::lock_guard<std::mutex> lock(m);
                n = acks.size();
            }
            const auto waited = std::chrono::steady_clock::now() - start;
            if ((n > 20 && waited > std::chrono::milliseconds(1500)) || waited > std::chrono::seconds(60)) break;
        }
        server.kill(SIGKILL);
        stop = true;
        editor.join();
    }
    ASSERT_GT(acks.size(), 10u) << "too few edits were acknowledged before the kill";

    ServerProcess again(data, dir / "log2.txt");
    ASSERT_GT(again.port(), 0) << again.log();
    httplib::Client c = client(again.port());
    for (const std::string& sid : scenes) {
        auto r = c.Get("/api/v1/scenes/" + sid);
        ASSERT_TRUE(r);
        ASSERT_EQ(r->status, 200) << sid << " lost: " << r->body;
        json doc = json::parse(r->body);
        // The last acknowledged edit of this scene is there (a later, unacknowledged one may be too).
        const Ack* last = nullptr;
        for (const Ack& a : acks)
            if (a.scene == sid) last = &a;
        ASSERT_NE(last, nullptr);
        EXPECT_GE(doc["revision"].get<std::uint64_t>(), last->revision) << sid;
        if (doc["revision"].get<std::uint64_t>() == last->revision)
            EXPECT_DOUBLE_EQ(doc["scene"]["pose"]["time"].get<double>(), last->time) << sid;
    }
    // The multi-file .gltf upload is back too.
    auto m = c.Get("/api/v1/models/" + gltfModel);
    ASSERT_TRUE(m);
    EXPECT_EQ(m->status, 200) << m->body;
    // And the restarted server renders them.
    auto f = c.Get("/api/v1/scenes/" + scenes[0] + "/frame?width=64&height=64");
    ASSERT_TRUE(f);
    EXPECT_EQ(f->status, 200) << f->body;
}

TEST(ServerProcessHttpTest, EightClientsMixingEditsAndRendersStayHealthy) {
    TempDir dir;
    ServerProcess server(dir / "data", dir / "log.txt");
    ASSERT_GT(server.port(), 0) << server.log();
    std::vector<std::string> scenes;
    {
        httplib::Client c = client(server.port());
        for (int s = 0; s < 4; ++s) {
            json created = createScene(c);
            ASSERT_TRUE(created.contains("id"));
            scenes.push_back(created["id"]);
        }
    }
    constexpr int kClients = 8, kTotal = 2000;
    std::atomic<int> next{0}, ok{0}, backPressure{0}, clientErrors{0}, serverErrors{0}, failed{0};
    std::atomic<long> rssMid{-1};
    std::mutex firstErrorMutex;
    std::string firstError;
    auto worker = [&](int seed) {
        std::mt19937 rng(static_cast<unsigned>(seed));
        httplib::Client c = client(server.port());
        c.set_keep_alive(true);
        for (int i; (i = next.fetch_add(1)) < kTotal;) {
            if (i == kTotal / 2) rssMid = server.rssKb();
            const std::string sid = scenes[rng() % scenes.size()];
            const std::string base = "/api/v1/scenes/" + sid;
            auto send = [&]() -> httplib::Result {
                switch (rng() % 6) {
                case 0:
                    return c.Patch(base + "/pose", json{{"time", (rng() % 100) * 0.02}}.dump(),
                                   "application/json");
                case 1:
                    return c.Patch(base + "/placements/stomach",
                                   json{{"center", {0.28 + (rng() % 10) * 0.005, 0.35}}}.dump(),
                                   "application/json");
                case 2: return c.Get(base);
                case 3: return c.Get(base + "/frame?width=96&height=96&format=jpeg");
                case 4: return c.Get(base + "/frame?width=128&height=128&yaw=" + std::to_string(rng() % 360));
                default: return c.Get(base + "/heightmaps/displacement?format=f32");
                }
            };
            httplib::Result r = send();
            if (!r) {
                ++failed;
                continue;
            }
            if (r->status < 400) ++ok;
            else if (r->status == 503) ++backPressure;
            else if (r->status >= 500) {
                ++serverErrors;
                std::lock_guard<std::mutex> lock(firstErrorMutex);
                if (firstError.empty()) firstError = std::to_string(r->status) + " " + r->body;
            } else {
                ++clientErrors;
                std::lock_guard<std::mutex> lock(firstErrorMutex);
                if (firstError.empty()) firstError = std::to_string(r->status) + " " + r->body;
            }
        }
    };
    std::vector<std::thread> threads;
    for (int k = 0; k < kClients; ++k)
        threads.emplace_back(worker, k + 1);
    for (auto& t : threads)
        t.join();
    const long rssEnd = server.rssKb();
    EXPECT_EQ(failed.load(), 0) << "requests without an answer";
    EXPECT_EQ(serverErrors.load(), 0) << firstError;
    EXPECT_EQ(clientErrors.load(), 0) << firstError;
    EXPECT_EQ(ok + backPressure, kTotal);
    EXPECT_GT(ok.load(), kTotal / 2);
    // Memory stops growing: the second half of the run adds less than 15% (caches are warm).
    ASSERT_GT(rssMid.load(), 0);
    EXPECT_LT(rssEnd, rssMid.load() * 115 / 100) << "RSS " << rssMid.load() << " kB at 1,000 requests, "
                                                  << rssEnd << " kB at 2,000";
    auto h = client(server.port()).Get("/api/v1/health");
    ASSERT_TRUE(h);
    EXPECT_EQ(h->status, 200);
}

} // namespace
