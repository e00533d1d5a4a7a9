// Inspection of a stored scene, CPU only (SPEC §6): pick — frame pixel to skin —, a placement's
// footprint outline in the texture view (SPEC §8), probe — why a texel has its height —,
// activation — each placement's t over a clip, with flags — and lint. All run on a snapshot,
// unlocked. Lint and the picks read the model's UV index, rest skin, symmetry plane and clip
// ranges from its entry (State::derivedOf: built once per model, core ModelDerived), not new ones
// per request.
#include "service_state.hpp"

#include "core/activation.hpp"
#include "core/deform.hpp"
#include "core/lint.hpp"
#include "core/pick.hpp"
#include "core/probe.hpp"
#include "core/surface_outline.hpp"
#include "core/surface_query.hpp"
#include "core/propose.hpp"

#include <algorithm>
#include <cmath>
#include <set>

namespace dermis {

using namespace detail;

namespace {

/// Seconds and t values rounded to 1e-6 (keeps the JSON short; far below what a person reads).
double rounded(double x) {
    return std::round(x * 1e6) / 1e6 + 0.0; // + 0.0: no "-0" in the JSON
}

/// The pick answer of a hit (shared by the frame and texture picks); the suggestion from the
/// range-of-motion analysis of `analysis` (the model's own derived data, cached: core
/// suggestFromMotion — a proposal's driver where one covers the hit). `uv` is
/// in `layout` (the scene's height-map layout, SPEC §8) when given and covering the hit;
/// `anchor` is where a surface placement would sit there (bind space; tangent across the
/// suggested joint's bone).
json pickAnswer(const ModelDerived& derived, const PickHit& h, const TextureLayout* layout,
                const ModelDerived& analysis) {
    const Model& m = derived.model();
    json joints = json::array();
    for (auto [node, weight] : h.joints)
        joints.push_back({{"name", m.nodes[static_cast<std::size_t>(node)].name}, {"weight", weight}});
    glm::vec2 uv = h.uv;
    if (layout)
        if (auto l = layoutUv(*layout, h)) uv = *l;
    // The driver from the range-of-motion analysis (SPEC §8; core suggestFromMotion), cached
    // per model with the proposals it reads.
    const glm::dvec3 bind = [&] {
        if (h.part < 0 || static_cast<std::size_t>(h.part) >= m.parts.size()) return glm::dvec3(0.0);
        return bindPositionAt(m, SurfacePoint{static_cast<std::size_t>(h.part), 3 * static_cast<std::size_t>(h.triangle), glm::dvec3(h.bary)});
    }();
    const MotionSuggestion s = suggestFromMotion(m, analysis.restSkin(), analysis.symmetryPlane(), analysis.bodyMap(),
                                                 analysis.motion(), analysis.proposals(), h.joints, bind);
    const SuggestedDriver& d = s.driver;
    const PickAnchor a = pickAnchor(m, h, d.joint.empty() ? -1 : findPosable(m, d.joint), derived.restSkin().world);
    const auto vec = [](glm::dvec3 v) { return json::array({v.x, v.y, v.z}); };
    return json{{"hit", true},
                {"uv", {uv.x, uv.y}},
                {"anchor", {{"position", vec(a.position)}, {"normal", vec(a.normal)}, {"tangent", vec(a.tangent)}}},
                {"position", {h.position.x, h.position.y, h.position.z}},
                {"part", h.part},
                {"triangle", h.triangle},
                {"joints", std::move(joints)},
                {"suggested", {{"joint", d.joint},
                               {"axis", s.axisVector ? vec(*s.axisVector) : json(d.axis)},
                               {"theta_min", d.thetaMin},
                               {"theta_max", d.thetaMax},
                               {"role", s.role},
                               {"proposal", s.proposal.empty() ? json() : json(s.proposal)}}}};
}

} // namespace

std::shared_ptr<const ModelDerived> Service::State::derivedOf(const Snapshot& snap) const {
    if (snap.derived && snap.derived->modelPtr() == snap.model) return snap.derived;
    std::shared_ptr<ModelDerivedSlot> slot;
    {
        std::shared_lock<std::shared_mutex> lock(mutex);
        auto it = models.find(snap.scene.model);
        if (it != models.end() && it->second.model == snap.model && it->second.derived)
            slot = it->second.derived;
    }
    if (!slot) return std::make_shared<const ModelDerived>(snap.model);
    return slot->get(snap.model);
}

Result<json> Service::probe(const std::string& id, double u, double v, std::optional<double> time) {
    auto snap = state_->snapshot(id);
    if (!snap) return snap.error();
    FrameOverrides o;
    o.time = time;
    if (auto s = state_->withLayout(snap->scene, *state_->derivedOf(*snap), o); !s) return s.error();
    auto plan = planFrame(snap->scene, *snap->model, snap->images, snap->base, o);
    if (!plan) {
        Error e = plan.error();
        if (e.field == "/pose/time") e.field = "time";
        return e;
    }
    auto r = probeHeights(plan->heights, u, v);
    if (!r) return r.error();
    json contributions = json::array();
    for (const ProbeContribution& c : r->contributions) {
        const Placement& p = snap->scene.placements.at(static_cast<std::size_t>(c.source));
        contributions.push_back({{"placement", p.id},
                                 {"pattern", p.pattern},
                                 {"target", std::string(toString(c.target))},
                                 {"t", rounded(c.t)},
                                 {"L", c.L},
                                 {"height", c.height}});
    }
    return json{{"u", u},
                {"v", v},
                {"texel", {r->texelX, r->texelY}},
                {"map_size", {plan->heights.width, plan->heights.height}},
                {"base", r->base},
                {"bump", r->bump},
                {"displacement", r->displacement},
                {"contributions", std::move(contributions)}};
}

Result<json> Service::activation(const std::string& id, const std::string& clip, double fps) {
    auto snap = state_->snapshot(id);
    if (!snap) return snap.error();
    auto a = clipActivation(snap->scene, *snap->model, clip, fps);
    if (!a) return a.error();
    json times = json::array();
    for (double t : a->times) times.push_back(rounded(t));
    json placements = json::object();
    for (std::size_t i = 0; i < a->t.size(); ++i) {
        json values = json::array();
        for (double t : a->t[i]) values.push_back(rounded(t));
        placements[snap->scene.placements[i].id] = std::move(values);
    }
    json flags = json::array();
    for (const ActivationFlag& f : a->flags)
        flags.push_back({{"placement", snap->scene.placements[f.placement].id},
                         {"kind", std::string(toString(f.kind))},
                         {"at", f.at ? json(rounded(*f.at)) : json()}});
    return json{{"scene", id},       {"clip", clip},           {"fps", fps},
                {"times", times},    {"placements", placements}, {"flags", flags}};
}

Result<json> Service::lint(const std::string& id) {
    auto snap = state_->snapshot(id);
    if (!snap) return snap.error();
    std::vector<std::string> unused;
    {
        std::shared_lock<std::shared_mutex> lock(state_->mutex);
        std::set<std::string> used;
        for (const auto& [sid, e] : state_->scenes) {
            for (const Placement& p : state_->resolved(*e.scene).placements) used.insert(p.pattern);
            if (e.scene->heightmapBase) used.insert(*e.scene->heightmapBase);
            for (const auto& [alias, target] : e.scene->patterns) used.insert(target);
        }
        for (const auto& [pid, e] : state_->patterns)
            if (!e.builtin && !used.count(pid)) unused.push_back(pid);
    }
    // The model's UV index, rest skin and symmetry plane, built once, in the texture space the
    // scene's maps live in (a generated layout: UV placements are checked there).
    const auto derived = state_->derivedInLayout(*snap);
    json out = json::array();
    for (const LintFinding& f : lintScene(snap->scene, *derived, snap->images))
        out.push_back({{"code", f.code},
                       {"severity", std::string(toString(f.severity))},
                       {"placement", f.placement >= 0
                                         ? json(snap->scene.placements[static_cast<std::size_t>(f.placement)].id)
                                         : json()},
                       {"message", f.message}});
    for (const std::string& pid : unused)
        out.push_back({{"code", "unused_upload"},
                       {"severity", "info"},
                       {"placement", nullptr},
                       {"message", "uploaded pattern " + pid + " is used by no scene"}});
    return out;
}

Result<json> Service::pick(const std::string& id, const FrameParams& params, double x, double y) {
    auto snap = state_->snapshot(id);
    if (!snap) return snap.error();
    auto plan = state_->plan(*snap, params);
    if (!plan) return plan.error();
    auto hit = pickFrame(*plan, *snap->model, x, y);
    if (!hit) return hit.error();
    if (!*hit) return json{{"hit", false}};
    const auto derived = state_->derivedOf(*snap);
    return pickAnswer(*derived, **hit, plan->heights.layout.get(), *derived);
}


Result<json> Service::pickUv(const std::string& id, double u, double v) {
    if (!std::isfinite(u) || u < 0.0 || u > 1.0) return bad("u", "must be in [0, 1]");
    if (!std::isfinite(v) || v < 0.0 || v > 1.0) return bad("v", "must be in [0, 1]");
    auto snap = state_->snapshot(id);
    if (!snap) return snap.error();
    // The UV index of the layout the scene's maps live in (the model's own, or the generated
    // one: what the texture view shows), built once.
    const auto derived = state_->derivedInLayout(*snap);
    if (!derived->model().hasUVs()) return bad("u", "the model has no UVs: nothing lies at a texture point");
    const auto hit = dermis::pickUv(derived->model(), derived->uvLookup(), {u, v});
    if (!hit) return json{{"hit", false}};
    return pickAnswer(*derived, *hit, nullptr, *state_->derivedOf(*snap));
}

json detail::outlineMembers(const SurfaceOutline& outline) {
    auto r5 = [](double x) { return std::round(x * 1e5) / 1e5 + 0.0; }; // + 0.0: no "-0"
    json segments = json::array();
    for (const auto& s : outline.segments) segments.push_back({r5(s[0]), r5(s[1]), r5(s[2]), r5(s[3])});
    json bounds = json::array();
    for (const OutlinePiece& piece : outline.pieces)
        bounds.push_back({r5(piece.min.x), r5(piece.min.y), r5(piece.max.x), r5(piece.max.y)});
    return json{{"pieces", outline.pieces.size()},
                {"bounds", std::move(bounds)},
                {"segments", std::move(segments)},
                {"truncated", outline.truncated},
                {"anchor_uv", outline.anchorUv ? json{r5(outline.anchorUv->x), r5(outline.anchorUv->y)} : json()}};
}

Result<json> Service::placementOutline(const std::string& id, const std::string& pid,
                                       std::optional<std::uint64_t> revision,
                                       std::optional<std::array<double, 2>> at) {
    if (at) {
        if (!std::isfinite((*at)[0]) || (*at)[0] < 0.0 || (*at)[0] > 1.0) return bad("u", "must be in [0, 1]");
        if (!std::isfinite((*at)[1]) || (*at)[1] < 0.0 || (*at)[1] > 1.0) return bad("v", "must be in [0, 1]");
    }
    FrameParams params;
    params.revision = revision;
    auto snap = state_->frameSnapshot(id, params);
    if (!snap) return snap.error();
    const auto& placements = snap->scene.placements;
    const auto it = std::find_if(placements.begin(), placements.end(), [&](const Placement& q) { return q.id == pid; });
    if (it == placements.end()) return notFound("placement", "no placement \"" + pid + "\" in scene " + id);
    const Placement* p = &*it;
    // The layout the scene's maps live in (the model's own UVs or the generated one: what the
    // texture view shows), and the model seen through it (built once per model and layout).
    const auto derived = state_->derivedOf(*snap);
    auto layout = state_->layoutFor(snap->scene, *derived);
    if (!layout) return layout.error();
    const auto inLayout = state_->derivedInLayout(*snap);
    auto outline = surfaceFootprintOutline(inLayout->model(), *p);
    if (!outline) { // fields of the placement (or the layout) in the scene document
        Error e = outline.error();
        e.field = e.field == "uv_layout" ? "/uv_layout"
                                         : "/placements/" + std::to_string(it - placements.begin()) + "/" + e.field;
        return e;
    }
    json out{{"placement", pid}, {"projection", std::string(toString(p->projection))}, {"layout", (*layout)->kind}};
    out.update(outlineMembers(*outline));
    if (at)
        out["hit"] = footprintContains(inLayout->model(), inLayout->uvLookup(), *p, {(*at)[0], (*at)[1]});
    return out;
}

Result<json> Service::drivers(const std::string& id, const FrameParams& params) {
    auto snap = state_->frameSnapshot(id, params);
    if (!snap) return snap.error();
    auto plan = state_->plan(*snap, params);
    if (!plan) return asParamError(plan.error(), params);
    const Model& m = *snap->model;
    json placements = json::array();
    for (std::size_t i = 0; i < snap->scene.placements.size(); ++i) {
        const Placement& p = snap->scene.placements[i];
        auto theta = placementAngle(m, plan->pose, p, i);
        if (!theta) return theta.error();
        placements.push_back({{"placement", p.id},
                              {"joint", p.joint},
                              {"axis", p.axisName.empty() ? json(p.axis) : json(p.axisName)},
                              {"theta", rounded(*theta)},
                              {"t", rounded(normalizedT(*theta, p.thetaMin, p.thetaMax))},
                              {"enabled", p.enabled}});
    }
    const FrameCamera cam = planCamera(*plan, m);
    const Camera& c = plan->render.camera;
    return json{{"scene", id},
                {"time", params.time.value_or(snap->scene.pose.time)},
                {"camera", {{"yaw", c.yaw}, {"pitch", c.pitch}, {"distance", rounded(cam.distance)}}},
                {"placements", std::move(placements)}};
}

} // namespace dermis
