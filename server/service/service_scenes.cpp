// Scene documents and their edits: create, replace, delete; placements; pose.
#include "service_state.hpp"

#include "core/mirror.hpp"

#include <set>

namespace dermis {

using namespace detail;

void SceneEntry::setCurrent(SceneVersion v) {
    doc = v.doc;
    scene = v.scene;
    revision = v.revision;
    recent.push_back(std::move(v));
    while (recent.size() > kRecentRevisions) recent.pop_front();
}

const SceneVersion* SceneEntry::recentVersion(std::uint64_t r) const {
    for (const SceneVersion& v : recent)
        if (v.revision == r) return &v;
    return nullptr;
}

int detail::placementIndex(const json& doc, const std::string& pid) {
    const auto pl = doc.find("placements");
    if (pl == doc.end() || !pl->is_array()) return -1;
    for (std::size_t i = 0; i < pl->size(); ++i)
        if ((*pl)[i].is_object() && (*pl)[i].value("id", "") == pid) return static_cast<int>(i);
    return -1;
}

std::string detail::uniquePlacementId(const json& doc, const std::string& base) {
    std::string id = base;
    for (int k = 2; placementIndex(doc, id) >= 0; ++k) id = base + "_" + std::to_string(k);
    return id;
}

namespace {

/// Placement `pid` of `doc`, or null when it has none.
json placementOf(const json& doc, const std::string& pid) {
    const int k = placementIndex(doc, pid);
    return k < 0 ? json() : doc["placements"][static_cast<std::size_t>(k)];
}

/// The placement ids of `doc`, in order.
std::vector<std::string> placementIds(const json& doc) {
    std::vector<std::string> ids;
    if (auto pl = doc.find("placements"); pl != doc.end() && pl->is_array())
        for (const json& p : *pl) ids.push_back(p.is_object() ? p.value("id", "") : "");
    return ids;
}

/// Why an edit of `scope` based on document `then` conflicts with document `now` ("" = it
/// does not: the edit may apply to `now`). See Service::State::checkIfMatch.
std::string conflictOf(const json& then, const json& now, const EditScope& scope) {
    if (then.value("model", "") != now.value("model", "")) return "the scene's model changed";
    switch (scope.kind) {
    case EditScope::Kind::Whole: return "the document changed";
    case EditScope::Kind::Add:
        if (scope.placement.empty()) return "";
        [[fallthrough]];
    case EditScope::Kind::Placement: {
        const json a = placementOf(then, scope.placement), b = placementOf(now, scope.placement);
        if (a == b) return "";
        const std::string p = "placement \"" + scope.placement + "\" ";
        return a.is_null() ? p + "was added" : b.is_null() ? p + "was deleted" : p + "changed";
    }
    case EditScope::Kind::Order:
        if (placementIds(then) == placementIds(now)) return "";
        return "the placements were added, deleted or reordered";
    case EditScope::Kind::Pose: {
        const auto a = then.find("pose"), b = now.find("pose");
        const bool same = (a == then.end() && b == now.end()) ||
                          (a != then.end() && b != now.end() && *a == *b);
        return same ? "" : "the pose changed";
    }
    }
    return "the document changed";
}

} // namespace

Status Service::State::checkIfMatch(const std::string& id, const EditContext& ctx,
                                    const EditScope& scope) {
    std::uint64_t current = 0;
    std::shared_ptr<const json> now, then;
    {
        std::shared_lock<std::shared_mutex> lock(mutex);
        auto it = scenes.find(id);
        if (it == scenes.end()) return notFound("id", "no scene \"" + id + "\"");
        current = it->second.revision;
        if (!ctx.ifMatch || *ctx.ifMatch == current) return Ok{};
        now = it->second.doc;
        if (const SceneVersion* v = it->second.recentVersion(*ctx.ifMatch)) then = v->doc;
    }
    const std::uint64_t base = *ctx.ifMatch;
    std::string why;
    if (scope.kind != EditScope::Kind::Whole && base < current) {
        if (!then) { // older than the recent ones: from the history (files are never rewritten)
            auto old = store->readRevision(id, base);
            if (old) then = std::make_shared<const json>(std::move(*old));
        }
        if (then) {
            why = conflictOf(*then, *now, scope);
            if (why.empty()) return Ok{}; // rebased: what the edit touches is as the client saw it
            why = ", and " + why + " since revision " + std::to_string(base);
        }
    }
    Error e = makeError(ErrorCode::StaleRevision, "dermis::Service", "If-Match",
                        "scene " + id + " is at revision " + std::to_string(current) + ", not " +
                            std::to_string(base) + why + ": read it again and redo the edit");
    e.currentRevision = current;
    return e;
}

Result<json> Service::State::commit(const std::string& id, const json& newDoc, const EditInfo& info,
                                    const EditContext& ctx, bool create) {
    Prepared prepared;
    std::uint64_t revision = 1;
    {
        std::shared_lock<std::shared_mutex> lock(mutex);
        auto p = prepare(newDoc);
        if (!p) return p.error();
        prepared = std::move(*p);
        if (!create) revision = scenes.at(id).revision + 1;
    }
    // Durable before visible; readers and renders go on meanwhile (writeMutex keeps other
    // mutations out, so the state validated above is still the state swapped into below).
    const Store::RevisionInfo kept{revision, nowSeconds(), info.op, ctx.client};
    auto canonical = std::make_shared<const json>(std::move(prepared.canonical));
    if (auto s = store->putScene(id, kept, canonical); !s) return s.error(); // keeps `canonical`
    json answer = {{"id", id}, {"revision", revision}, {"scene", *canonical}};
    SceneVersion version{revision, std::move(canonical),
                         std::make_shared<const Scene>(std::move(prepared.scene))};
    {
        std::unique_lock<std::shared_mutex> lock(mutex);
        SceneEntry& e = scenes[id];
        e.setCurrent(std::move(version));
        e.history.push_back(kept);
    }
    applyRetention(id);
    json event = {{"type", info.type}, {"scene", id},      {"revision", revision},
                  {"client", ctx.client}, {"op", info.op}, {"placement", info.placement}};
    if (info.placement.empty()) event["placement"] = nullptr;
    publish(id, event);
    return answer;
}

Result<json> Service::State::edit(const std::string& id, const EditContext& ctx, EditInfo& info,
                                  const EditScope& scope,
                                  const std::function<Status(json&)>& change) {
    std::lock_guard<std::mutex> write(writeMutex);
    if (auto s = checkIfMatch(id, ctx, scope); !s) return s.error();
    json doc;
    {
        std::shared_lock<std::shared_mutex> lock(mutex);
        auto it = scenes.find(id);
        if (it == scenes.end()) return notFound("id", "no scene \"" + id + "\"");
        doc = *it->second.doc;
    }
    if (auto s = change(doc); !s) return s.error();
    return commit(id, doc, info, ctx, false);
}

json Service::listScenes() const {
    std::shared_lock<std::shared_mutex> lock(state_->mutex);
    json out = json::array();
    for (const auto& [id, e] : state_->scenes)
        out.push_back({{"id", id}, {"revision", e.revision}, {"model", e.scene->model},
                       {"placements", e.scene->placements.size()}});
    return {{"scenes", out}};
}

Result<json> Service::createScene(const json& body, const EditContext& ctx) {
    if (!body.is_object()) return bad("", "a scene document must be a JSON object");
    json doc = body;
    if (auto dp = doc.find("default_patterns"); dp != doc.end()) {
        if (!dp->is_boolean()) return bad("/default_patterns", "must be true or false");
        const bool wanted = dp->get<bool>();
        doc.erase("default_patterns");
        if (wanted) {
            if (auto m = doc.find("model"); m != doc.end() && !m->is_string())
                return bad("/model", "must be a string (a model id)");
            if (doc.value("model", std::string(kBuiltinDefault)) != kBuiltinDefault)
                return bad("/default_patterns", "the default pattern set exists only for builtin:default");
            if (!state_->defaultSceneDoc.is_object())
                return makeError(ErrorCode::Unavailable, "dermis::Service", "/default_patterns",
                                 "the default pattern set is not installed");
            json base = state_->defaultSceneDoc;
            for (auto it = doc.begin(); it != doc.end(); ++it)
                base[it.key()] = it.value();
            doc = std::move(base);
        }
    }
    std::lock_guard<std::mutex> write(state_->writeMutex);
    return state_->commit(Store::newId("s"), doc, EditInfo{"created", "create", ""}, ctx, true);
}

Result<json> Service::getScene(const std::string& id) const {
    std::shared_lock<std::shared_mutex> lock(state_->mutex);
    auto it = state_->scenes.find(id);
    if (it == state_->scenes.end()) return notFound("id", "no scene \"" + id + "\"");
    return json{{"id", id}, {"revision", it->second.revision}, {"scene", *it->second.doc}};
}

Result<json> Service::replaceScene(const std::string& id, const json& doc, const EditContext& ctx) {
    EditInfo info{"replaced", "replace scene", ""};
    return state_->edit(id, ctx, info, EditScope{}, [&](json& d) -> Status {
        d = doc;
        return Ok{};
    });
}

Status Service::deleteScene(const std::string& id, const EditContext& ctx) {
    std::lock_guard<std::mutex> write(state_->writeMutex);
    if (auto s = state_->checkIfMatch(id, ctx, EditScope{}); !s) return s;
    if (auto s = state_->store->removeScene(id); !s) return s;
    {
        std::unique_lock<std::shared_mutex> lock(state_->mutex);
        state_->scenes.erase(id);
    }
    state_->publish(id, {{"type", "deleted"}, {"scene", id}, {"client", ctx.client}, {"op", "delete scene"}});
    {
        std::lock_guard<std::mutex> pl(state_->presenceMutex);
        state_->presence.erase(id);
    }
    std::lock_guard<std::mutex> sl(state_->subsMutex);
    auto [a, b] = state_->subs.equal_range(id);
    for (auto it = a; it != b; ++it)
        it->second->close();
    state_->subs.erase(id);
    return Ok{};
}

Result<json> Service::addPlacement(const std::string& id, const json& placement,
                                   const EditContext& ctx) {
    if (!placement.is_object()) return bad("", "a placement must be a JSON object");
    EditInfo info{"placement_added", "", ""};
    EditScope scope{EditScope::Kind::Add, ""};
    if (auto given = placement.find("id"); given != placement.end() && given->is_string())
        scope.placement = given->get<std::string>();
    return state_->edit(id, ctx, info, scope, [&](json& doc) -> Status {
        json p = placement;
        if (!p.contains("id")) { // a fresh id that no other placement has
            std::string pid;
            for (int k = static_cast<int>(doc["placements"].size());; ++k) {
                pid = "p" + std::to_string(k);
                if (placementIndex(doc, pid) < 0) break;
            }
            p["id"] = pid;
        }
        if (p["id"].is_string()) info.placement = p["id"].get<std::string>();
        info.op = "add placement " + info.placement;
        doc["placements"].push_back(p);
        return Ok{};
    });
}

Result<json> Service::patchPlacement(const std::string& id, const std::string& pid, const json& patch,
                                     const EditContext& ctx) {
    if (auto s = checkPlacementPatch(pid, patch); !s) return s.error(); // before the writer lock
    EditInfo info{"placement_updated", "patch placement " + pid, pid};
    const EditScope scope{EditScope::Kind::Placement, pid};
    return state_->edit(id, ctx, info, scope, [&](json& doc) -> Status {
        return mergePlacementPatch(doc, id, pid, patch);
    });
}

Status detail::checkPlacementPatch(const std::string& pid, const json& patch) {
    if (!patch.is_object()) return bad("", "a placement patch must be a JSON object");
    if (auto i = patch.find("id"); i != patch.end() && (!i->is_string() || i->get<std::string>() != pid))
        return bad("/id", "a placement's id cannot be changed");
    return Ok{};
}

Status detail::mergePlacementPatch(json& doc, const std::string& sceneId, const std::string& pid, const json& patch) {
    if (auto s = checkPlacementPatch(pid, patch); !s) return s;
    const int k = placementIndex(doc, pid);
    if (k < 0) return notFound("pid", "no placement \"" + pid + "\" in scene " + sceneId);
    doc["placements"][static_cast<std::size_t>(k)].merge_patch(patch);
    return Ok{};
}

Result<json> Service::deletePlacement(const std::string& id, const std::string& pid,
                                      const EditContext& ctx) {
    EditInfo info{"placement_deleted", "delete placement " + pid, pid};
    const EditScope scope{EditScope::Kind::Placement, pid};
    return state_->edit(id, ctx, info, scope, [&](json& doc) -> Status {
        const int k = placementIndex(doc, pid);
        if (k < 0) return notFound("pid", "no placement \"" + pid + "\" in scene " + id);
        doc["placements"].erase(static_cast<std::size_t>(k));
        return Ok{};
    });
}

Result<json> Service::mirrorPlacement(const std::string& id, const std::string& pid,
                                      const EditContext& ctx, bool update) {
    // The model's derived data (UV index, rest skin, symmetry plane) is built here, before the
    // writer lock, so that a first mirror on a large model holds no other edit back meanwhile.
    if (auto warm = state_->snapshot(id)) {
        const auto derived = state_->derivedInLayout(*warm);
        if (derived->model().hasUVs()) {
            derived->uvLookup();
            derived->symmetryPlane();
        }
    }
    EditInfo info{"placement_added", "mirror placement " + pid, ""};
    const EditScope scope{EditScope::Kind::Placement, pid};
    return state_->edit(id, ctx, info, scope, [&](json& doc) -> Status {
        // Under writeMutex: the snapshot is the document being edited.
        auto snap = state_->snapshot(id);
        if (!snap) return snap.error();
        const Placement* source = nullptr;
        for (const Placement& p : snap->scene.placements)
            if (p.id == pid) source = &p;
        const int at = placementIndex(doc, pid);
        if (!source || at < 0)
            return notFound("pid", "no placement \"" + pid + "\" in scene " + id);
        // UV index, plane and rest skin, built once, in the layout the scene's maps live in.
        const auto derived = state_->derivedInLayout(*snap);
        auto twin = dermis::mirrorPlacement(*source, derived->model(), derived->uvLookup(),
                                            derived->symmetryPlane(), derived->restSkin());
        if (!twin) {
            Error e = twin.error();
            e.code = ErrorCode::InvalidArgument; // the placement cannot be mirrored: 422
            // Fields of the placement (or of the layout its maps live in) in the scene document.
            e.field = e.field == "/uvs" ? "/uv_layout" : "/placements/" + std::to_string(at) + "/" + e.field;
            return e;
        }
        // Mirroring twice stacks nothing: a placement that already is the twin answers 409.
        if (const int k = findMirrorTwin(snap->scene, *twin); k >= 0) {
            const std::string& existing = snap->scene.placements[static_cast<std::size_t>(k)].id;
            const int there = placementIndex(doc, existing);
            if (update && existing != pid && there >= 0) {
                // The twin is brought up to date in place: its id and order kept.
                info.type = "placement_updated";
                info.op = "mirror placement " + pid + " onto " + existing;
                info.placement = existing;
                Scene one;
                one.placements.push_back(*twin);
                one.placements[0].id = existing;
                one.placements[0].pattern = doc["placements"][static_cast<std::size_t>(at)]["pattern"];
                doc["placements"][static_cast<std::size_t>(there)] = dermis::toJson(one)["placements"][0];
                return Ok{};
            }
            const std::string why =
                existing == pid ? "placement \"" + pid + "\" is its own mirror twin (it lies on "
                                  "the model's symmetry plane)"
                                : "placement \"" + existing + "\" already is the mirror twin of \"" +
                                      pid + "\" (same joint, pattern and target, centre within " +
                                      std::to_string(static_cast<int>(kMirrorCenterTexels)) +
                                      " texels of where it mirrors to)";
            return makeError(ErrorCode::Conflict, "dermis::Service::mirrorPlacement", "placement", why);
        }
        // The twin's id: the source's with its side swapped (elbow_l → elbow_r), else from the
        // twin joint's side or "<pid>_twin"; "_2", "_3"… only when that is taken.
        const std::string newId = uniquePlacementId(doc, mirrorPlacementId(pid, twin->joint));
        info.placement = newId;
        // toJson of a one-placement scene gives the placement's canonical form.
        Scene one;
        one.placements.push_back(*twin);
        one.placements[0].id = newId;
        one.placements[0].pattern = doc["placements"][static_cast<std::size_t>(at)]["pattern"];
        doc["placements"].push_back(dermis::toJson(one)["placements"][0]);
        return Ok{};
    });
}

Result<json> Service::reorderPlacements(const std::string& id, const json& order,
                                        const EditContext& ctx) {
    if (!order.is_array()) return bad("", "the order must be an array of placement ids");
    EditInfo info{"placements_reordered", "reorder placements", ""};
    return state_->edit(id, ctx, info, EditScope{EditScope::Kind::Order, ""}, [&](json& doc) -> Status {
        const json& old = doc["placements"];
        if (order.size() != old.size())
            return bad("", "the order must list each of the " + std::to_string(old.size()) + " placements once");
        json reordered = json::array();
        std::set<std::string> seen;
        for (std::size_t i = 0; i < order.size(); ++i) {
            const std::string f = "/" + std::to_string(i);
            if (!order[i].is_string()) return bad(f, "must be a placement id");
            const std::string pid = order[i].get<std::string>();
            const int k = placementIndex(doc, pid);
            if (k < 0) return notFound(f, "no placement \"" + pid + "\"");
            if (!seen.insert(pid).second) return bad(f, "placement \"" + pid + "\" listed twice");
            reordered.push_back(old[static_cast<std::size_t>(k)]);
        }
        doc["placements"] = std::move(reordered);
        return Ok{};
    });
}

Result<json> Service::putPose(const std::string& id, const json& pose, const EditContext& ctx) {
    if (!pose.is_object()) return bad("/pose", "a pose must be a JSON object");
    EditInfo info{"pose", "set pose", ""};
    return state_->edit(id, ctx, info, EditScope{EditScope::Kind::Pose, ""}, [&](json& doc) -> Status {
        doc["pose"] = pose;
        return Ok{};
    });
}

Result<json> Service::patchPose(const std::string& id, const json& patch, const EditContext& ctx) {
    if (!patch.is_object()) return bad("/pose", "a pose patch must be a JSON object");
    EditInfo info{"pose", "patch pose", ""};
    return state_->edit(id, ctx, info, EditScope{EditScope::Kind::Pose, ""}, [&](json& doc) -> Status {
        json& pose = doc["pose"];
        if (!pose.is_object()) pose = json::object();
        for (auto e = patch.begin(); e != patch.end(); ++e) {
            if ((e.key() == "joints" || e.key() == "morphs") && e->is_object()) {
                // Member by member (null removes one), like the joints the morph weights.
                json& members = pose[e.key()];
                if (!members.is_object()) members = json::object();
                for (auto j = e->begin(); j != e->end(); ++j) {
                    if (j->is_null()) members.erase(j.key());
                    else members[j.key()] = *j;
                }
            } else if (e->is_null()) {
                pose.erase(e.key());
            } else {
                pose[e.key()] = *e;
            }
        }
        return Ok{};
    });
}

} // namespace dermis
