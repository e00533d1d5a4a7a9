// Sweep steps. See sweep.hpp.
#include "sweep.hpp"

#include "angles.hpp"

#include <glm/gtc/quaternion.hpp>

#include <cmath>

namespace dermis {

namespace {

Status checkSteps(int steps, const char* where) {
    if (steps < kMinSweepSteps || steps > kMaxSweepSteps)
        return makeError(ErrorCode::InvalidArgument, where, "steps",
                         "must be an integer in [" + std::to_string(kMinSweepSteps) + ", " +
                             std::to_string(kMaxSweepSteps) + "]");
    return Ok{};
}

/// Every placement's t under `pose` (the functions resolvePlacements uses for a frame).
Result<std::vector<double>> allT(const Scene& scene, const Model& model, const Pose& pose) {
    auto local = evaluatePose(model, pose);
    if (!local) return local.error();
    std::vector<double> out(scene.placements.size(), 0.0);
    for (std::size_t i = 0; i < scene.placements.size(); ++i) {
        const Placement& p = scene.placements[i];
        auto theta = placementAngle(model, *local, p, i);
        if (!theta) return theta.error();
        out[i] = normalizedT(*theta, p.thetaMin, p.thetaMax);
    }
    return out;
}

double fraction(int k, int steps) {
    return static_cast<double>(k) / static_cast<double>(steps - 1);
}

} // namespace

Result<Sweep> jointSweep(const Scene& scene, const Model& model, std::size_t placement, int steps,
                         std::optional<double> time) {
    const char* where = "dermis::jointSweep";
    if (auto s = checkSteps(steps, where); !s) return s.error();
    if (placement >= scene.placements.size())
        return makeError(ErrorCode::NotFound, where, "placement",
                         "no placement " + std::to_string(placement) + " in the scene");
    if (time && !(std::isfinite(*time) && *time >= 0.0))
        return makeError(ErrorCode::InvalidArgument, where, "time", "must be a finite number >= 0");
    const Placement& p = scene.placements[placement];
    Pose base = scene.pose;
    if (time) base.time = *time;
    auto local = evaluatePose(model, base);
    if (!local) return local.error();
    auto current = placementAngle(model, *local, p, placement);
    if (!current) return current.error();
    const int n = findPosable(model, p.joint); // found: placementAngle succeeded
    const glm::dquat q(local->rotation[static_cast<std::size_t>(n)]);
    const glm::dvec3 axis = glm::normalize(glm::dvec3(p.axis[0], p.axis[1], p.axis[2]));

    Sweep out;
    out.placement = placement;
    for (int k = 0; k < steps; ++k) {
        SweepStep step;
        step.theta = p.thetaMin + fraction(k, steps) * (p.thetaMax - p.thetaMin);
        step.time = base.time;
        step.pose = base;
        const glm::dquat r =
            glm::normalize(q * glm::angleAxis(glm::radians(step.theta - *current), axis));
        JointPose jp;
        jp.rotation = std::array<double, 4>{r.x, r.y, r.z, r.w};
        step.pose.joints[p.joint] = jp;
        auto t = allT(scene, model, step.pose);
        if (!t) return t.error();
        step.t = std::move(*t);
        out.steps.push_back(std::move(step));
    }
    return out;
}

Result<Sweep> clipSweep(const Scene& scene, const Model& model, const std::string& clip,
                        int steps) {
    const char* where = "dermis::clipSweep";
    if (auto s = checkSteps(steps, where); !s) return s.error();
    const int c = model.findClip(clip);
    if (c < 0)
        return makeError(ErrorCode::NotFound, where, "clip",
                         "the model has no clip named '" + clip + "'");
    Sweep out;
    out.clip = clip;
    out.duration = model.clips[static_cast<std::size_t>(c)].duration;
    for (int k = 0; k < steps; ++k) {
        SweepStep step;
        step.time = fraction(k, steps) * out.duration;
        step.pose.animation = clip;
        step.pose.time = step.time;
        auto t = allT(scene, model, step.pose);
        if (!t) return t.error();
        step.t = std::move(*t);
        out.steps.push_back(std::move(step));
    }
    return out;
}

} // namespace dermis
