// dermis-loadbench — the HTTP server under load on loopback, bounded; prints JSON.
// Usage: dermis-loadbench [--repeat N] [--gl BACKEND]   (default 40 requests per figure)
//
// Starts the server in-process (Service + Api on 127.0.0.1, a temporary data folder) with the
// default character and pattern set (1024² maps), then measures with cpp-httplib clients:
//  * edit_to_frame: PATCH the pose (a new time, so the height pass reruns), then GET the frame —
//    p50/p99 ms at 512² and 1024², PNG and JPEG, MSAA off (and 1024² PNG at 4x);
//  * frames_per_second: GET frame loops from 1 and 4 concurrent clients (512², PNG, MSAA off);
//  * heightmap fetch: p50/p99 ms of the displacement map as raw float32 and the bump map as
//    16-bit PNG.
#include "http/api.hpp"
#include "service/service.hpp"

#include "bench_stats.hpp"

#include <httplib.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <random>
#include <thread>

using namespace dermis;
using json = nlohmann::json;

namespace {

using bench::Clock;
using bench::ms;

} // namespace

int main(int argc, char** argv) {
    int repeat = 40;
    GlBackend backend = GlBackend::Auto;
    for (int i = 1; i < argc; ++i) {
        if (std::strcmp(argv[i], "--repeat") == 0 && i + 1 < argc) {
            repeat = std::max(5, std::atoi(argv[++i]));
        } else if (std::strcmp(argv[i], "--gl") == 0 && i + 1 < argc) {
            auto b = glBackendFromString(argv[++i]);
            if (!b) return 2;
            backend = *b;
        } else {
            std::cerr << "usage: dermis-loadbench [--repeat N] [--gl BACKEND]\n";
            return 2;
        }
    }
    const std::filesystem::path data =
        std::filesystem::temp_directory_path() / ("dermis-loadbench-" + std::to_string(::getpid()));
    ServerLimits limits;
    limits.queueLength = 64;
    auto service = Service::open(data.string(), backend, limits);
    if (!service) {
        std::cerr << service.error().message << "\n";
        return 1;
    }
    ApiOptions opt;
    opt.port = 0;
    Api api(**service, opt);
    auto port = api.bind();
    if (!port) {
        std::cerr << port.error().message << "\n";
        return 1;
    }
    std::thread serverThread([&] { api.run(); });
    auto client = [&] {
        auto c = std::make_unique<httplib::Client>("127.0.0.1", *port);
        c->set_keep_alive(true);
        c->set_tcp_nodelay(true); // else a PATCH (headers, then body) waits on the delayed ACK
        c->set_read_timeout(60, 0);
        return c;
    };
    int rc = 0;
    json results = json::array();
    {
        auto c = client();
        auto created = c->Post("/api/v1/scenes", R"({"default_patterns": true})", "application/json");
        if (!created || created->status != 201) {
            std::cerr << "cannot create the scene\n";
            rc = 1;
        } else {
            const std::string sid = json::parse(created->body)["id"];
            const std::string base = "/api/v1/scenes/" + sid;
            int step = 0;
            auto editThenFrame = [&](int size, const char* format, int msaa) {
                std::vector<double> lat;
                for (int r = 0; r <= repeat; ++r) {
                    const auto t0 = Clock::now();
                    const double time = 0.05 * (++step % 40); // the squat moves: joints change
                    auto e = c->Patch(base + "/pose", json{{"time", time}}.dump(), "application/json");
                    auto f = c->Get(base + "/frame?format=" + format + "&width=" + std::to_string(size) +
                                    "&height=" + std::to_string(size) + "&msaa=" + std::to_string(msaa));
                    const auto t1 = Clock::now();
                    if (!e || !f || e->status != 200 || f->status != 200) return json{{"error", "request failed"}};
                    if (r > 0) lat.push_back(ms(t0, t1));
                }
                json j = bench::percentiles(lat);
                j["name"] = "edit_to_frame";
                j["size"] = size;
                j["format"] = format;
                j["msaa"] = msaa;
                return j;
            };
            for (int size : {512, 1024})
                for (const char* format : {"png", "jpeg"})
                    results.push_back(editThenFrame(size, format, 1));
            results.push_back(editThenFrame(1024, "png", 4));

            for (int clients : {1, 4}) {
                std::atomic<int> done{0}, failed{0};
                const int perClient = repeat;
                const auto t0 = Clock::now();
                std::vector<std::thread> threads;
                for (int k = 0; k < clients; ++k)
                    threads.emplace_back([&, k] {
                        auto cc = client();
                        for (int r = 0; r < perClient; ++r) {
                            auto f = cc->Get(base + "/frame?width=512&height=512&msaa=1&yaw=" +
                                             std::to_string((k * 37 + r * 5) % 360));
                            if (f && f->status == 200) ++done;
                            else ++failed;
                        }
                    });
                for (auto& t : threads)
                    t.join();
                const double seconds = ms(t0, Clock::now()) / 1000.0;
                results.push_back({{"name", "frames_per_second"},
                                   {"clients", clients},
                                   {"size", 512},
                                   {"format", "png"},
                                   {"fps", std::round(done / seconds * 10) / 10},
                                   {"frames", done.load()},
                                   {"failed", failed.load()}});
            }
            for (auto [map, format] : {std::pair{"displacement", "f32"}, std::pair{"bump", "png16"}}) {
                std::vector<double> lat;
                for (int r = 0; r <= repeat; ++r) {
                    const auto t0 = Clock::now();
                    auto h = c->Get(base + "/heightmaps/" + map + "?format=" + format);
                    if (!h || h->status != 200) break;
                    if (r > 0) lat.push_back(ms(t0, Clock::now()));
                }
                if (lat.empty()) continue;
                json j = bench::percentiles(lat);
                j["name"] = "heightmap_fetch";
                j["map"] = map;
                j["format"] = format;
                j["size"] = 1024;
                results.push_back(j);
            }
        }
    }
    const json info = (*service)->info();
    api.stop();
    serverThread.join();
    std::error_code ec;
    std::filesystem::remove_all(data, ec);
    if (rc != 0) return rc;
    std::cout << json{{"benchmark", "dermis-loadbench"},
                      {"backend", info["backend"]},
                      {"gl_renderer", info["gl"]["renderer"]},
                      {"hardware_threads", std::thread::hardware_concurrency()},
                      {"results", results}}
                     .dump(2)
              << "\n";
    return 0;
}
