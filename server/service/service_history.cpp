// Scene history (SPEC §6 History): revisions listed newest first, any revision read back,
// revert as a new revision; and presence — what each person has selected, broadcast and kept
// for kPresenceSeconds after the last refresh.
#include "service_state.hpp"

#include <algorithm>
#include <cmath>
#include <ctime>

namespace dermis {

using namespace detail;

namespace {

/// RFC 3339 in UTC with milliseconds, e.g. "2026-11-23T19:05:00.123Z".
std::string rfc3339(double seconds) {
    const double whole = std::floor(seconds);
    const std::time_t t = static_cast<std::time_t>(whole);
    std::tm utc{};
    gmtime_r(&t, &utc);
    char buf[96];
    const int ms = std::clamp(static_cast<int>(std::lround((seconds - whole) * 1000.0)), 0, 999);
    std::snprintf(buf, sizeof buf, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", utc.tm_year + 1900,
                  utc.tm_mon + 1, utc.tm_mday, utc.tm_hour, utc.tm_min, utc.tm_sec, ms);
    return buf;
}

json revisionJson(const Store::RevisionInfo& r) {
    return {{"revision", r.revision}, {"time", rfc3339(r.time)}, {"op", r.op}, {"client", r.client}};
}

constexpr std::size_t kMaxSelection = 256;
constexpr std::size_t kMaxColor = 32;

} // namespace

Status detail::keptRevision(const std::string& id, const SceneEntry& e, std::uint64_t revision,
                            const std::string& flag) {
    if (revision == 0 || revision >= e.droppedBefore) return Ok{};
    return makeError(ErrorCode::Gone, "dermis::Service", "revision",
                     "scene " + id + ": revision " + std::to_string(revision) +
                         " was dropped by the history retention (" +
                         (flag.empty() ? "an earlier --history-keep" : flag) +
                         "); the oldest kept revision is " + std::to_string(e.droppedBefore));
}

void Service::State::applyRetention(const std::string& id) {
    if (limits.historyKeep.keepsAll()) return;
    std::uint64_t oldest = 0;
    std::vector<Store::RevisionInfo> kept;
    {
        std::unique_lock<std::shared_mutex> lock(mutex);
        auto it = scenes.find(id);
        if (it == scenes.end()) return;
        SceneEntry& e = it->second;
        oldest = oldestKept(e.history, limits.historyKeep, nowSeconds());
        auto cut = std::lower_bound(e.history.begin(), e.history.end(), oldest,
                                    [](const Store::RevisionInfo& r, std::uint64_t b) {
                                        return r.revision < b;
                                    });
        if (cut != e.history.begin()) {
            e.history.erase(e.history.begin(), cut);
            e.droppedBefore = std::max(e.droppedBefore, oldest);
        }
        if (e.droppedBefore == 0 || !store->compactionDue(id, e.droppedBefore)) return;
        oldest = e.droppedBefore;
        kept = e.history;
    }
    (void)store->dropRevisionsBefore(id, oldest, kept); // a failure: tried again at the next edit
}

std::string checkClientName(const std::string& name) {
    if (name.size() > 64) return "longer than 64 characters";
    for (unsigned char c : name)
        if (c < 0x20 || c > 0x7e) return "only printable ASCII characters may name a client";
    return "";
}

Result<json> Service::listRevisions(const std::string& id, std::size_t limit,
                                    std::optional<std::uint64_t> before) const {
    if (limit < 1 || limit > 1000) return bad("limit", "must be in [1, 1000]");
    std::shared_lock<std::shared_mutex> lock(state_->mutex);
    auto it = state_->scenes.find(id);
    if (it == state_->scenes.end()) return notFound("id", "no scene \"" + id + "\"");
    const auto& h = it->second.history;
    // Newest first, strictly below `before`: binary search in the ascending list.
    auto end = before ? std::lower_bound(h.begin(), h.end(), *before,
                                         [](const Store::RevisionInfo& r, std::uint64_t b) {
                                             return r.revision < b;
                                         })
                      : h.end();
    json list = json::array();
    for (auto r = std::make_reverse_iterator(end); r != h.rend() && list.size() < limit; ++r)
        list.push_back(revisionJson(*r));
    return json{{"id", id}, {"revision", it->second.revision}, {"revisions", std::move(list)}};
}

Result<std::string> Service::getSceneRevisionText(const std::string& id, std::uint64_t revision) const {
    std::uint64_t current = 0;
    std::shared_ptr<const json> recent;
    {
        std::shared_lock<std::shared_mutex> lock(state_->mutex);
        auto it = state_->scenes.find(id);
        if (it == state_->scenes.end()) return notFound("id", "no scene \"" + id + "\"");
        current = it->second.revision;
        if (revision == 0 || revision > current)
            return notFound("revision", "scene " + id + " has no revision " +
                                            std::to_string(revision) + " (current: " +
                                            std::to_string(current) + ")");
        if (auto s = keptRevision(id, it->second, revision, state_->limits.historyKeep.flag()); !s)
            return s.error();
        if (const SceneVersion* v = it->second.recentVersion(revision)) recent = v->doc;
    }
    // Older revisions are read from disk, outside the lock (a chunk is only appended to; a
    // compaction deletes files of dropped revisions only).
    std::string scene;
    if (recent) {
        scene = recent->dump();
    } else {
        auto text = state_->store->readRevisionText(id, revision);
        if (!text) {
            if (text.error().code == ErrorCode::NotFound) { // dropped (and compacted) meanwhile?
                std::shared_lock<std::shared_mutex> lock(state_->mutex);
                auto it = state_->scenes.find(id);
                if (it != state_->scenes.end())
                    if (auto s = keptRevision(id, it->second, revision, state_->limits.historyKeep.flag()); !s)
                        return s.error();
            }
            return text.error();
        }
        scene = std::move(*text);
    }
    // {"current_revision", "id", "revision", "scene"}: dump()'s order (keys sorted).
    std::string answer = json{{"current_revision", current}, {"id", id}, {"revision", revision}}.dump();
    answer.pop_back();
    answer.reserve(answer.size() + scene.size() + 10);
    answer += ",\"scene\":";
    answer += scene;
    answer += '}';
    return answer;
}

Result<json> Service::getSceneRevision(const std::string& id, std::uint64_t revision) const {
    auto text = getSceneRevisionText(id, revision);
    if (!text) return text.error();
    json answer = json::parse(*text, nullptr, false);
    if (answer.is_discarded())
        return makeError(ErrorCode::Parse, "dermis::Service", "revision",
                         "scene " + id + ": revision " + std::to_string(revision) + " is damaged in the history");
    return answer;
}

Result<json> Service::revert(const std::string& id, std::uint64_t revision, const EditContext& ctx) {
    std::lock_guard<std::mutex> write(state_->writeMutex);
    if (auto s = state_->checkIfMatch(id, ctx, EditScope{}); !s) return s.error();
    std::shared_ptr<const json> recent;
    {
        std::shared_lock<std::shared_mutex> lock(state_->mutex);
        auto it = state_->scenes.find(id);
        if (it == state_->scenes.end()) return notFound("id", "no scene \"" + id + "\"");
        if (revision == 0 || revision > it->second.revision)
            return notFound("/revision", "scene " + id + " has no revision " +
                                             std::to_string(revision));
        if (auto s = keptRevision(id, it->second, revision, state_->limits.historyKeep.flag()); !s) {
            Error e = s.error();
            e.field = "/revision";
            return e;
        }
        if (const SceneVersion* v = it->second.recentVersion(revision)) recent = v->doc;
    }
    if (recent) // undo and redo of a recent edit: no file to read
        return state_->commit(id, *recent,
                              EditInfo{"reverted", "revert to " + std::to_string(revision), ""},
                              ctx, false);
    auto doc = state_->store->readRevision(id, revision);
    if (!doc) {
        Error e = doc.error();
        if (e.code == ErrorCode::NotFound) e.field = "/revision";
        return e;
    }
    return state_->commit(id, *doc, EditInfo{"reverted", "revert to " + std::to_string(revision), ""},
                          ctx, false);
}

json Service::State::livePresence(const std::string& sceneId) {
    const double now = nowSeconds();
    json live = json::array();
    auto sceneIt = presence.find(sceneId);
    if (sceneIt == presence.end()) return live;
    for (auto it = sceneIt->second.begin(); it != sceneIt->second.end();) {
        if (it->second.expires <= now) {
            publish(sceneId,
                    {{"type", "presence"}, {"scene", sceneId}, {"client", it->first},
                     {"selection", json::array()}, {"color", it->second.color}, {"left", true}},
                    "presence");
            it = sceneIt->second.erase(it);
            continue;
        }
        live.push_back({{"client", it->first}, {"selection", it->second.selection},
                        {"color", it->second.color}, {"expires_in", it->second.expires - now}});
        ++it;
    }
    if (sceneIt->second.empty()) presence.erase(sceneIt);
    return live;
}

Result<json> Service::postPresence(const std::string& id, const json& body, const std::string& address) {
    if (!body.is_object()) return bad("", "presence must be a JSON object");
    for (auto it = body.begin(); it != body.end(); ++it)
        if (it.key() != "client" && it.key() != "selection" && it.key() != "color")
            return bad("/" + it.key(), "unknown field (client, selection, color)");
    const auto client = body.find("client");
    if (client == body.end() || !client->is_string() || client->get<std::string>().empty())
        return bad("/client", "must name the client (a non-empty string)");
    if (auto why = checkClientName(client->get<std::string>()); !why.empty()) return bad("/client", why);
    json selection = json::array();
    if (auto sel = body.find("selection"); sel != body.end()) {
        if (!sel->is_array()) return bad("/selection", "must be an array of placement ids");
        if (sel->size() > kMaxSelection)
            return bad("/selection", "at most " + std::to_string(kMaxSelection) + " placements");
        for (std::size_t k = 0; k < sel->size(); ++k)
            if (!(*sel)[k].is_string() || (*sel)[k].get<std::string>().size() > 64)
                return bad("/selection/" + std::to_string(k), "must be a placement id");
        selection = *sel;
    }
    std::string color;
    if (auto c = body.find("color"); c != body.end()) {
        if (!c->is_string() || c->get<std::string>().size() > kMaxColor)
            return bad("/color", "must be a CSS colour of at most 32 characters");
        color = c->get<std::string>();
    }
    {
        std::shared_lock<std::shared_mutex> lock(state_->mutex);
        if (!state_->scenes.count(id)) return notFound("id", "no scene \"" + id + "\"");
    }
    std::lock_guard<std::mutex> pl(state_->presenceMutex);
    const std::string name = client->get<std::string>();
    state_->livePresence(id); // lapsed entries go first (and are announced)
    auto& entries = state_->presence[id];
    if (!entries.count(name)) {
        // A new name: within its address's share (its entry nearest to lapsing makes room), and
        // within the scene's.
        std::vector<decltype(entries.begin())> mine;
        for (auto it = entries.begin(); it != entries.end(); ++it)
            if (it->second.address == address) mine.push_back(it);
        if (mine.size() >= kMaxPresencePerAddress) {
            auto oldest = *std::min_element(mine.begin(), mine.end(), [](const auto& a, const auto& b) {
                return a->second.expires < b->second.expires;
            });
            state_->publish(id,
                            {{"type", "presence"}, {"scene", id}, {"client", oldest->first},
                             {"selection", json::array()}, {"color", oldest->second.color}, {"left", true}},
                            "presence");
            entries.erase(oldest);
        } else if (entries.size() >= kMaxPresencePerScene) {
            return makeError(ErrorCode::Unavailable, "dermis::Service::postPresence", "/client",
                             std::to_string(kMaxPresencePerScene) +
                                 " people are on this scene, the most its presence lists; retry later");
        }
    }
    PresenceEntry& e = entries[name];
    e.address = address;
    e.selection = selection;
    e.color = color;
    e.expires = nowSeconds() + limits_.presenceSeconds;
    state_->publish(id,
                    {{"type", "presence"}, {"scene", id}, {"client", name}, {"selection", selection},
                     {"color", color}, {"expires_in", limits_.presenceSeconds}},
                    "presence");
    return json{{"scene", id}, {"presence", state_->livePresence(id)}};
}

Result<json> Service::listPresence(const std::string& id) {
    {
        std::shared_lock<std::shared_mutex> lock(state_->mutex);
        if (!state_->scenes.count(id)) return notFound("id", "no scene \"" + id + "\"");
    }
    std::lock_guard<std::mutex> pl(state_->presenceMutex);
    return json{{"scene", id}, {"presence", state_->livePresence(id)}};
}

} // namespace dermis
