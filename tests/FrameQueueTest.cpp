// FrameQueueTest — the bounded frame-writing queue: every job runs once, at most `capacity` wait,
// the first error stops further jobs and is returned by push and finish.
#include "io/frame_queue.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

using namespace dermis;

TEST(FrameQueueTest, RunsEveryJobOnce) {
    std::atomic<int> sum{0};
    FrameWriteQueue q(2, 3);
    for (int k = 1; k <= 100; ++k)
        ASSERT_TRUE(q.push([&sum, k]() -> Status {
            sum += k;
            return Ok{};
        }));
    ASSERT_TRUE(q.finish());
    EXPECT_EQ(sum.load(), 5050);
}

TEST(FrameQueueTest, PushBlocksWhileTheQueueIsFull) {
    std::atomic<bool> release{false};
    std::atomic<int> waitingMax{0}, started{0};
    FrameWriteQueue q(1, 2);
    std::thread producer([&] {
        for (int k = 0; k < 6; ++k)
            (void)q.push([&]() -> Status {
                ++started;
                while (!release) std::this_thread::sleep_for(std::chrono::milliseconds(1));
                return Ok{};
            });
    });
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    // One job running, two waiting: the producer is blocked on the fourth.
    EXPECT_EQ(started.load(), 1);
    release = true;
    producer.join();
    ASSERT_TRUE(q.finish());
    EXPECT_EQ(started.load(), 6);
}

TEST(FrameQueueTest, TheFirstErrorStopsFurtherJobs) {
    std::atomic<int> ran{0};
    FrameWriteQueue q(1, 1);
    ASSERT_TRUE(q.push([]() -> Status {
        return makeError(ErrorCode::Io, "job", "frame_0001.png", "disk full");
    }));
    Status last = Ok{};
    for (int k = 0; k < 50 && last; ++k)
        last = q.push([&]() -> Status {
            ++ran;
            return Ok{};
        });
    Status done = q.finish();
    ASSERT_FALSE(done);
    EXPECT_EQ(done.error().field, "frame_0001.png");
    EXPECT_LT(ran.load(), 50); // push reported the error and the producer stopped
}
