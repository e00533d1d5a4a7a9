// Dermis service — the content cache of a stateless replica (SPEC §7, issue #15): models, pattern
// images and environments that batch renders sent inline, kept by content address
// ("sha256:<64 hex>") so that the next batch naming the same hash needs no bytes. Least recently
// used entries are dropped once the decoded sizes exceed a byte budget.
//
// Holds decoded content only (a Model, a PatternImage, an EnvironmentImage), shared and
// immutable: an entry dropped while a render uses it lives on until that render lets it go. Does not decode, hash or check
// anything (service_content.cpp does), does not persist, and knows nothing of uploads (those are
// stored; this is a cache that may forget at any time). Thread-safe: one mutex, held for map work
// only.
#pragma once

#include "core/environment.hpp"
#include "core/heightmap.hpp"
#include "core/model.hpp"
#include "core/model_derived.hpp"

#include <cstddef>
#include <cstdint>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace dermis {

class ContentCache {
public:
    /// A cached item: one of `model` / `pattern` / `environment` is set. A model comes with its
    /// derived data (its generated layout, rest-surface maps, UV index…: built on first use and
    /// kept with the model, so that the next batch naming it bakes none of them again).
    struct Item {
        std::shared_ptr<const Model> model;
        std::shared_ptr<const PatternImage> pattern;
        std::shared_ptr<const ModelDerived> derived; ///< with `model`
        std::shared_ptr<const EnvironmentImage> environment;
    };
    struct Stats {
        std::size_t entries = 0, bytes = 0, budget = 0;
        std::uint64_t hits = 0, misses = 0, insertions = 0, evictions = 0;
        /// Rest-surface maps baked for the cached models so far (their derived data's count).
        std::uint64_t restSurfaceBuilds = 0;
    };

    /// `budgetBytes` 0 keeps nothing (every put is evicted at once).
    explicit ContentCache(std::size_t budgetBytes) : budget_(budgetBytes) {}

    /// The item under `address` (marked most recently used), or an empty Item.
    Item find(const std::string& address);
    /// Adds (or replaces) `item` under `address`, costing `bytes`; returns the items it pushed
    /// out (least recently used first) so that the caller can free what depends on them (GPU
    /// copies). An item larger than the whole budget is returned at once, not kept.
    std::vector<Item> put(const std::string& address, Item item, std::size_t bytes);
    Stats stats() const;

    /// About how many bytes a decoded model holds (vertex and index arrays, textures, clips).
    static std::size_t approxBytes(const Model& model);
    /// The bytes of a pattern image's pixels and mip levels.
    static std::size_t approxBytes(const PatternImage& image);
    /// The bytes of an environment's texels.
    static std::size_t approxBytes(const EnvironmentImage& image);

private:
    struct Entry {
        Item item;
        std::size_t bytes = 0;
        std::list<std::string>::iterator order;
    };
    mutable std::mutex mutex_;
    std::size_t budget_ = 0, bytes_ = 0;
    std::map<std::string, Entry> entries_;
    std::list<std::string> order_; ///< most recently used first
    std::uint64_t hits_ = 0, misses_ = 0, insertions_ = 0, evictions_ = 0;
};

} // namespace dermis
