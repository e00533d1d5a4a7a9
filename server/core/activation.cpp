// Activation of placements over a clip. See activation.hpp.
#include "activation.hpp"

#include <cmath>

namespace dermis {

std::string_view toString(ActivationFlagKind k) {
    switch (k) {
    case ActivationFlagKind::NeverActive: return "never_active";
    case ActivationFlagKind::Saturated: return "saturated";
    case ActivationFlagKind::Jump: return "jump";
    }
    return "never_active";
}

Result<Activation> clipActivation(const Scene& scene, const Model& model, const std::string& clip,
                                  double fps) {
    const char* where = "dermis::clipActivation";
    const int c = model.findClip(clip);
    if (c < 0) return makeError(ErrorCode::NotFound, where, "clip", "the model has no clip named '" + clip + "'");
    if (!std::isfinite(fps) || fps <= 0.0 || fps > 240.0)
        return makeError(ErrorCode::InvalidArgument, where, "fps", "must be in (0, 240]");
    const double duration = model.clips[static_cast<std::size_t>(c)].duration;
    const double steps = std::floor(duration * fps + 1e-9);
    if (steps + 1 > static_cast<double>(kMaxActivationSamples))
        return makeError(ErrorCode::InvalidArgument, where, "fps",
                         "the clip would need more than " + std::to_string(kMaxActivationSamples) +
                             " samples");
    Activation out;
    const std::size_t n = static_cast<std::size_t>(steps) + 1;
    for (std::size_t k = 0; k < n; ++k)
        out.times.push_back(std::min(duration, static_cast<double>(k) / fps));
    if (out.times.back() < duration - 1e-9) out.times.push_back(duration);
    out.t.assign(scene.placements.size(), std::vector<double>(out.times.size(), 0.0));

    Pose pose;
    pose.animation = clip;
    for (std::size_t k = 0; k < out.times.size(); ++k) {
        auto local = evaluatePose(model, pose, out.times[k]);
        if (!local) return local.error();
        for (std::size_t i = 0; i < scene.placements.size(); ++i) {
            const Placement& p = scene.placements[i];
            auto theta = placementAngle(model, *local, p, i);
            if (!theta) return theta.error();
            out.t[i][k] = normalizedT(*theta, p.thetaMin, p.thetaMax);
        }
    }
    for (std::size_t i = 0; i < out.t.size(); ++i) {
        const std::vector<double>& t = out.t[i];
        double maxT = 0.0;
        std::size_t full = 0;
        std::optional<double> firstFull, jumpAt;
        for (std::size_t k = 0; k < t.size(); ++k) {
            maxT = std::max(maxT, t[k]);
            if (t[k] >= 1.0) {
                ++full;
                if (!firstFull) firstFull = out.times[k];
            }
            if (k > 0 && !jumpAt && std::abs(t[k] - t[k - 1]) > 0.5) jumpAt = out.times[k];
        }
        if (maxT <= 0.0) out.flags.push_back({i, ActivationFlagKind::NeverActive, std::nullopt});
        if (4 * full >= t.size()) out.flags.push_back({i, ActivationFlagKind::Saturated, firstFull});
        if (jumpAt) out.flags.push_back({i, ActivationFlagKind::Jump, jumpAt});
    }
    return out;
}

} // namespace dermis
