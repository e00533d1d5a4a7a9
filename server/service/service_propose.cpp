// Proposals and transfer (SPEC §8): a full pattern set for a scene's character from its
// range-of-motion analysis (core proposePatterns, cached per model in ModelDerived::proposals),
// and another scene's placements carried onto it (core transferPlacements); each answered as a
// list and, with apply, added in one revision (op "propose" / "transfer from <scene>").
#include "service_state.hpp"

#include "core/mirror.hpp"
#include "core/propose.hpp"
#include "core/scene_json.hpp"
#include "core/surface_outline.hpp"
#include "core/transfer.hpp"

#include <cmath>

namespace dermis {

using namespace detail;

namespace {

double r3(double x) { return std::round(x * 1000.0) / 1000.0 + 0.0; }

/// Segments of a proposal's outline in the answer at most (a ghost, not an edit: coarser is fine).
constexpr std::size_t kProposalOutlineSegments = 4000;

/// The placement's canonical JSON (toJson of a one-placement scene).
json placementJson(const Placement& p) {
    Scene one;
    one.placements.push_back(p);
    return toJson(one)["placements"][0];
}

/// The placement of `scene` that already is proposal `p` (same joint, pattern and projection,
/// anchor within kMirrorAnchorFraction of its size), or "".
std::string existingFor(const Scene& scene, const Placement& p) {
    for (const Placement& q : scene.placements)
        if (q.projection == Projection::Surface && q.joint == p.joint && q.pattern == p.pattern &&
            surfaceAnchorDistance(q, p) <= kMirrorAnchorFraction * std::max(p.size[0], p.size[1]))
            return q.id;
    return "";
}

json whyJson(const ProposalWhy& w) {
    return {{"joint", w.joint},
            {"role", w.role},
            {"axis", {r3(w.axis.x), r3(w.axis.y), r3(w.axis.z)}},
            {"neutral", w.neutral},
            {"peak", w.peak},
            {"peak_clip", w.peakClip.empty() ? json() : json(w.peakClip)},
            {"peak_time", w.peakClip.empty() ? json() : json(w.peakTime)},
            {"synthetic", w.synthetic},
            {"planarity", r3(w.planarity)},
            {"compression", r3(w.compression)},
            {"stretch", r3(w.stretch)},
            {"correlation", r3(w.correlation)},
            {"radius", r3(w.radius)}};
}

} // namespace

Result<json> Service::propose(const std::string& id, bool apply, const EditContext& ctx) {
    auto snap = state_->snapshot(id);
    if (!snap) return snap.error();
    // The analysis (cached per model) is made here, unlocked, before any writer lock.
    const auto derived = state_->derivedOf(*snap);
    const std::vector<Proposal>& proposals = derived->proposals();
    // Each proposal's outline in the layout the scene's maps live in: the texture view's ghosts.
    std::vector<json> outlines(proposals.size());
    if (auto layout = state_->layoutFor(snap->scene, *derived)) {
        const auto inLayout = state_->derivedInLayout(*snap);
        for (std::size_t i = 0; i < proposals.size(); ++i)
            if (auto o = surfaceFootprintOutline(inLayout->model(), proposals[i].placement, kProposalOutlineSegments)) {
                outlines[i] = outlineMembers(*o);
                outlines[i]["layout"] = (*layout)->kind;
            }
    }
    const auto answer = [&](const Scene& scene, const std::map<std::string, std::string>& ids) {
        json list = json::array();
        for (std::size_t i = 0; i < proposals.size(); ++i) {
            const Proposal& p = proposals[i];
            Placement placed = p.placement;
            if (auto it = ids.find(placed.id); it != ids.end()) placed.id = it->second;
            const std::string existing = existingFor(scene, p.placement);
            std::string twin = p.twin;
            if (auto it = ids.find(twin); it != ids.end()) twin = it->second;
            list.push_back({{"placement", placementJson(placed)},
                            {"kind", p.kind},
                            {"joint", p.placement.joint},
                            {"score", p.score},
                            {"twin", twin.empty() ? json() : json(twin)},
                            {"existing", existing.empty() || ids.count(p.placement.id) ? json() : json(existing)},
                            {"why", whyJson(p.why)},
                            {"outline", outlines[i]}});
        }
        return list;
    };
    if (!apply) {
        json out = {{"id", id}, {"applied", json::array()}};
        out["proposals"] = answer(snap->scene, {});
        return out;
    }
    std::map<std::string, std::string> ids; // proposal id → id in the scene
    json applied = json::array();
    EditInfo info{"placements_added", "propose", ""};
    auto edited = state_->edit(id, ctx, info, EditScope{EditScope::Kind::Whole, ""}, [&](json& doc) -> Status {
        auto now = state_->snapshot(id);
        if (!now) return now.error();
        ids.clear();
        applied = json::array();
        for (const Proposal& p : proposals) {
            if (!existingFor(now->scene, p.placement).empty()) continue;
            const std::string newId = uniquePlacementId(doc, p.placement.id);
            ids[p.placement.id] = newId;
            Placement placed = p.placement;
            placed.id = newId;
            doc["placements"].push_back(placementJson(placed));
            applied.push_back(newId);
        }
        if (applied.empty())
            return makeError(ErrorCode::Conflict, "dermis::Service::propose", "placements",
                             "every proposal is in the scene already");
        return Ok{};
    });
    if (!edited) return edited.error();
    json out = *edited;
    out["applied"] = applied;
    auto after = state_->snapshot(id);
    out["proposals"] = answer(after ? after->scene : snap->scene, ids);
    return out;
}

// --- transfer (SPEC §8) ----------------------------------------------------------------------

Result<json> Service::transfer(const std::string& id, const json& body, bool apply, const EditContext& ctx) {
    const char* where = "dermis::Service::transfer";
    if (!body.is_object()) return bad("", "the body must be {\"from\": \"<scene id>\", \"joint_map\": {…}?}");
    const auto from = body.find("from");
    if (from == body.end() || !from->is_string())
        return bad("/from", "\"from\" must name the scene whose placements to carry over");
    std::map<std::string, std::string> jointMap;
    if (const auto jm = body.find("joint_map"); jm != body.end()) {
        if (!jm->is_object()) return bad("/joint_map", "must map source joint names to this character's");
        for (auto e = jm->begin(); e != jm->end(); ++e) {
            if (!e->is_string()) return bad("/joint_map/" + e.key(), "must be a joint name");
            jointMap[e.key()] = e->get<std::string>();
        }
    }
    for (auto e = body.begin(); e != body.end(); ++e)
        if (e.key() != "from" && e.key() != "joint_map") return bad("/" + e.key(), "unknown member");
    auto source = state_->snapshot(from->get<std::string>());
    if (!source) {
        Error e = source.error();
        e.field = "/from";
        return e;
    }
    auto snap = state_->snapshot(id);
    if (!snap) return snap.error();
    // Derived data, built here, unlocked: the source's UV placements are read in the layout its
    // maps live in.
    const auto srcDerived = state_->derivedOf(*source);
    const auto srcLayout = state_->derivedInLayout(*source);
    const auto dstDerived = state_->derivedOf(*snap);
    const bool uvs = srcLayout->model().hasUVs();
    const TransferModel src{srcDerived->model(), srcDerived->restSkin(), srcDerived->bodyMap(),
                            uvs ? &srcLayout->uvLookup() : nullptr, &srcLayout->model()};
    const TransferModel dst{dstDerived->model(), dstDerived->restSkin(), dstDerived->bodyMap(), nullptr, nullptr};
    const TransferResult result = transferPlacements(source->scene.placements, src, dst, jointMap);
    json unmapped = json::array();
    for (const auto& u : result.unmapped)
        unmapped.push_back({{"placement", u.from}, {"field", u.field}, {"reason", u.reason}});
    json joints = json::object();
    for (const auto& [a, b] : result.joints) joints[a] = b;
    const auto listing = [&](const std::map<std::string, std::string>& ids) {
        json list = json::array();
        for (const auto& m : result.mapped) {
            Placement placed = m.placement;
            if (auto it = ids.find(m.from); it != ids.end()) placed.id = it->second;
            Scene one;
            one.placements.push_back(placed);
            list.push_back({{"from", m.from}, {"placement", toJson(one)["placements"][0]}});
        }
        return list;
    };
    if (!apply)
        return json{{"id", id}, {"from", *from}, {"transferred", listing({})}, {"unmapped", unmapped}, {"joints", joints}};
    if (result.mapped.empty())
        return makeError(ErrorCode::InvalidArgument, where, "/from",
                         "no placement of scene " + from->get<std::string>() + " could follow onto this character");
    std::map<std::string, std::string> ids;
    EditInfo info{"placements_added", "transfer from " + from->get<std::string>(), ""};
    auto edited = state_->edit(id, ctx, info, EditScope{EditScope::Kind::Whole, ""}, [&](json& doc) -> Status {
        ids.clear();
        for (const auto& m : result.mapped) {
            const std::string newId = uniquePlacementId(doc, m.from);
            ids[m.from] = newId;
            Placement placed = m.placement;
            placed.id = newId;
            Scene one;
            one.placements.push_back(placed);
            doc["placements"].push_back(toJson(one)["placements"][0]);
        }
        return Ok{};
    });
    if (!edited) return edited.error();
    json out = *edited;
    out["from"] = *from;
    out["transferred"] = listing(ids);
    out["unmapped"] = unmapped;
    out["joints"] = joints;
    return out;
}

} // namespace dermis
