// Scene documents and their edits: create, replace, delete; placements; pose.
#include "service/service_state.hpp"

#include <set>

namespace dermis {

using namespace detail;

Result<json> Service::State::commit(const std::string& id, const json& newDoc, const char* what,
                                    bool create) {
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
    if (auto s = store->putScene(id, revision, prepared.canonical); !s) return s.error();
    json answer = {{"id", id}, {"revision", revision}, {"scene", prepared.canonical}};
    {
        std::unique_lock<std::shared_mutex> lock(mutex);
        SceneEntry& e = scenes[id];
        e.doc = std::move(prepared.canonical);
        e.scene = std::move(prepared.scene);
        e.revision = revision;
    }
    publish(id, {{"type", what}, {"scene", id}, {"revision", revision}});
    return answer;
}

Result<json> Service::State::edit(const std::string& id, const char* what,
                                  const std::function<Status(json&)>& change) {
    std::lock_guard<std::mutex> write(writeMutex);
    json doc;
    {
        std::shared_lock<std::shared_mutex> lock(mutex);
        auto it = scenes.find(id);
        if (it == scenes.end()) return notFound("id", "no scene \"" + id + "\"");
        doc = it->second.doc;
    }
    if (auto s = change(doc); !s) return s.error();
    return commit(id, doc, what, false);
}

json Service::listScenes() const {
    std::shared_lock<std::shared_mutex> lock(state_->mutex);
    json out = json::array();
    for (const auto& [id, e] : state_->scenes)
        out.push_back({{"id", id}, {"revision", e.revision}, {"model", e.scene.model},
                       {"placements", e.scene.placements.size()}});
    return {{"scenes", out}};
}

Result<json> Service::createScene(const json& body) {
    if (!body.is_object()) return bad("", "a scene document must be a JSON object");
    json doc = body;
    if (auto dp = doc.find("default_patterns"); dp != doc.end()) {
        if (!dp->is_boolean()) return bad("/default_patterns", "must be true or false");
        const bool wanted = dp->get<bool>();
        doc.erase("default_patterns");
        if (wanted) {
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
    return state_->commit(Store::newId("s"), doc, "created", true);
}

Result<json> Service::getScene(const std::string& id) const {
    std::shared_lock<std::shared_mutex> lock(state_->mutex);
    auto it = state_->scenes.find(id);
    if (it == state_->scenes.end()) return notFound("id", "no scene \"" + id + "\"");
    return json{{"id", id}, {"revision", it->second.revision}, {"scene", it->second.doc}};
}

Result<json> Service::replaceScene(const std::string& id, const json& doc) {
    return state_->edit(id, "replaced", [&](json& d) -> Status {
        d = doc;
        return Ok{};
    });
}

Status Service::deleteScene(const std::string& id) {
    std::lock_guard<std::mutex> write(state_->writeMutex);
    {
        std::shared_lock<std::shared_mutex> lock(state_->mutex);
        if (!state_->scenes.count(id)) return notFound("id", "no scene \"" + id + "\"");
    }
    if (auto s = state_->store->removeScene(id); !s) return s;
    {
        std::unique_lock<std::shared_mutex> lock(state_->mutex);
        state_->scenes.erase(id);
    }
    state_->publish(id, {{"type", "deleted"}, {"scene", id}});
    std::lock_guard<std::mutex> sl(state_->subsMutex);
    auto [a, b] = state_->subs.equal_range(id);
    for (auto it = a; it != b; ++it)
        it->second->close();
    state_->subs.erase(id);
    return Ok{};
}

namespace {

/// Index of placement `pid` in doc["placements"], or −1.
int placementIndex(const json& doc, const std::string& pid) {
    const json& pl = doc["placements"];
    for (std::size_t i = 0; i < pl.size(); ++i)
        if (pl[i].value("id", "") == pid) return static_cast<int>(i);
    return -1;
}

} // namespace

Result<json> Service::addPlacement(const std::string& id, const json& placement) {
    if (!placement.is_object()) return bad("", "a placement must be a JSON object");
    return state_->edit(id, "placement_added", [&](json& doc) -> Status {
        json p = placement;
        if (!p.contains("id")) { // a fresh id that no other placement has
            std::string pid;
            for (int k = static_cast<int>(doc["placements"].size());; ++k) {
                pid = "p" + std::to_string(k);
                if (placementIndex(doc, pid) < 0) break;
            }
            p["id"] = pid;
        }
        doc["placements"].push_back(p);
        return Ok{};
    });
}

Result<json> Service::patchPlacement(const std::string& id, const std::string& pid, const json& patch) {
    if (!patch.is_object()) return bad("", "a placement patch must be a JSON object");
    if (auto i = patch.find("id"); i != patch.end() && (!i->is_string() || i->get<std::string>() != pid))
        return bad("/id", "a placement's id cannot be changed");
    return state_->edit(id, "placement_updated", [&](json& doc) -> Status {
        const int k = placementIndex(doc, pid);
        if (k < 0) return notFound("pid", "no placement \"" + pid + "\" in scene " + id);
        doc["placements"][static_cast<std::size_t>(k)].merge_patch(patch);
        return Ok{};
    });
}

Result<json> Service::deletePlacement(const std::string& id, const std::string& pid) {
    return state_->edit(id, "placement_deleted", [&](json& doc) -> Status {
        const int k = placementIndex(doc, pid);
        if (k < 0) return notFound("pid", "no placement \"" + pid + "\" in scene " + id);
        doc["placements"].erase(static_cast<std::size_t>(k));
        return Ok{};
    });
}

Result<json> Service::reorderPlacements(const std::string& id, const json& order) {
    if (!order.is_array()) return bad("", "the order must be an array of placement ids");
    return state_->edit(id, "placements_reordered", [&](json& doc) -> Status {
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

Result<json> Service::putPose(const std::string& id, const json& pose) {
    if (!pose.is_object()) return bad("/pose", "a pose must be a JSON object");
    return state_->edit(id, "pose", [&](json& doc) -> Status {
        doc["pose"] = pose;
        return Ok{};
    });
}

Result<json> Service::patchPose(const std::string& id, const json& patch) {
    if (!patch.is_object()) return bad("/pose", "a pose patch must be a JSON object");
    return state_->edit(id, "pose", [&](json& doc) -> Status {
        json& pose = doc["pose"];
        if (!pose.is_object()) pose = json::object();
        for (auto e = patch.begin(); e != patch.end(); ++e) {
            if (e.key() == "joints" && e->is_object()) {
                if (!pose["joints"].is_object()) pose["joints"] = json::object();
                for (auto j = e->begin(); j != e->end(); ++j) {
                    if (j->is_null()) pose["joints"].erase(j.key());
                    else pose["joints"][j.key()] = *j;
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
