// Dermis core — does a pattern ever activate in a clip? (SPEC §6 Activation): every placement's
// normalised angle t sampled over one of the model's clips, and flags for what an artist should
// look at. CPU only, no images needed.
//
// Pure; thread-safe on const inputs.
#pragma once

#include "bake.hpp"

#include <optional>
#include <string>
#include <vector>

namespace dermis {

enum class ActivationFlagKind {
    NeverActive, ///< t stays 0 over the whole clip: the θ range is never entered
    Saturated,   ///< t sits at 1 for at least a quarter of the samples: the range ends too soon
    Jump,        ///< t changes by more than 0.5 between two samples (e.g. an angle wrapping)
};
std::string_view toString(ActivationFlagKind k);

struct ActivationFlag {
    std::size_t placement = 0; ///< index in Scene::placements
    ActivationFlagKind kind = ActivationFlagKind::NeverActive;
    std::optional<double> at;  ///< seconds: where it saturates first / the later sample of a
                               ///< jump; none for NeverActive
};

struct Activation {
    std::vector<double> times;           ///< 0, 1/fps, … up to the clip's duration (included)
    std::vector<std::vector<double>> t;  ///< per placement (scene order), one value per time
    std::vector<ActivationFlag> flags;   ///< by placement, then kind
};

/// Most samples one activation may take.
constexpr std::size_t kMaxActivationSamples = 100000;

/// Samples the clip named `clip` of `model` at `fps` (the clip alone: the scene's pose time and
/// joint overrides are not applied) and each placement's t = normalizedT(θ) at every sample
/// (disabled placements too). Fails: NotFound (field "clip") for an unknown clip;
/// InvalidArgument (field "fps") unless 0 < fps ≤ 240, or when the clip would need more than
/// kMaxActivationSamples samples; NotFound naming "/placements/<i>/joint" for an unknown joint.
Result<Activation> clipActivation(const Scene& scene, const Model& model, const std::string& clip,
                                  double fps);

} // namespace dermis
