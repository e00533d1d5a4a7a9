// dermis-bench — prints JSON figures (median milliseconds) for the paper's headline scenario:
// 15 placements in texture space, CPU height maps at 1024² and 2048², one thread and all threads.
// Usage: dermis-bench [--repeat N]   (default 15 repetitions after one warm-up run)
//
// Patterns are synthetic 512² smooth height fields (the built-in library's size); footprints
// cover 0.08–0.3 of the UV square each, rotated, as in a dressed character.
#include "core/heightmap.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <random>
#include <thread>

using namespace dermis;

namespace {

HeightImage makePattern(int n, unsigned seed) {
    HeightImage img(n, n);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> f(2, 9), ph(0, 6.28);
    const double fx = f(rng), fy = f(rng), p = ph(rng);
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const double x = (i + 0.5) / n, y = (j + 0.5) / n;
            const double window = std::sin(M_PI * x) * std::sin(M_PI * y);
            img.at(i, j) = static_cast<float>(window * std::sin(fx * x * 6.28 + p) *
                                              std::cos(fy * y * 3.14));
        }
    return img;
}

double medianMs(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

} // namespace

int main(int argc, char** argv) {
    int repeat = 15;
    for (int i = 1; i + 1 < argc; ++i)
        if (std::strcmp(argv[i], "--repeat") == 0) repeat = std::max(1, std::atoi(argv[i + 1]));

    std::vector<HeightImage> patterns;
    for (unsigned k = 0; k < 8; ++k) patterns.push_back(makePattern(512, k + 1));
    std::mt19937 rng(42);
    std::uniform_real_distribution<double> u(0.15, 0.85), sc(0.08, 0.3), rot(-90, 90), t(0.2, 1.0);
    std::vector<BakePlacement> placements;
    for (int k = 0; k < 15; ++k) {
        BakePlacement p;
        p.pattern = &patterns[k % patterns.size()];
        p.footprint.center = {u(rng), u(rng)};
        p.footprint.scale = {sc(rng), sc(rng)};
        p.footprint.rotationDeg = rot(rng);
        p.model = k % 5 == 4 ? DeformModel::Bias : DeformModel::Scale;
        p.target = k % 4 == 3 ? Target::Displacement : Target::Bump;
        p.t = t(rng);
        placements.push_back(p);
    }

    const int hw = std::max(1u, std::thread::hardware_concurrency());
    nlohmann::json cases = nlohmann::json::array();
    for (int size : {1024, 2048})
        for (int threads : {1, hw}) {
            BakeSettings s;
            s.width = s.height = size;
            s.threads = threads;
            // Steady state of a per-frame loop: the maps' storage is reused (bakeHeightMapsInto),
            // so the figure is the bake itself, not the allocator's page faults.
            std::vector<double> ms;
            HeightMaps maps;
            for (int r = 0; r <= repeat; ++r) {
                const auto t0 = std::chrono::steady_clock::now();
                auto status = bakeHeightMapsInto(placements, s, maps);
                const auto t1 = std::chrono::steady_clock::now();
                if (!status) {
                    std::cerr << status.error().message << "\n";
                    return 1;
                }
                if (r > 0) ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
            }
            cases.push_back({{"name", "cpu_heightmaps"},
                             {"size", size},
                             {"placements", placements.size()},
                             {"threads", threads},
                             {"median_ms", std::round(medianMs(ms) * 100) / 100},
                             {"min_ms", std::round(*std::min_element(ms.begin(), ms.end()) * 100) / 100},
                             {"repetitions", ms.size()}});
        }
    nlohmann::json out = {{"benchmark", "dermis"},
                          {"hardware_threads", hw},
                          {"results", cases}};
    std::cout << out.dump(2) << "\n";
    return 0;
}
