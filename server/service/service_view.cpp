// 3D-view helpers of a stored scene: focus — where the camera should look to frame a placement
// (core footprintRegion on the frame's posed skin) — and the turntable — the placement's range of
// motion as an animated WebP: its driver joint swept θmin → θmax → θmin (core jointSweep's poses)
// while the camera's yaw turns once, each frame rendered by the one renderer.
#include "service_state.hpp"

#include "core/focus.hpp"
#include "core/model_derived.hpp"
#include "core/rig.hpp"
#include "core/sweep.hpp"
#include "io/webp_anim.hpp"

#include <cmath>
#include <limits>

namespace dermis {

using namespace detail;

namespace {

double rounded(double x) {
    return std::round(x * 1e6) / 1e6 + 0.0;
}

/// The index of placement `pid`, or NotFound naming "placement".
Result<std::size_t> placementAt(const Scene& scene, const std::string& pid, const std::string& id) {
    if (pid.empty()) return bad("placement", "a placement id is required");
    for (std::size_t i = 0; i < scene.placements.size(); ++i)
        if (scene.placements[i].id == pid) return i;
    return notFound("placement", "no placement \"" + pid + "\" in scene " + id);
}

} // namespace

Result<json> Service::focus(const std::string& id, const std::string& pid, const FrameParams& params) {
    auto snap = state_->frameSnapshot(id, params);
    if (!snap) return snap.error();
    auto index = placementAt(snap->scene, pid, id);
    if (!index) return index.error();
    const Placement& p = snap->scene.placements[*index];
    if (p.projection == Projection::Surface) {
        // SPEC §8: the decal's anchor on the posed body (through the rest-mesh vertex nearest to
        // it in bind space), and half the decal's diagonal.
        auto plan = state_->plan(*snap, params);
        if (!plan) return asParamError(plan.error(), params);
        const Model& m = *snap->model;
        const glm::dvec3 c(p.anchor.position[0], p.anchor.position[1], p.anchor.position[2]);
        double best = std::numeric_limits<double>::infinity();
        std::size_t bp = 0, bv = 0;
        for (std::size_t pi = 0; pi < m.parts.size(); ++pi)
            for (std::size_t v = 0; v < m.parts[pi].positions.size(); ++v) {
                const double d = glm::length(glm::dvec3(m.parts[pi].positions[v]) - c);
                if (d < best) {
                    best = d;
                    bp = pi;
                    bv = v;
                }
            }
        if (!std::isfinite(best)) return bad("placement", "the model has no vertices");
        const std::vector<SkinnedPart> posed = skin(m, plan->world, plan->pose.morphWeights);
        const glm::vec3 target = posed[bp].positions[bv];
        const double radius = std::max(0.5 * std::hypot(p.size[0], p.size[1]), 1e-3);
        return json{{"scene", id},
                    {"placement", pid},
                    {"target", {rounded(target.x), rounded(target.y), rounded(target.z)}},
                    {"radius", rounded(radius)},
                    {"distance", rounded(focusDistance(radius))},
                    {"hit", best <= p.depthOrDefault()}};
    }
    // The footprint lies in the layout the scene's maps live in (the model's UVs or generated).
    const auto derived = state_->derivedInLayout(*snap);
    if (!derived->model().hasUVs()) return bad("placement", "the model has no UVs: a footprint lies nowhere");
    auto plan = state_->plan(*snap, params);
    if (!plan) return asParamError(plan.error(), params);
    const auto region = footprintRegion(derived->model(), derived->uvLookup(), skin(derived->model(), plan->world, plan->pose.morphWeights),
                                        {p.center[0], p.center[1]}, {p.scale[0], p.scale[1]}, p.rotation);
    if (!region) return bad("placement", "no skin lies inside the footprint of \"" + pid + "\"");
    return json{{"scene", id},
                {"placement", pid},
                {"target", {rounded(region->target.x), rounded(region->target.y), rounded(region->target.z)}},
                {"radius", rounded(region->radius)},
                {"distance", rounded(focusDistance(region->radius))},
                {"hit", region->hit}};
}

Result<EncodedImage> Service::turntable(const std::string& id, const TurntableParams& params) {
    if (params.frames < kMinTurntableFrames || params.frames > kMaxTurntableFrames)
        return bad("frames", "must be an integer in [" + std::to_string(kMinTurntableFrames) + ", " +
                                 std::to_string(kMaxTurntableFrames) + "]");
    if (params.size < kMinTurntableSize || params.size > kMaxTurntableSize)
        return bad("size", "must be an integer in [" + std::to_string(kMinTurntableSize) + ", " +
                               std::to_string(kMaxTurntableSize) + "]");
    if (params.size > limits_.maxRenderSide)
        return makeError(ErrorCode::TooLarge, "dermis::Service", "size",
                         "frames larger than this server's " + std::to_string(limits_.maxRenderSide) +
                             " pixels");
    if (!(params.fps >= 1.0 && params.fps <= 50.0)) return bad("fps", "must be a number in [1, 50]");
    if (params.frame.format != "webp") return bad("format", "a turntable is an animated webp");
    QueueSlot slot(state_->inFlight, limits_.queueLength);
    if (!slot.ok()) return queueFull();
    auto snap = state_->frameSnapshot(id, params.frame);
    if (!snap) return snap.error();
    auto index = placementAt(snap->scene, params.placement, id);
    if (!index) return index.error();
    // θ at N + 1 even steps; frame k shows step 2k going up and 2N − 2k coming back, so the loop
    // starts and ends at θmin with θmax half way, for any N.
    const int n = params.frames;
    auto sweep = jointSweep(snap->scene, *snap->model, *index, n + 1, params.frame.time);
    if (!sweep) return sweep.error();
    FrameParams cell = params.frame;
    cell.width = cell.height = params.size;
    cell.time.reset(); // each step's pose carries its time
    const double yaw0 = params.frame.yaw.value_or(snap->scene.render.camera.yaw);
    std::vector<Image8> frames;
    frames.reserve(static_cast<std::size_t>(n));
    State::Snapshot cellSnap = *snap;
    for (int k = 0; k < n; ++k) {
        const int step = 2 * k <= n ? 2 * k : 2 * n - 2 * k;
        cellSnap.scene.pose = sweep->steps[static_cast<std::size_t>(step)].pose;
        cell.yaw = std::remainder(yaw0 + 360.0 * k / n, 360.0);
        auto image = state_->renderImage(cellSnap, cell);
        if (!image) return asParamError(image.error(), cell);
        frames.push_back(std::move(*image));
    }
    auto bytes = encodeAnimatedWebp(frames, static_cast<int>(std::lround(1000.0 / params.fps)));
    if (!bytes) return bytes.error();
    EncodedImage out;
    out.bytes = std::move(*bytes);
    out.contentType = "image/webp";
    out.backend = state_->renderer->info().backend;
    return out;
}

} // namespace dermis
