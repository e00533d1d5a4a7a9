// RowBandsTest — forRowBands (core/row_bands.hpp), the core's one split of rows over threads. Pure.
#include "core/row_bands.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>
#include <tuple>
#include <vector>

using namespace dermis;

namespace {
/// The (band, y0, y1) calls of forRowBands(rows, bands, …), sorted by band.
std::vector<std::tuple<int, int, int>> calls(int rows, int bands) {
    std::mutex m;
    std::set<std::tuple<int, int, int>> seen;
    forRowBands(rows, bands, [&](int band, int y0, int y1) {
        std::lock_guard<std::mutex> lock(m);
        seen.emplace(band, y0, y1);
    });
    return {seen.begin(), seen.end()};
}
} // namespace

TEST(RowBandsTest, BandsTileTheRowsInOrderWithSizesWithinOneRow) {
    for (int rows : {1, 2, 7, 16, 1000, 1023})
        for (int bands : {1, 2, 3, 8}) {
            const auto c = calls(rows, bands);
            ASSERT_EQ(c.size(), static_cast<std::size_t>(std::min(rows, bands))) << rows << " rows, " << bands;
            int next = 0, smallest = rows, largest = 0;
            for (std::size_t k = 0; k < c.size(); ++k) {
                const auto [band, y0, y1] = c[k];
                EXPECT_EQ(band, static_cast<int>(k));
                EXPECT_EQ(y0, next) << "band " << band << " of " << rows << " rows";
                EXPECT_LT(y0, y1);
                smallest = std::min(smallest, y1 - y0);
                largest = std::max(largest, y1 - y0);
                next = y1;
            }
            EXPECT_EQ(next, rows);
            EXPECT_LE(largest - smallest, 1);
        }
}

TEST(RowBandsTest, ClampsBandsAndDoesNothingWithoutRows) {
    EXPECT_EQ(calls(5, 0), (std::vector<std::tuple<int, int, int>>{{0, 0, 5}}));
    EXPECT_EQ(calls(5, -3), (std::vector<std::tuple<int, int, int>>{{0, 0, 5}}));
    EXPECT_EQ(calls(3, 64).size(), 3u);
    EXPECT_TRUE(calls(0, 4).empty());
    EXPECT_TRUE(calls(-2, 4).empty());
}

TEST(RowBandsTest, TheLastBandRunsOnTheCallingThreadAndTheOthersDoNot) {
    const std::thread::id caller = std::this_thread::get_id();
    std::atomic<int> onCaller{0}, lastOnCaller{0};
    forRowBands(64, 4, [&](int band, int, int) {
        if (std::this_thread::get_id() == caller) {
            ++onCaller;
            if (band == 3) ++lastOnCaller;
        }
    });
    EXPECT_EQ(onCaller.load(), 1);
    EXPECT_EQ(lastOnCaller.load(), 1);
}

TEST(RowBandsTest, WhatTheCallingThreadsBandThrowsArrivesAfterTheOthersFinish) {
    std::atomic<int> finished{0};
    const std::thread::id caller = std::this_thread::get_id();
    EXPECT_THROW(forRowBands(64, 4,
                             [&](int, int, int) {
                                 if (std::this_thread::get_id() == caller) throw std::runtime_error("band");
                                 std::this_thread::sleep_for(std::chrono::milliseconds(20));
                                 ++finished;
                             }),
                 std::runtime_error);
    EXPECT_EQ(finished.load(), 3); // joined, not abandoned (that would terminate)
}
