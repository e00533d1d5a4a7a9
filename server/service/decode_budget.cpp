// One budget for the memory of image decodes in flight (see the header).
#include "service/decode_budget.hpp"

#include <algorithm>

namespace dermis {

DecodeBudget::DecodeBudget(std::size_t bytes) : capacity_(std::max<std::size_t>(bytes, 1)) {}

DecodeBudget::Lease::~Lease() {
    if (budget_) budget_->release(bytes_);
}

Result<DecodeBudget::Lease> DecodeBudget::reserve(std::size_t bytes, std::chrono::milliseconds wait,
                                                   const std::string& field) {
    const std::size_t n = std::min(std::max<std::size_t>(bytes, 1), capacity_);
    std::unique_lock<std::mutex> lock(mutex_);
    if (!freed_.wait_for(lock, wait, [&] { return used_ + n <= capacity_; })) {
        ++refused_;
        return makeError(ErrorCode::Unavailable, "dermis::DecodeBudget", field,
                         "the server is decoding other images (" + std::to_string(used_ >> 20) + " of " +
                             std::to_string(capacity_ >> 20) + " MB of its decode budget in use); retry shortly");
    }
    used_ += n;
    peak_ = std::max(peak_, used_);
    return Lease(this, n);
}

void DecodeBudget::release(std::size_t bytes) {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        used_ -= std::min(used_, bytes);
    }
    freed_.notify_all();
}

std::size_t DecodeBudget::inUse() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return used_;
}

std::size_t DecodeBudget::peak() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return peak_;
}

std::size_t DecodeBudget::refused() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return refused_;
}

} // namespace dermis
