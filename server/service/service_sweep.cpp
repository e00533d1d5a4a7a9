// Sweeps of a stored scene (SPEC §6 Sweep): the steps as JSON (CPU only), or every step rendered
// as one cell of a labelled PNG contact sheet. Steps are planned by core/sweep on the frame's
// snapshot (current document or a revision, patterns=off / only= applied); each cell is a frame
// planned by planFrame with the step's pose, rendered by the one renderer.
#include "service_state.hpp"

#include "core/contact_sheet.hpp"
#include "core/sweep.hpp"
#include "io/frame_io.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace dermis {

using namespace detail;

namespace {

/// Seconds, degrees and t rounded to 1e-6 (no −0).
double rounded(double x) {
    return std::round(x * 1e6) / 1e6 + 0.0;
}

std::string fixed(double x, int decimals) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*f", decimals, x);
    return buf;
}

/// The index of placement `pid`, or NotFound naming "placement".
Result<std::size_t> placementIndex(const Scene& scene, const std::string& pid,
                                   const std::string& id) {
    for (std::size_t i = 0; i < scene.placements.size(); ++i)
        if (scene.placements[i].id == pid) return i;
    return notFound("placement", "no placement \"" + pid + "\" in scene " + id);
}

/// The sweep `params` ask for, on `snap`; `maxSteps` bounds the steps.
Result<Sweep> planSweep(const Service::State::Snapshot& snap, const std::string& id,
                        const SweepParams& params, int maxSteps) {
    if (params.placement.empty() && params.clip.empty())
        return bad("placement", "a placement (joint sweep) or a clip (clip sweep) is required");
    if (params.steps < kMinSweepSteps || params.steps > maxSteps)
        return bad("steps", "must be an integer in [" + std::to_string(kMinSweepSteps) + ", " +
                                std::to_string(maxSteps) + "]" +
                                (maxSteps < kMaxSweepSteps
                                     ? " for a contact sheet (up to " +
                                           std::to_string(kMaxSweepSteps) + " with format=json)"
                                     : std::string()));
    std::optional<std::size_t> index;
    if (!params.placement.empty()) {
        auto i = placementIndex(snap.scene, params.placement, id);
        if (!i) return i.error();
        index = *i;
    }
    Result<Sweep> sweep =
        params.clip.empty()
            ? jointSweep(snap.scene, *snap.model, *index, params.steps, params.frame.time)
            : clipSweep(snap.scene, *snap.model, params.clip, params.steps);
    if (!sweep) return sweep.error();
    if (!params.clip.empty()) sweep->placement = index;
    return sweep;
}

/// The label lines of step `k`.
std::vector<std::string> labelOf(const Sweep& sweep, const Scene& scene, std::size_t k) {
    const SweepStep& step = sweep.steps[k];
    std::vector<std::string> lines;
    if (sweep.clip.empty()) {
        lines.push_back("\u03b8=" + fixed(step.theta, 1) + "\u00b0");
        lines.push_back("t=" + fixed(step.t[*sweep.placement], 2));
        return lines;
    }
    lines.push_back("time=" + fixed(step.time, 2) + "s");
    if (sweep.placement) {
        lines.push_back(scene.placements[*sweep.placement].id +
                        " t=" + fixed(step.t[*sweep.placement], 2));
        return lines;
    }
    // Every placement that shows (t ≥ 0.005, i.e. 0.01 once printed), the most active first.
    std::vector<std::size_t> active;
    for (std::size_t i = 0; i < step.t.size(); ++i)
        if (step.t[i] >= 0.005) active.push_back(i);
    std::stable_sort(active.begin(), active.end(),
                     [&](std::size_t a, std::size_t b) { return step.t[a] > step.t[b]; });
    for (std::size_t i : active)
        lines.push_back(scene.placements[i].id + " " + fixed(step.t[i], 2));
    return lines;
}

} // namespace

