// The renderer's GPU cache: pattern/base textures and model uploads under one byte budget,
// freed least recently used first, or at once when their content is deleted (see renderer.hpp,
// "Caches"). Everything here runs on the render thread but publishCacheStats' copy.
#include "renderer_impl.hpp"

#include <limits>

namespace dermis {

using namespace gl;

void Renderer::Impl::erasePattern(std::map<std::uint64_t, PatternTexture>::iterator it) {
    if (baseTexture == it->second.tex) baseTexture = 0;
    glDeleteTextures(1, &it->second.tex);
    if (it->second.tex2) glDeleteTextures(1, &it->second.tex2);
    patternBytes -= it->second.bytes;
    patterns.erase(it);
}

void Renderer::Impl::eraseModel(std::map<const Model*, GpuModel>::iterator it) {
    it->second.destroy();
    modelBytes -= it->second.bytes;
    models.erase(it);
}

bool Renderer::Impl::evictOldest(std::uint64_t before, bool patternsOnly) {
    auto oldestPattern = patterns.end();
    std::uint64_t oldest = std::numeric_limits<std::uint64_t>::max();
    for (auto it = patterns.begin(); it != patterns.end(); ++it)
        if (it->second.lastUse < before && it->second.lastUse < oldest) {
            oldest = it->second.lastUse;
            oldestPattern = it;
        }
    auto oldestModel = models.end();
    for (auto it = models.begin(); it != models.end() && !patternsOnly; ++it)
        if (it->second.lastUse < before && it->second.lastUse < oldest) {
            oldest = it->second.lastUse;
            oldestModel = it;
        }
    if (oldestModel != models.end())
        eraseModel(oldestModel);
    else if (oldestPattern != patterns.end())
        erasePattern(oldestPattern);
    else
        return false;
    ++evictions;
    return true;
}

void Renderer::Impl::makeRoom(std::size_t incoming) {
    while (patternBytes + modelBytes + incoming > cacheBudget && evictOldest(useCounter)) {
    }
}

void Renderer::Impl::trimCache() {
    dropOrphanedModels();
    while (patternBytes + modelBytes > cacheBudget && evictOldest(useCounter + 1)) {
    }
}

void Renderer::Impl::forgetPattern(std::uint64_t contentId) {
    if (auto it = patterns.find(contentId); it != patterns.end()) {
        erasePattern(it);
        ++forgotten;
    }
}

void Renderer::Impl::forgetModel(const std::weak_ptr<const Model>& model) {
    // By owner, not by address: the address of a model already gone may hold a new one.
    for (auto it = models.begin(); it != models.end(); ++it)
        if (!it->second.owner.owner_before(model) && !model.owner_before(it->second.owner)) {
            eraseModel(it);
            ++forgotten;
            break;
        }
    dropOrphanedModels();
}

void Renderer::Impl::publishCacheStats() {
    GpuCacheStats s;
    s.textures = patterns.size();
    s.textureBytes = patternBytes;
    s.models = models.size();
    s.modelBytes = modelBytes;
    s.budgetBytes = cacheBudget;
    s.evictions = evictions;
    s.forgotten = forgotten;
    std::lock_guard<std::mutex> lock(statsMutex);
    published = s;
}

// --- public façade ---------------------------------------------------------------------------------

void Renderer::forgetPattern(std::uint64_t contentId) {
    Impl* impl = impl_.get();
    impl->post([impl, contentId] {
        impl->forgetPattern(contentId);
        impl->endJob();
    });
}

void Renderer::forgetModel(const std::shared_ptr<const Model>& model) {
    if (!model) return;
    Impl* impl = impl_.get();
    impl->post([impl, weak = std::weak_ptr<const Model>(model)] {
        impl->forgetModel(weak);
        impl->endJob();
    });
}

std::optional<GpuCacheStats> Renderer::cacheStats() const {
    std::lock_guard<std::mutex> lock(impl_->statsMutex);
    return impl_->published;
}

} // namespace dermis
