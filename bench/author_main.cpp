// dermis-authorbench — the authoring API (SPEC §6) on a scene with a long history, over HTTP on
// loopback; prints JSON. Usage: dermis-authorbench [--revisions N] [--repeat N] [--gl BACKEND]
// [--big-revisions N] [--big-placements N] (default 10,000 revisions, 50 requests per figure; a
// 1,000-placement scene with 10,000 revisions; --big-revisions 0 leaves it out).
//
// Starts the server in-process (Service + Api on 127.0.0.1, a temporary data folder), creates a
// small scene on the default character and edits it until it has N revisions (through the Service
// directly: every one written durably, as over HTTP), then measures p50/p99 over loopback:
//  * scene_read (GET /scenes/{id}), revision_read (GET ?revision=k, k spread over the history,
//    read from disk), revisions_page (GET /revisions?limit=50, newest and from the middle);
//  * edit (PATCH a placement with If-Match), revert (POST /revert to an old revision);
//  * probe (GET /probe at the elbow crease), activation (GET /activation of elbow_curl at 30 fps),
//    lint of the default pattern set (18 placements, 7 clips), pick of a 512² frame's pixel,
//    sweep of the left elbow crease (64 steps as JSON; a 3×3 contact sheet of 160² cells, 9 GL
//    renders), a 256² JPEG frame without and with ?revision= (the current one, as the editor
//    sends it), drivers with ?revision=, mirror of the left elbow crease (its twin deleted,
//    untimed, before each);
//  * edit_if_match_rebased: the same PATCH with an If-Match one revision old, another client
//    having changed the pose meanwhile (rebased);
//  * big_history (issue #27.4): a scene of --big-placements placements edited one placement at a
//    time until it has --big-revisions revisions: bytes its history takes on disk per edit (files'
//    sizes, and the blocks they hold), the time of an edit while filling; then revision_read_big
//    (GET ?revision=k, k spread over that history: its chunk's snapshot plus up to 255 patches),
//    revision_read_big_service (Service::getSceneRevision, without HTTP and the answer's text)
//    and edit_big (PATCH one placement with If-Match);
//  * reopen_ms: Service::open of the data folder with that history.
#include "http/api.hpp"
#include "service/service.hpp"

#include "bench_stats.hpp"

#include <httplib.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <iostream>
#include <random>
#include <thread>
#include <sys/stat.h>
#include <unistd.h>

using namespace dermis;
using json = nlohmann::json;

namespace {

using bench::Clock;
using bench::ms;

const json kScene = json::parse(R"({
  "format": "dermis.scene/1", "model": "builtin:default", "heightmap": {"size": [256, 256]},
  "placements": [{"id": "elbow", "pattern": "crease", "center": [0.3, 0.4], "scale": [0.08, 0.05],
                  "joint": "forearm.l", "axis": "x", "theta_min": 0, "theta_max": 120}],
  "render": {"size": [128, 128], "msaa": 1}})");

/// A scene of `n` placements of the crease, spread over the UV square.
json bigScene(int n) {
    json doc = kScene;
    doc["placements"] = json::array();
    for (int k = 0; k < n; ++k)
        doc["placements"].push_back({{"id", "p" + std::to_string(k)}, {"pattern", "crease"},
                                     {"center", {0.02 + 0.96 * (k % 40) / 40.0, 0.02 + 0.96 * (k / 40 % 40) / 40.0}},
                                     {"scale", {0.02, 0.02}}, {"joint", "forearm.l"}, {"axis", "x"},
                                     {"theta_min", 0}, {"theta_max", 120}});
    return doc;
}

/// Bytes of the files under `dir`, and bytes of the blocks they hold.
std::pair<double, double> folderBytes(const std::filesystem::path& dir) {
    double bytes = 0, blocks = 0;
    std::error_code ec;
    for (const auto& e : std::filesystem::recursive_directory_iterator(dir, ec)) {
        struct stat st {};
        if (!e.is_regular_file() || ::stat(e.path().c_str(), &st) != 0) continue;
        bytes += static_cast<double>(st.st_size);
        blocks += static_cast<double>(st.st_blocks) * 512.0;
    }
    return {bytes, blocks};
}

} // namespace

