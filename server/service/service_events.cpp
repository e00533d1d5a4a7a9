// Live change events: per-scene subscriptions of typed events (the HTTP layer frames them as
// server-sent events), bounded per reader.
#include "service_state.hpp"

#include <chrono>

namespace dermis {

using namespace detail;

Subscription::Subscription(std::string sceneId) : sceneId_(std::move(sceneId)) {}

std::optional<SceneEvent> Subscription::next(int timeoutMs) {
    std::unique_lock<std::mutex> lock(mutex_);
    cv_.wait_for(lock, std::chrono::milliseconds(timeoutMs), [&] { return closed_ || !events_.empty(); });
    if (events_.empty()) return std::nullopt;
    SceneEvent e = std::move(events_.front());
    events_.pop_front();
    if (events_.empty()) resyncQueued_ = false; // the resync, if any, was the last one queued
    return e;
}

void Subscription::push(SceneEvent event) {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        if (closed_ || resyncQueued_) return; // a reader told to resync re-reads anyway
        if (events_.size() >= kMaxQueued) {
            // The reader is too far behind to catch up event by event: drop what it has not read
            // and tell it to read the scene again.
            events_.clear();
            events_.push_back({"resync", json{{"type", "resync"}, {"scene", sceneId_}}.dump()});
            resyncQueued_ = true;
        } else {
            events_.push_back(std::move(event));
        }
    }
    cv_.notify_all();
}

void Subscription::close() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        closed_ = true;
    }
    cv_.notify_all();
}

bool Subscription::closed() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return closed_;
}

void Service::State::publish(const std::string& sceneId, const json& event, const char* name) {
    const SceneEvent e{name, event.dump()};
    std::lock_guard<std::mutex> lock(subsMutex);
    auto [a, b] = subs.equal_range(sceneId);
    for (auto it = a; it != b; ++it)
        it->second->push(e);
}

Result<std::shared_ptr<Subscription>> Service::subscribe(const std::string& id) {
    std::shared_lock<std::shared_mutex> lock(state_->mutex);
    auto it = state_->scenes.find(id);
    if (it == state_->scenes.end()) return notFound("id", "no scene \"" + id + "\"");
    auto sub = std::make_shared<Subscription>(id);
    sub->push({"hello", json{{"type", "hello"}, {"scene", id}, {"revision", it->second.revision}}.dump()});
    std::lock_guard<std::mutex> sl(state_->subsMutex);
    state_->subs.emplace(id, sub);
    return sub;
}

void Service::unsubscribe(const std::string& id, const std::shared_ptr<Subscription>& s) {
    std::lock_guard<std::mutex> sl(state_->subsMutex);
    auto [a, b] = state_->subs.equal_range(id);
    for (auto it = a; it != b; ++it)
        if (it->second == s) {
            state_->subs.erase(it);
            break;
        }
}

void Service::closeSubscriptions() {
    std::lock_guard<std::mutex> sl(state_->subsMutex);
    for (auto& [id, s] : state_->subs)
        s->close();
    state_->subs.clear();
}

} // namespace dermis
