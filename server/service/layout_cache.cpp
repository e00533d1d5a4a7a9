// Dermis service — generated layouts cached in memory and in the data folder (layout_cache.hpp).
#include "service/layout_cache.hpp"

#include "core/layout_codec.hpp"
#include "io/atomic_file.hpp"

#include <algorithm>
#include <filesystem>

namespace dermis {

LayoutCache::LayoutCache(std::string folder, std::string salt, Generator generate, std::size_t maxEntries)
    : folder_(std::move(folder)), salt_(std::move(salt)), generate_(std::move(generate)),
      maxEntries_(std::max<std::size_t>(1, maxEntries)) {}

std::string LayoutCache::keyOf(const std::shared_ptr<const Model>& model) {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        auto it = keys_.find(model.get());
        if (it != keys_.end() && !it->second.first.expired()) return it->second.second;
    }
    const std::string key = layoutContentKey(*model, salt_); // outside the lock: hashes the mesh
    std::lock_guard<std::mutex> lock(mutex_);
    for (auto it = keys_.begin(); it != keys_.end();) // forget models that are gone
        it = it->second.first.expired() ? keys_.erase(it) : std::next(it);
    keys_[model.get()] = {model, key};
    return key;
}

void LayoutCache::touch(const std::string& key) {
    recent_.remove(key);
    recent_.push_front(key);
    while (recent_.size() > maxEntries_) {
        auto victim = entries_.find(recent_.back());
        if (victim != entries_.end() && !victim->second.building) entries_.erase(victim);
        recent_.pop_back();
    }
}

Result<std::shared_ptr<const TextureLayout>> LayoutCache::generated(const std::shared_ptr<const Model>& model) {
    const std::string key = keyOf(model);
    {
        std::unique_lock<std::mutex> lock(mutex_);
        built_.wait(lock, [&] { auto it = entries_.find(key); return it == entries_.end() || !it->second.building; });
        auto it = entries_.find(key);
        if (it != entries_.end() && it->second.layout) {
            ++stats_.memoryHits;
            touch(key);
            return it->second.layout;
        }
        entries_[key].building = true;
    }
    // One builder per key from here; the others wait above.
    std::shared_ptr<const TextureLayout> layout;
    bool fromDisk = false, writeFailed = false;
    const std::string file = folder_.empty() ? "" : (std::filesystem::path(folder_) / (key + ".bin")).string();
    if (!file.empty()) {
        if (auto bytes = readWholeFile(file, std::size_t(1) << 30))
            if (auto decoded = decodeTextureLayout(*bytes, *model); decoded && decoded->kind == "generated") {
                layout = std::make_shared<const TextureLayout>(std::move(*decoded));
                fromDisk = true;
            }
    }
    Error failure;
    if (!layout) {
        auto made = generate_(*model);
        if (made) {
            layout = std::make_shared<const TextureLayout>(std::move(*made));
            if (!file.empty()) {
                std::error_code ec;
                std::filesystem::create_directories(folder_, ec);
                writeFailed = !writeFileAtomically(file, encodeTextureLayout(*layout), Durability::Durable,
                                                   "dermis::LayoutCache");
            }
        } else {
            failure = made.error();
        }
    }
    std::lock_guard<std::mutex> lock(mutex_);
    Entry& e = entries_[key];
    e.building = false;
    built_.notify_all();
    if (!layout) {
        entries_.erase(key);
        return failure;
    }
    e.layout = layout;
    ++(fromDisk ? stats_.diskHits : stats_.generated);
    if (writeFailed) ++stats_.diskWriteFailures;
    touch(key);
    return layout;
}

LayoutCache::Stats LayoutCache::stats() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return stats_;
}

} // namespace dermis
