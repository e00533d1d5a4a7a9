// EventsHttpTest — a scene's server-sent events (/api/v1/scenes/{id}/events) end to end on one
// server (HttpTestFixture.hpp: a real dermis::Service + dermis::Api on 127.0.0.1, a GL context on
// $DERMIS_TEST_GL, cpp-httplib clients over loopback). It checks:
//   * server-sent events: hello, then one change event per edit with increasing revisions; the
//     stream ends when the scene is deleted;
//   * back-pressure: event streams beyond half the HTTP threads are refused (503) so that /health
//     still answers.
#include "HttpTestFixture.hpp"

using namespace dermis;
using namespace dermis::test;
using namespace dermis::test::http;

namespace {

/// One server (no token).
class EventsHttpTest : public SharedServerTest {};

// ================================================================================================
// Server-sent events
// ================================================================================================

TEST_F(EventsHttpTest, EventsStreamHelloAndOneChangePerEdit) {
    Http h = http();
    const std::string id = createScene(smallScene());
    ASSERT_FALSE(id.empty());

    std::mutex mutex;
    std::condition_variable cv;
    std::string received;
    std::atomic<bool> stop{false};
    int streamStatus = 0;
    std::thread reader([&] {
        httplib::Client cli("127.0.0.1", server_->port());
        cli.set_read_timeout(30, 0);
        auto res = cli.Get(
            kApi + "/scenes/" + id + "/events",
            [&](const httplib::Response& r) {
                std::lock_guard<std::mutex> lock(mutex);
                streamStatus = r.status;
                return r.status == 200;
            },
            [&](const char* data, std::size_t n) {
                {
                    std::lock_guard<std::mutex> lock(mutex);
                    received.append(data, n);
                }
                cv.notify_all();
                return !stop.load();
            });
        (void)res;
        cv.notify_all();
    });
    auto waitFor = [&](auto pred) {
        std::unique_lock<std::mutex> lock(mutex);
        return cv.wait_for(lock, std::chrono::seconds(10), [&] { return pred(received); });
    };
    auto count = [](const std::string& s, const std::string& what) {
        std::size_t n = 0;
        for (std::size_t p = s.find(what); p != std::string::npos; p = s.find(what, p + 1))
            ++n;
        return n;
    };
    const bool hello = waitFor([&](const std::string& s) { return count(s, "event: hello") == 1; });
    EXPECT_TRUE(hello) << received;
    EXPECT_EQ(h.patch("/scenes/" + id + "/pose", {{"time", 0.1}}).status, 200);
    EXPECT_EQ(h.patch("/scenes/" + id + "/placements/elbow", {{"h", 0.5}}).status, 200);
    const bool changes =
        waitFor([&](const std::string& s) { return count(s, "event: change") >= 2; });
    EXPECT_TRUE(changes) << received;
    stop = true;
    reader.join(); // the next ping (≤ 1 s) ends the stream

    EXPECT_EQ(streamStatus, 200);
    // Parse the events: "event: X\ndata: {...}\n\n"; comments (": ping") are skipped.
    std::vector<std::pair<std::string, json>> events;
    std::istringstream in(received);
    std::string line, type;
    while (std::getline(in, line)) {
        if (line.rfind("event: ", 0) == 0)
            type = line.substr(7);
        else if (line.rfind("data: ", 0) == 0)
            events.push_back({type, json::parse(line.substr(6), nullptr, false)});
    }
    ASSERT_GE(events.size(), 3u) << received;
    EXPECT_EQ(events[0].first, "hello");
    EXPECT_EQ(events[0].second["revision"], 1);
    EXPECT_EQ(events[0].second["scene"], id);
    EXPECT_EQ(events[1].first, "change");
    EXPECT_EQ(events[1].second["revision"], 2);
    EXPECT_EQ(events[1].second["type"], "pose");
    EXPECT_EQ(events[2].first, "change");
    EXPECT_EQ(events[2].second["revision"], 3);
    EXPECT_EQ(events[2].second["type"], "placement_updated");
    EXPECT_EQ(events.size(), 3u) << received;

    expectError(h.get("/scenes/s_0000000000000000/events"), 404, "id");
    EXPECT_EQ(h.del("/scenes/" + id).status, 204);
}

TEST_F(EventsHttpTest, EventsStreamEndsWhenTheSceneIsDeleted) {
    Http h = http();
    const std::string id = createScene(smallScene());
    ASSERT_FALSE(id.empty());
    std::atomic<bool> gotHello{false}, ended{false};
    std::string received;
    std::thread reader([&] {
        httplib::Client cli("127.0.0.1", server_->port());
        cli.set_read_timeout(30, 0);
        auto res =
            cli.Get(kApi + "/scenes/" + id + "/events", [&](const char* data, std::size_t n) {
                received.append(data, n);
                if (received.find("event: hello") != std::string::npos) gotHello = true;
                return received.size() < 100000;
            });
        ended = true;
        (void)res;
    });
    for (int i = 0; i < 1000 && !gotHello; ++i)
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    ASSERT_TRUE(gotHello.load());
    EXPECT_EQ(h.del("/scenes/" + id).status, 204);
    for (int i = 0; i < 1000 && !ended; ++i)
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    EXPECT_TRUE(ended.load()) << "the stream did not end within 10 s of the deletion";
    reader.join();
    EXPECT_NE(received.find("\"deleted\""), std::string::npos) << received;
}

TEST_F(EventsHttpTest, EventStreamsCannotTakeEveryHttpThread) {
    // Each open stream holds an HTTP worker thread (the fixture has 24): beyond a cap, streams are
    // refused with 503 so that other requests are still served.
    Http h = http();
    const std::string id = createScene(smallScene());
    ASSERT_FALSE(id.empty());
    constexpr int kStreams = 24;
    std::mutex mutex;
    std::condition_variable cv;
    std::vector<int> statuses(kStreams, 0);
    std::vector<std::string> retryAfter(kStreams);
    std::vector<std::size_t> retryAfters(kStreams, 0); // how many Retry-After headers
    std::atomic<bool> stop{false};
    std::vector<std::thread> readers;
    for (int i = 0; i < kStreams; ++i)
        readers.emplace_back([&, i] {
            httplib::Client cli("127.0.0.1", server_->port());
            cli.set_read_timeout(30, 0);
            auto res = cli.Get(
                kApi + "/scenes/" + id + "/events",
                [&](const httplib::Response& r) {
                    {
                        std::lock_guard<std::mutex> lock(mutex);
                        statuses[static_cast<std::size_t>(i)] = r.status;
                        retryAfter[static_cast<std::size_t>(i)] = r.get_header_value("Retry-After");
                        retryAfters[static_cast<std::size_t>(i)] = r.get_header_value_count("Retry-After");
                    }
                    cv.notify_all();
                    return true;
                },
                [&](const char*, std::size_t) { return !stop.load(); });
            if (!res) {
                std::lock_guard<std::mutex> lock(mutex);
                if (statuses[static_cast<std::size_t>(i)] == 0)
                    statuses[static_cast<std::size_t>(i)] = -1;
            }
            cv.notify_all();
        });
    {
        std::unique_lock<std::mutex> lock(mutex);
        cv.wait_for(lock, std::chrono::seconds(10),
                    [&] { return std::count(statuses.begin(), statuses.end(), 0) == 0; });
    }
    // While the streams are open, the server answers other requests.
    httplib::Client probe("127.0.0.1", server_->port());
    probe.set_read_timeout(5, 0);
    auto health = probe.Get(kApi + "/health");
    EXPECT_TRUE(health && health->status == 200)
        << "GET /health while " << kStreams << " streams are open: "
        << (health ? std::to_string(health->status) : httplib::to_string(health.error()));
    stop = true;
    for (std::thread& t : readers)
        t.join();
    int open = 0, refused = 0;
    for (int i = 0; i < kStreams; ++i) {
        if (statuses[static_cast<std::size_t>(i)] == 200)
            ++open;
        else if (statuses[static_cast<std::size_t>(i)] == 503) {
            ++refused;
            EXPECT_FALSE(retryAfter[static_cast<std::size_t>(i)].empty());
            EXPECT_EQ(retryAfters[static_cast<std::size_t>(i)], 1u) << "one Retry-After";
        } else
            ADD_FAILURE() << "stream " << i << ": status " << statuses[static_cast<std::size_t>(i)];
    }
    EXPECT_GE(open, 1);
    EXPECT_GE(refused, 1);
    EXPECT_EQ(h.del("/scenes/" + id).status, 204);
}

} // namespace
