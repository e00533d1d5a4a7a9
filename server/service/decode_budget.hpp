// Dermis service — one budget for the memory of image decodes in flight (issue #27: a small file
// declaring a large image made every concurrent upload decode hundreds of MB at once). Each
// decode reserves the bytes it may need before it starts (a lease, given back when it ends); a
// reservation that does not fit waits for others to end, up to a deadline, and is then refused
// (Unavailable: the HTTP layer answers 503 with Retry-After). Pure C++: no image library here.
// Thread-safe (one mutex, one condition variable).
#pragma once

#include "core/result.hpp"

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <memory>
#include <mutex>

namespace dermis {

class DecodeBudget {
public:
    /// `bytes` in all (at least 1).
    explicit DecodeBudget(std::size_t bytes);

    /// Bytes reserved until destroyed.
    class Lease {
    public:
        Lease() = default;
        Lease(Lease&& o) noexcept : budget_(o.budget_), bytes_(o.bytes_) { o.budget_ = nullptr; }
        Lease& operator=(Lease&&) = delete;
        ~Lease();
        std::size_t bytes() const { return bytes_; }

    private:
        friend class DecodeBudget;
        Lease(DecodeBudget* b, std::size_t n) : budget_(b), bytes_(n) {}
        DecodeBudget* budget_ = nullptr;
        std::size_t bytes_ = 0;
    };

    /// Reserves `bytes` (a request over the whole budget asks for the whole budget: it runs
    /// alone), waiting up to `wait` for room. Unavailable (field `field`) when there was none.
    Result<Lease> reserve(std::size_t bytes, std::chrono::milliseconds wait, const std::string& field);

    std::size_t capacity() const { return capacity_; }
    std::size_t inUse() const;
    std::size_t peak() const;     ///< the most ever reserved at once
    std::size_t refused() const;  ///< reservations refused so far

private:
    void release(std::size_t bytes);
    const std::size_t capacity_;
    mutable std::mutex mutex_;
    std::condition_variable freed_;
    std::size_t used_ = 0, peak_ = 0, refused_ = 0;
};

} // namespace dermis
