// Dermis core — the one way the core splits an image-shaped job over threads: contiguous bands
// of rows, one short-lived std::thread per band, joined before returning. Used by the height-map
// bake, the rest-surface bake, the environment prefilter and the edge pass.
//
// Pure: standard library only. Not a pool: each call starts its threads and joins them (the jobs
// it serves take milliseconds or more, so thread start-up is noise). Does not balance load
// between bands; a body whose rows cost unevenly gets uneven bands.
#pragma once

#include <algorithm>
#include <system_error>
#include <thread>
#include <vector>

namespace dermis {

/// The number of threads a "0 = automatic" setting means: hardware_concurrency, at least 1.
inline int automaticThreadCount() {
    return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

/// Runs body(band, y0, y1) for band = 0 … bands-1 over [0, rows) split into `bands` contiguous
/// bands (y1 of one is y0 of the next; sizes differ by at most one row), and waits for all of
/// them. `bands` is clamped to [1, rows]; nothing runs when rows <= 0. The last band runs on the
/// calling thread; so does any band whose thread cannot start (std::system_error), so the work is
/// always done and, for bands that are independent of each other, the result never depends on
/// how many threads ran. `body` is called concurrently and must be safe for that; it must not
/// throw on another thread (that terminates, as any std::thread does). What it throws on the
/// calling thread propagates after every started thread has been joined.
template <class F>
void forRowBands(int rows, int bands, const F& body) {
    if (rows <= 0) return;
    bands = std::clamp(bands, 1, rows);
    const auto edge = [&](int k) { return static_cast<int>(static_cast<long long>(rows) * k / bands); };
    std::vector<std::thread> pool;
    pool.reserve(static_cast<std::size_t>(bands - 1));
    int started = 0;
    try {
        for (; started + 1 < bands; ++started) {
            const int k = started;
            pool.emplace_back([&body, k, y0 = edge(k), y1 = edge(k + 1)] { body(k, y0, y1); });
        }
    } catch (const std::system_error&) { // no more threads: the rest run here
    }
    try {
        for (int k = started; k < bands; ++k)
            body(k, edge(k), edge(k + 1));
    } catch (...) {
        for (std::thread& t : pool)
            t.join();
        throw;
    }
    for (std::thread& t : pool)
        t.join();
}

} // namespace dermis
