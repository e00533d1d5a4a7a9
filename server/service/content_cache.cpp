// The content cache of a stateless replica: an LRU list over a map, under one mutex.
#include "service/content_cache.hpp"

namespace dermis {

ContentCache::Item ContentCache::find(const std::string& address) {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = entries_.find(address);
    if (it == entries_.end()) {
        ++misses_;
        return {};
    }
    ++hits_;
    order_.splice(order_.begin(), order_, it->second.order);
    return it->second.item;
}

std::vector<ContentCache::Item> ContentCache::put(const std::string& address, Item item,
                                                  std::size_t bytes) {
    std::vector<Item> out;
    std::lock_guard<std::mutex> lock(mutex_);
    if (auto old = entries_.find(address); old != entries_.end()) {
        bytes_ -= old->second.bytes;
        order_.erase(old->second.order);
        out.push_back(std::move(old->second.item));
        entries_.erase(old);
    }
    if (bytes > budget_) {
        out.push_back(std::move(item));
        ++evictions_;
        return out;
    }
    while (bytes_ + bytes > budget_ && !order_.empty()) {
        auto victim = entries_.find(order_.back());
        bytes_ -= victim->second.bytes;
        out.push_back(std::move(victim->second.item));
        entries_.erase(victim);
        order_.pop_back();
        ++evictions_;
    }
    order_.push_front(address);
    entries_[address] = Entry{std::move(item), bytes, order_.begin()};
    bytes_ += bytes;
    ++insertions_;
    return out;
}

ContentCache::Stats ContentCache::stats() const {
    std::lock_guard<std::mutex> lock(mutex_);
    Stats s;
    s.entries = entries_.size();
    s.bytes = bytes_;
    s.budget = budget_;
    s.hits = hits_;
    s.misses = misses_;
    s.insertions = insertions_;
    s.evictions = evictions_;
    for (const auto& [address, e] : entries_)
        if (e.item.derived) s.restSurfaceBuilds += static_cast<std::uint64_t>(e.item.derived->restSurfaceBuilds());
    return s;
}

std::size_t ContentCache::approxBytes(const Model& m) {
    std::size_t n = sizeof(Model) + m.nodes.size() * sizeof(Node) + m.joints.size() * sizeof(int);
    for (const MeshPart& p : m.parts)
        n += sizeof(MeshPart) + p.positions.size() * sizeof(glm::vec3) + p.normals.size() * sizeof(glm::vec3) +
             (p.uvs.size() + p.uvs1.size()) * sizeof(glm::vec2) +
             (p.tangents.size() + p.colors.size()) * sizeof(glm::vec4) + p.joints.size() * sizeof(glm::u16vec4) +
             p.weights.size() * sizeof(glm::vec4) + p.indices.size() * sizeof(std::uint32_t) +
             p.influences.size() * sizeof(Influence);
    for (const MeshPart& p : m.parts)
        for (const MorphTarget& t : p.morphs)
            n += sizeof(MorphTarget) + (t.positions.size() + t.normals.size() + t.tangents.size()) * sizeof(glm::vec3);
    n += m.morphWeights.size() * sizeof(MorphWeight);
    for (const Image8& img : m.images) n += img.rgba.size() + img.rgba.size() / 3; // + CPU mip chain
    for (const Clip& c : m.clips)
        for (const Channel& ch : c.channels) n += (ch.times.size() + ch.values.size()) * sizeof(float);
    return n;
}

std::size_t ContentCache::approxBytes(const PatternImage& image) {
    // The pixels and, on the GPU side's behalf, about a third more for a mip chain.
    return sizeof(PatternImage) + image.pixels.data.size() * sizeof(float) * 4 / 3;
}

std::size_t ContentCache::approxBytes(const EnvironmentImage& image) {
    return sizeof(EnvironmentImage) + image.texels.size() * sizeof(glm::vec3);
}

} // namespace dermis
