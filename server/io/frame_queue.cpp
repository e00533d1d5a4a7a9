// The bounded frame-writing queue. See frame_queue.hpp.
#include "io/frame_queue.hpp"

#include <algorithm>
#include <exception>

namespace dermis {

FrameWriteQueue::FrameWriteQueue(int threads, std::size_t capacity)
    : capacity_(std::max<std::size_t>(1, capacity)) {
    for (int k = 0; k < std::max(1, threads); ++k)
        workers_.emplace_back([this] { work(); });
}

FrameWriteQueue::~FrameWriteQueue() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        stopping_ = true;
        jobs_.clear();
    }
    changed_.notify_all();
    for (std::thread& t : workers_)
        t.join();
}

void FrameWriteQueue::work() {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
        changed_.wait(lock, [&] { return stopping_ || !jobs_.empty(); });
        if (jobs_.empty()) return; // stopping
        std::function<Status()> job = std::move(jobs_.front());
        jobs_.pop_front();
        ++running_;
        changed_.notify_all(); // room for the producer
        lock.unlock();
        Status s = Ok{};
        try {
            s = job();
        } catch (const std::exception& e) {
            s = makeError(ErrorCode::Internal, "dermis::FrameWriteQueue", "",
                          std::string("a frame job threw: ") + e.what());
        }
        lock.lock();
        --running_;
        if (!s && !error_) {
            error_ = s.error();
            jobs_.clear(); // no further job starts
        }
        changed_.notify_all();
    }
}

Status FrameWriteQueue::push(std::function<Status()> job) {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [&] { return error_ || jobs_.size() < capacity_; });
    if (error_) return *error_;
    jobs_.push_back(std::move(job));
    changed_.notify_all();
    return Ok{};
}

Status FrameWriteQueue::finish() {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [&] { return jobs_.empty() && running_ == 0; });
    if (error_) return *error_;
    return Ok{};
}

} // namespace dermis
