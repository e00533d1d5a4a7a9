// Dermis io shell — a bounded queue of frame-writing jobs run on worker threads, so that an
// animation range encodes and writes frame k while the renderer draws frame k+1
// (`dermis-server render --frames`): render thread → this queue (at most `capacity` frames
// waiting, so memory stays bounded when encoding is slower than rendering) → `threads` workers,
// each job typically encodeFrame + writeFileAtomically (frame_io.hpp). The bytes of each file
// do not depend on the threads: the encoders are deterministic.
//
// Jobs run in any order across workers. After the first failing job no further job starts:
// push and finish return that first error (the others are dropped). Not copyable; the destructor
// waits for the running jobs (and drops the waiting ones if finish was not called). push and
// finish are called from one producer thread.
#pragma once

#include "core/result.hpp"

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

namespace dermis {

class FrameWriteQueue {
public:
    /// `threads` ≥ 1 workers, `capacity` ≥ 1 jobs waiting at most (both clamped to ≥ 1).
    FrameWriteQueue(int threads, std::size_t capacity);
    ~FrameWriteQueue();
    FrameWriteQueue(const FrameWriteQueue&) = delete;
    FrameWriteQueue& operator=(const FrameWriteQueue&) = delete;

    /// Queues a job, blocking while `capacity` jobs wait. Returns the first error of any job so
    /// far (the job is then not queued), else Ok.
    Status push(std::function<Status()> job);
    /// Waits until every queued job has run; the first error, else Ok.
    Status finish();

private:
    void work();
    std::mutex mutex_;
    std::condition_variable changed_;
    std::deque<std::function<Status()>> jobs_;
    std::size_t capacity_;
    std::size_t running_ = 0;
    bool stopping_ = false;
    std::optional<Error> error_;
    std::vector<std::thread> workers_;
};

} // namespace dermis
