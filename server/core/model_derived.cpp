// Per-model derived data, built once. See model_derived.hpp.
#include "model_derived.hpp"

#include "angles.hpp"
#include "rig.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace dermis {

ModelDerived::ModelDerived(std::shared_ptr<const Model> model)
    : model_(model ? std::move(model) : std::make_shared<const Model>()) {}

const UvLookup& ModelDerived::uvLookup() const {
    std::call_once(lookupOnce_, [this] {
        lookup_ = std::make_unique<const UvLookup>(*model_);
        lookupBuilds_.fetch_add(1);
    });
    return *lookup_;
}

const RestSkin& ModelDerived::restSkin() const {
    std::call_once(restOnce_, [this] {
        rest_ = dermis::restSkin(*model_);
        restBuilds_.fetch_add(1);
    });
    return rest_;
}

const SymmetryPlane& ModelDerived::symmetryPlane() const {
    std::call_once(planeOnce_, [this] {
        plane_ = dermis::symmetryPlane(restSkin()); // = symmetryPlane(*model_)
        planeBuilds_.fetch_add(1);
    });
    return plane_;
}

const UvDiagnosis& ModelDerived::uvDiagnosis() const {
    std::call_once(diagnosisOnce_, [this] {
        diagnosis_ = diagnoseUvs(*model_, restSkin(), symmetryPlane());
        diagnosisBuilds_.fetch_add(1);
    });
    return diagnosis_;
}

const BodyMap& ModelDerived::bodyMap() const {
    std::call_once(bodyOnce_, [this] { body_ = mapBody(*model_, restSkin(), symmetryPlane()); });
    return body_;
}

const MotionAnalysis& ModelDerived::motion() const {
    std::call_once(motionOnce_, [this] { motion_ = analyzeMotion(*model_, restSkin(), bodyMap()); });
    return motion_;
}

const std::vector<Proposal>& ModelDerived::proposals() const {
    std::call_once(proposalsOnce_, [this] {
        proposals_ = proposePatterns(*model_, restSkin(), symmetryPlane(), bodyMap(), motion());
        proposalBuilds_.fetch_add(1);
    });
    return proposals_;
}

SuggestedDriver
ModelDerived::suggestDriver(const std::vector<std::pair<int, float>>& joints) const {
    const Model& model = *model_;
    if (joints.empty() || model.clips.empty()) return dermis::suggestDriver(model, joints);
    std::call_once(rangesOnce_, [&] {
        std::vector<std::array<AngleRange, 3>> ranges(model.nodes.size());
        std::vector<bool> ranged(model.nodes.size(), false);
        for (int n : model.joints)
            if (n >= 0 && static_cast<std::size_t>(n) < model.nodes.size())
                ranged[static_cast<std::size_t>(n)] = true;
        const glm::vec3 axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
        // The same samples, in the same order, as core suggestDriver (pick.cpp).
        for (const Clip& clip : model.clips) {
            const int steps = static_cast<int>(std::floor(clip.duration * 15.0)) + 1;
            const int c = model.findClip(clip.name);
            for (int k = 0; k <= steps; ++k) {
                const LocalPose pose =
                    sampleClip(model, c, std::min(clip.duration, static_cast<float>(k) / 15.0f));
                for (std::size_t n = 0; n < ranges.size(); ++n) {
                    if (!ranged[n]) continue;
                    for (std::size_t a = 0; a < 3; ++a) {
                        const double th =
                            jointAngle(model.nodes[n].rotation, pose.rotation[n], axes[a]);
                        ranges[n][a].lo = std::min(ranges[n][a].lo, th);
                        ranges[n][a].hi = std::max(ranges[n][a].hi, th);
                    }
                }
            }
        }
        ranges_ = std::move(ranges);
        ranged_ = std::move(ranged);
        rangesBuilds_.fetch_add(1);
    });
    for (const auto& [node, weight] : joints)
        if (node < 0 || static_cast<std::size_t>(node) >= ranged_.size() ||
            !ranged_[static_cast<std::size_t>(node)])
            return dermis::suggestDriver(model, joints);
    // The choice, as core suggestDriver makes it, from the ranges sampled once.
    std::vector<std::array<AngleRange, 3>> ranges;
    ranges.reserve(joints.size());
    for (const auto& [node, weight] : joints) ranges.push_back(ranges_[static_cast<std::size_t>(node)]);
    return chooseDriver(model, joints, ranges);
}

const std::shared_ptr<const TextureLayout>& ModelDerived::modelLayout() const {
    std::call_once(layoutOnce_, [this] {
        layout_ = std::make_shared<const TextureLayout>(modelTextureLayout(*model_));
    });
    return layout_;
}

std::shared_ptr<const RestSurfaceMap>
ModelDerived::restSurface(const std::shared_ptr<const TextureLayout>& given, int width, int height) const {
    const std::shared_ptr<const TextureLayout> layout = given ? given : modelLayout();
    auto find = [&]() -> std::shared_ptr<const RestSurfaceMap> {
        for (auto it = restCache_.begin(); it != restCache_.end(); ++it)
            if (it->layout.lock() == layout && it->width == width && it->height == height) {
                RestEntry e = *it;
                restCache_.erase(it);
                restCache_.insert(restCache_.begin(), e); // most recently used first
                return e.map;
            }
        return nullptr;
    };
    {
        std::lock_guard<std::mutex> lock(restMutex_);
        if (auto m = find()) return m;
    }
    auto map = std::make_shared<const RestSurfaceMap>(bakeRestSurface(*model_, *layout, width, height));
    restSurfaceBuilds_.fetch_add(1);
    std::lock_guard<std::mutex> lock(restMutex_);
    if (auto m = find()) return m; // another caller baked it meanwhile
    restCache_.insert(restCache_.begin(), RestEntry{layout, width, height, map});
    // Entries whose layout is gone, then the least recently used beyond the bound.
    restCache_.erase(std::remove_if(restCache_.begin(), restCache_.end(),
                                    [](const RestEntry& e) { return e.layout.expired(); }),
                     restCache_.end());
    if (restCache_.size() > kRestCacheEntries) restCache_.resize(kRestCacheEntries);
    return map;
}

std::shared_ptr<const ModelDerived>
ModelDerivedSlot::get(const std::shared_ptr<const Model>& model) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!derived_ || derived_->modelPtr() != model)
        derived_ = std::make_shared<const ModelDerived>(model);
    return derived_;
}

std::shared_ptr<const ModelDerived> ModelDerivedSlot::peek() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return derived_;
}

std::shared_ptr<const ModelDerived>
ModelDerived::throughLayout(const std::shared_ptr<const TextureLayout>& layout) const {
    {
        std::lock_guard<std::mutex> lock(throughMutex_);
        for (const auto& [l, d] : through_)
            if (l == layout) return d;
    }
    // Built outside the lock (copies the mesh); two first uses at once may both build, one is kept.
    auto made = std::make_shared<const ModelDerived>(
        std::make_shared<const Model>(modelThroughLayout(model(), *layout)));
    std::lock_guard<std::mutex> lock(throughMutex_);
    for (const auto& [l, d] : through_)
        if (l == layout) return d;
    through_.emplace_back(layout, made);
    return made;
}

} // namespace dermis
