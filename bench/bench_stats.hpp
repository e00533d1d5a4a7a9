// Benchmark helpers shared by dermis-loadbench and dermis-authorbench: elapsed milliseconds and
// the p50/p99 summary every figure prints.
#pragma once

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <vector>

namespace dermis::bench {

using Clock = std::chrono::steady_clock;

inline double ms(Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double, std::milli>(b - a).count();
}

/// {"p50_ms", "p99_ms", "requests"} of latencies in ms (nearest rank), rounded to `decimals`.
/// Precondition: `v` is not empty.
inline nlohmann::json percentiles(std::vector<double> v, int decimals = 2) {
    std::sort(v.begin(), v.end());
    const double scale = std::pow(10.0, decimals);
    auto at = [&](double q) {
        const std::size_t i = std::min(
            v.size() - 1, static_cast<std::size_t>(std::ceil(q * static_cast<double>(v.size()))) - 1);
        return std::round(v[i] * scale) / scale;
    };
    return {{"p50_ms", at(0.5)}, {"p99_ms", at(0.99)}, {"requests", v.size()}};
}

} // namespace dermis::bench
