// Per-model derived data, built once. See model_derived.hpp.
#include "model_derived.hpp"

#include <stdexcept>
#include <utility>

namespace dermis {

ModelDerived::ModelDerived(std::shared_ptr<const Model> model) : model_(std::move(model)) {
    if (!model_) throw std::invalid_argument("dermis::ModelDerived: null model");
}

const UvLookup& ModelDerived::uvLookup() const {
    std::call_once(lookupOnce_, [this] {
        lookup_ = std::make_unique<const UvLookup>(*model_);
        lookupBuilds_.fetch_add(1);
    });
    return *lookup_;
}

const SymmetryPlane& ModelDerived::symmetryPlane() const {
    std::call_once(planeOnce_, [this] {
        plane_ = dermis::symmetryPlane(*model_);
        planeBuilds_.fetch_add(1);
    });
    return plane_;
}

std::shared_ptr<const ModelDerived> ModelDerivedSlot::get(const std::shared_ptr<const Model>& model) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!derived_ || derived_->modelPtr() != model) derived_ = std::make_shared<const ModelDerived>(model);
    return derived_;
}

std::shared_ptr<const ModelDerived> ModelDerivedSlot::peek() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return derived_;
}

} // namespace dermis