int main(int argc, char** argv) {
    int revisions = 10000, repeat = 50, bigRevisions = 10000, bigPlacements = 1000;
    GlBackend backend = GlBackend::Auto;
    for (int i = 1; i < argc; ++i) {
        if (std::strcmp(argv[i], "--revisions") == 0 && i + 1 < argc) {
            revisions = std::max(10, std::atoi(argv[++i]));
        } else if (std::strcmp(argv[i], "--repeat") == 0 && i + 1 < argc) {
            repeat = std::max(5, std::atoi(argv[++i]));
        } else if (std::strcmp(argv[i], "--big-revisions") == 0 && i + 1 < argc) {
            bigRevisions = std::max(0, std::atoi(argv[++i]));
        } else if (std::strcmp(argv[i], "--big-placements") == 0 && i + 1 < argc) {
            bigPlacements = std::clamp(std::atoi(argv[++i]), 1, 100000);
        } else if (std::strcmp(argv[i], "--gl") == 0 && i + 1 < argc) {
            auto b = glBackendFromString(argv[++i]);
            if (!b) return 2;
            backend = *b;
        } else {
            std::cerr << "usage: dermis-authorbench [--revisions N] [--repeat N] [--gl BACKEND] "
                         "[--big-revisions N] [--big-placements N]\n";
            return 2;
        }
    }
    const std::filesystem::path data = std::filesystem::temp_directory_path() /
                                       ("dermis-authorbench-" + std::to_string(::getpid()));
    ServerLimits limits;
    limits.maxPlacements = std::max<std::size_t>(limits.maxPlacements, static_cast<std::size_t>(bigPlacements));
    auto service = Service::open(data.string(), backend, limits);
    if (!service) {
        std::cerr << service.error().message << "\n";
        return 1;
    }
    auto created = (*service)->createScene(kScene);
    if (!created) {
        std::cerr << created.error().message << "\n";
        return 1;
    }
    const std::string id = (*created)["id"];
    const auto fill0 = Clock::now();
    for (int r = 2; r <= revisions; ++r) {
        auto e = (*service)->patchPlacement(id, "elbow", {{"h", 1.0 + (r % 50) * 0.01}},
                                            EditContext{{}, "bench"});
        if (!e) {
            std::cerr << e.error().message << "\n";
            return 1;
        }
    }
    const double fillMs = ms(fill0, Clock::now());

    // The big scene: one placement moved per revision, as an editor's drags do.
    json big = {{"revisions", bigRevisions}, {"placements", bigPlacements}};
    std::string bigId;
    if (bigRevisions > 1) {
        auto made = (*service)->createScene(bigScene(bigPlacements));
        if (!made) {
            std::cerr << made.error().message << "\n";
            return 1;
        }
        bigId = (*made)["id"];
        std::mt19937 rng(27);
        std::uniform_real_distribution<double> u(0.05, 0.95);
        const auto t0 = Clock::now();
        for (int r = 2; r <= bigRevisions; ++r) {
            auto e = (*service)->patchPlacement(bigId, "p" + std::to_string(rng() % bigPlacements),
                                                {{"center", {u(rng), u(rng)}}}, EditContext{{}, "bench"});
            if (!e) {
                std::cerr << e.error().message << "\n";
                return 1;
            }
        }
        const auto [bytes, blocks] = folderBytes(data / "scenes" / (bigId + ".history"));
        big["fill_ms_per_edit"] = std::round(ms(t0, Clock::now()) / (bigRevisions - 1) * 100) / 100;
        big["document_bytes"] = (*service)->getScene(bigId).value()["scene"].dump().size();
        big["history_bytes_per_edit"] = std::round(bytes / bigRevisions);
        big["history_block_bytes_per_edit"] = std::round(blocks / bigRevisions);
    }

    ApiOptions opt;
    opt.port = 0;
    auto api = std::make_unique<Api>(**service, opt);
    auto port = api->bind();
    if (!port) {
        std::cerr << port.error().message << "\n";
        return 1;
    }
    std::thread serverThread([&] { api->run(); });
    httplib::Client c("127.0.0.1", *port);
    c.set_keep_alive(true);
    c.set_tcp_nodelay(true);
    c.set_read_timeout(60, 0);
    const std::string base = "/api/v1/scenes/" + id;
    json results = json::array();
    bool failed = false;
    // `setup(r)`, when given, runs before each request, untimed.
    auto measure = [&](const char* name, const std::function<bool(int)>& request,
                       const std::function<void(int)>& setup = nullptr) {
        std::vector<double> lat;
        for (int r = 0; r <= repeat && !failed; ++r) {
            if (setup) setup(r);
            const auto t0 = Clock::now();
            if (!request(r)) {
                failed = true;
                std::cerr << name << ": request " << r << " failed\n";
            }
            if (r > 0) lat.push_back(ms(t0, Clock::now()));
        }
        if (failed) return;
        json j = bench::percentiles(lat, 3);
        j["name"] = name;
        j["revisions"] = revisions;
        results.push_back(j);
    };
    auto ok = [](const httplib::Result& res) {
        if (res && res->status != 200) std::cerr << res->status << " " << res->body << "\n";
        return res && res->status == 200;
    };
    measure("scene_read", [&](int) { return ok(c.Get(base)); });
    measure("revision_read", [&](int r) {
        const int k = 1 + (r * 7919) % (revisions - 1);
        return ok(c.Get(base + "?revision=" + std::to_string(k)));
    });
    if (!bigId.empty()) {
        const std::string bigBase = "/api/v1/scenes/" + bigId;
        measure("revision_read_big", [&](int r) {
            const int k = 1 + (r * 7919) % (bigRevisions - 1);
            return ok(c.Get(bigBase + "?revision=" + std::to_string(k)));
        });
        results.back()["revisions"] = bigRevisions;
        measure("revision_read_big_service", [&](int r) {
            const int k = 1 + (r * 104729) % (bigRevisions - 1);
            return static_cast<bool>((*service)->getSceneRevision(bigId, static_cast<std::uint64_t>(k)));
        });
        results.back()["revisions"] = bigRevisions;
        std::uint64_t bigCurrent = static_cast<std::uint64_t>(bigRevisions);
        measure("edit_big", [&](int r) {
            httplib::Headers h{{"If-Match", "\"r" + std::to_string(bigCurrent) + "\""},
                               {"X-Dermis-Client", "bench"}};
            auto res = c.Patch(bigBase + "/placements/p" + std::to_string(r % bigPlacements), h,
                               json{{"center", {0.5, 0.3 + 0.001 * r}}}.dump(), "application/json");
            ++bigCurrent;
            return ok(res);
        });
        results.back()["revisions"] = bigRevisions;
    }
    measure("revisions_page_newest", [&](int) { return ok(c.Get(base + "/revisions?limit=50")); });
    measure("revisions_page_middle", [&](int) {
        return ok(c.Get(base + "/revisions?limit=50&before=" + std::to_string(revisions / 2)));
    });
    measure("probe", [&](int r) {
        return ok(c.Get(base + "/probe?u=" + std::to_string(0.28 + 0.001 * (r % 40)) + "&v=0.4"));
    });
    measure("activation_elbow_curl_30fps", [&](int) {
        return ok(c.Get(base + "/activation?clip=elbow_curl&fps=30"));
    });
    auto full = (*service)->createScene({{"default_patterns", true}});
    if (!full) {
        std::cerr << full.error().message << "\n";
        return 1;
    }
    const std::string fullBase = "/api/v1/scenes/" + (*full)["id"].get<std::string>();
    measure("lint_default_scene", [&](int) { return ok(c.Get(fullBase + "/lint")); });
    measure("sweep_json_elbow_64", [&](int) {
        return ok(c.Get(fullBase + "/sweep?placement=elbow_l&steps=64&format=json"));
    });
    measure("sweep_sheet_elbow_9x160", [&](int) {
        return ok(c.Get(fullBase + "/sweep?placement=elbow_l&steps=9&size=160&msaa=1"));
    });
    measure("pick_512", [&](int r) {
        return ok(c.Get(fullBase + "/pick?width=512&height=512&x=" + std::to_string(200 + r % 100) + "&y=200"));
    });
    const auto fullRead = c.Get(fullBase);
    const std::string fullRevision =
        fullRead && fullRead->status == 200
            ? std::to_string(json::parse(fullRead->body)["revision"].get<std::uint64_t>())
            : "1";
    measure("frame_256_jpeg", [&](int r) {
        return ok(c.Get(fullBase + "/frame?format=jpeg&width=256&height=256&msaa=1&yaw=" +
                        std::to_string(r % 40)));
    });
    measure("frame_256_jpeg_revision_current", [&](int r) { // what the editor sends
        return ok(c.Get(fullBase + "/frame?format=jpeg&width=256&height=256&msaa=1&yaw=" +
                        std::to_string(r % 40) + "&revision=" + fullRevision));
    });
    measure("drivers_revision_current", [&](int r) {
        return ok(c.Get(fullBase + "/drivers?time=" + std::to_string(0.01 * (r % 100)) +
                        "&revision=" + fullRevision));
    });
    // The twin is deleted (untimed) before each mirror: mirroring onto an existing twin is a 409.
    measure(
        "mirror_placement",
        [&](int) {
            auto res = c.Post(fullBase + "/placements/elbow_l/mirror", "", "application/json");
            return res && res->status == 201;
        },
        [&](int) { c.Delete(fullBase + "/placements/elbow_r"); });
    std::uint64_t current = static_cast<std::uint64_t>(revisions);
    measure("edit_if_match", [&](int r) {
        httplib::Headers h{{"If-Match", "\"r" + std::to_string(current) + "\""},
                           {"X-Dermis-Client", "bench"}};
        auto res = c.Patch(base + "/placements/elbow", h, json{{"h", 1.0 + r * 0.001}}.dump(),
                           "application/json");
        ++current;
        return ok(res);
    });
    // Two clients: before each timed PATCH of the elbow (If-Match: the revision of this client's
    // own last answer), another client changes the pose (untimed), so every If-Match is one
    // revision behind and is rebased (the base document from the recent revisions in memory).
    std::uint64_t mine = current;
    measure(
        "edit_if_match_rebased",
        [&](int r) {
            httplib::Headers h{{"If-Match", "\"r" + std::to_string(mine) + "\""},
                               {"X-Dermis-Client", "bench"}};
            auto res = c.Patch(base + "/placements/elbow", h, json{{"h", 1.0 + r * 0.001}}.dump(),
                               "application/json");
            if (!ok(res)) return false;
            mine = current = json::parse(res->body)["revision"].get<std::uint64_t>();
            return true;
        },
        [&](int r) {
            c.Patch(base + "/pose", json{{"time", 0.01 * (r % 100)}}.dump(), "application/json");
            ++current;
        });
    measure("revert", [&](int r) {
        auto res = c.Post(base + "/revert", json{{"revision", 1 + (r * 13) % revisions}}.dump(), "application/json");
        ++current;
        return ok(res);
    });
    api->stop();
    serverThread.join();
    api.reset(); // before the service it serves
    service->reset();
    const auto open0 = Clock::now();
    auto reopened = Service::open(data.string(), backend, limits);
    const double reopenMs = ms(open0, Clock::now());
    const bool reopenOk = reopened && (*reopened)->getScene(id);
    reopened = makeError(ErrorCode::Internal, "", "", "closed");
    std::error_code ec;
    std::filesystem::remove_all(data, ec);
    if (failed || !reopenOk) std::cerr << "a request failed (the figures before it follow)\n";
    std::cout << json{{"benchmark", "dermis-authorbench"},
                      {"revisions", revisions},
                      {"fill_ms_per_edit", std::round(fillMs / (revisions - 1) * 1000) / 1000},
                      {"reopen_ms", std::round(reopenMs * 10) / 10},
                      {"big_history", big},
                      {"hardware_threads", std::thread::hardware_concurrency()},
                      {"results", results}}
                     .dump(2)
              << "\n";
    return failed || !reopenOk ? 1 : 0;
}
