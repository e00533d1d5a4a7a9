// Dermis service — generated height-map layouts (SPEC §8 `uv_layout: generated`), cached per model
// content in memory and in the data folder (<data>/cache/layouts/<key>.bin, core layout_codec), so
// a model is laid out once, not once per process start or per request.
//
// The generator is injected (the service passes core generateTextureLayout; tests count calls).
// Concurrent first requests for one model wait for a single generation. A cache file that is
// damaged or belongs to other bytes is ignored and rewritten; a data folder that cannot be written
// only loses the disk copy (the layout is still served and kept in memory). Memory: the newest
// `maxEntries` layouts are kept (least recently used dropped; holders keep theirs alive).
// Thread-safe. Does not choose a scene's layout (the service does, from the UV diagnosis).
#pragma once

#include "core/model.hpp"
#include "core/result.hpp"
#include "core/texture_layout.hpp"

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <string>

namespace dermis {

class LayoutCache {
public:
    using Generator = std::function<Result<TextureLayout>(const Model&)>;
    struct Stats {
        std::uint64_t generated = 0, diskHits = 0, memoryHits = 0, diskWriteFailures = 0;
    };

    /// `folder`: where layouts are kept on disk ("" = memory only); created on the first write.
    /// `salt` names the generator and its options (part of every key: a new generator version
    /// never reads an old one's files).
    LayoutCache(std::string folder, std::string salt, Generator generate, std::size_t maxEntries = 8);

    /// The generated layout of `model` (non-null): from memory, the data folder, or the
    /// generator. Fails as the generator does (the failure is not cached).
    Result<std::shared_ptr<const TextureLayout>> generated(const std::shared_ptr<const Model>& model);

    /// The key `model`'s layout is cached under (core layoutContentKey with the salt); computed
    /// once per model object.
    std::string keyOf(const std::shared_ptr<const Model>& model);

    Stats stats() const;

private:
    struct Entry {
        std::shared_ptr<const TextureLayout> layout;
        bool building = false;
    };
    std::string folder_, salt_;
    Generator generate_;
    std::size_t maxEntries_;
    mutable std::mutex mutex_;
    std::condition_variable built_;
    std::map<std::string, Entry> entries_;             ///< by content key
    std::list<std::string> recent_;                    ///< keys, most recently used first
    std::map<const Model*, std::pair<std::weak_ptr<const Model>, std::string>> keys_;
    Stats stats_;

    void touch(const std::string& key);
};

} // namespace dermis