Result<json> Service::sweepSteps(const std::string& id, const SweepParams& params) {
    auto snap = state_->frameSnapshot(id, params.frame);
    if (!snap) return snap.error();
    auto sweep = planSweep(*snap, id, params, kMaxSweepSteps);
    if (!sweep) return sweep.error();
    const Scene& scene = snap->scene;
    json steps = json::array();
    if (sweep->clip.empty()) {
        const std::size_t i = *sweep->placement;
        const Placement& p = scene.placements[i];
        json placements = json::object();
        for (const Placement& q : scene.placements)
            placements[q.id] = json::array();
        for (const SweepStep& s : sweep->steps) {
            steps.push_back({{"theta", rounded(s.theta)}, {"t", rounded(s.t[i])}});
            for (std::size_t j = 0; j < scene.placements.size(); ++j)
                placements[scene.placements[j].id].push_back(rounded(s.t[j]));
        }
        const json axis =
            p.axisName.empty() ? json{p.axis[0], p.axis[1], p.axis[2]} : json(p.axisName);
        return json{{"scene", id},
                    {"placement", p.id},
                    {"joint", p.joint},
                    {"axis", axis},
                    {"theta_min", p.thetaMin},
                    {"theta_max", p.thetaMax},
                    {"time", rounded(sweep->steps.front().time)},
                    {"steps", std::move(steps)},
                    {"placements", std::move(placements)}};
    }
    for (const SweepStep& s : sweep->steps) {
        json t = json::object();
        for (std::size_t j = 0; j < scene.placements.size(); ++j)
            if (!sweep->placement || *sweep->placement == j)
                t[scene.placements[j].id] = rounded(s.t[j]);
        steps.push_back({{"time", rounded(s.time)}, {"t", std::move(t)}});
    }
    return json{
        {"scene", id},
        {"clip", sweep->clip},
        {"duration", rounded(sweep->duration)},
        {"placement", sweep->placement ? json(scene.placements[*sweep->placement].id) : json()},
        {"steps", std::move(steps)}};
}

Result<EncodedImage> Service::sweep(const std::string& id, const SweepParams& params) {
    if (params.size < 1 || params.size > kMaxRenderSize)
        return bad("size", "must be an integer in [1, " + std::to_string(kMaxRenderSize) + "]");
    if (params.size > limits_.maxRenderSide)
        return makeError(ErrorCode::TooLarge, "dermis::Service", "size",
                         "cells larger than this server's " +
                             std::to_string(limits_.maxRenderSide) + " pixels");
    QueueSlot slot(state_->inFlight, limits_.queueLength);
    if (!slot.ok()) return queueFull();
    auto snap = state_->frameSnapshot(id, params.frame);
    if (!snap) return snap.error();
    auto sweep = planSweep(*snap, id, params, kMaxSweepCells);
    if (!sweep) return sweep.error();
    const SheetLayout layout = sheetLayout(sweep->steps.size());
    if (static_cast<long long>(std::max(layout.cols, layout.rows)) * params.size >
        limits_.maxRenderSide)
        return makeError(ErrorCode::TooLarge, "dermis::Service", "size",
                         "a " + std::to_string(layout.cols) + "x" + std::to_string(layout.rows) +
                             " sheet of " + std::to_string(params.size) +
                             "-pixel cells is larger than this server's " +
                             std::to_string(limits_.maxRenderSide) + " pixels");
    FrameParams cellParams = params.frame;
    cellParams.width = cellParams.height = params.size;
    cellParams.time.reset(); // each step's pose carries its time
    std::vector<Image8> cells;
    cells.reserve(sweep->steps.size());
    State::Snapshot cellSnap = *snap;
    for (std::size_t k = 0; k < sweep->steps.size(); ++k) {
        cellSnap.scene.pose = sweep->steps[k].pose;
        auto image = state_->renderImage(cellSnap, cellParams);
        if (!image) return asParamError(image.error(), cellParams);
        // Labels take at most 40% of the cell's height (a clip sweep may list many placements).
        const int lineH = kLineHeight * labelScale(*image);
        labelCell(*image, labelOf(*sweep, snap->scene, k),
                  static_cast<std::size_t>(std::max(2, 2 * params.size / (5 * lineH))));
        cells.push_back(std::move(*image));
    }
    auto sheet = composeSheet(cells, layout);
    if (!sheet) return sheet.error();
    auto bytes = encodePng(*sheet, false);
    if (!bytes) return bytes.error();
    EncodedImage out;
    out.bytes = std::move(*bytes);
    out.contentType = "image/png";
    out.backend = state_->renderer->info().backend;
    return out;
}

} // namespace dermis
