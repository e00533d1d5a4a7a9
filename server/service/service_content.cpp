// Content addresses in batches (SPEC §7, issue #15): a stateless batch may name its model,
// patterns and environment as "sha256:<hex>" so that any replica can serve it. What a replica
// lacks it lists in a MissingContent error; the client sends those bytes along (multipart parts
// named by address), which are checked, decoded by the role the document gives them and kept in
// the content cache.
#include "service_state.hpp"

#include "common/sha256.hpp"
#include "service/store.hpp"

#include <algorithm>

namespace dermis {

using namespace detail;

namespace {

constexpr const char* kWhere = "dermis::Service::batch";
constexpr const char* kPrefix = "sha256:";

enum class Role { Model, Pattern, Environment };

/// Where a document names a content address, and as what.
struct Ref {
    std::string address, field;
    Role role;
};

/// The role with its article, for messages.
const char* roleName(Role r) {
    return r == Role::Model ? "a model" : r == Role::Pattern ? "a pattern" : "an environment";
}

/// Whether `item` holds content of `role`.
bool holds(const ContentCache::Item& item, Role role) {
    return role == Role::Model ? bool(item.model) : role == Role::Pattern ? bool(item.pattern) : bool(item.environment);
}

/// Every member of `doc` that may name content and does so with the "sha256:" prefix: the model,
/// the pattern map's values, placements' patterns, the height map's base and the render's
/// environment. Other members are left to the scene parser. Fails on a malformed address.
Result<std::vector<Ref>> collectRefs(const json& doc) {
    std::vector<Ref> out;
    const auto consider = [&](const json& v, const std::string& field, Role role) -> Status {
        if (!v.is_string()) return Ok{};
        const std::string s = v.get<std::string>();
        if (s.rfind(kPrefix, 0) != 0) return Ok{};
        if (!isContentAddress(s))
            return makeError(ErrorCode::InvalidArgument, kWhere, "/scene" + field,
                             "a content address is \"sha256:\" followed by 64 lower-case hex digits");
        out.push_back({s, "/scene" + field, role});
        return Ok{};
    };
    if (!doc.is_object()) return out;
    if (auto m = doc.find("model"); m != doc.end())
        if (auto s = consider(*m, "/model", Role::Model); !s) return s.error();
    if (auto pm = doc.find("patterns"); pm != doc.end() && pm->is_object())
        for (auto it = pm->begin(); it != pm->end(); ++it)
            if (auto s = consider(*it, "/patterns/" + jsonPointerEscape(it.key()), Role::Pattern); !s) return s.error();
    if (auto pl = doc.find("placements"); pl != doc.end() && pl->is_array())
        for (std::size_t k = 0; k < pl->size(); ++k)
            if (const json& p = (*pl)[k]; p.is_object())
                if (auto pat = p.find("pattern"); pat != p.end())
                    if (auto s = consider(*pat, "/placements/" + std::to_string(k) + "/pattern", Role::Pattern); !s)
                        return s.error();
    if (auto hm = doc.find("heightmap"); hm != doc.end() && hm->is_object())
        if (auto base = hm->find("base"); base != hm->end())
            if (auto s = consider(*base, "/heightmap/base", Role::Pattern); !s) return s.error();
    if (auto r = doc.find("render"); r != doc.end() && r->is_object())
        if (auto env = r->find("environment"); env != r->end())
            if (auto s = consider(*env, "/render/environment", Role::Environment); !s) return s.error();
    return out;
}

} // namespace

bool detail::isContentAddress(const std::string& s) {
    const std::size_t n = std::char_traits<char>::length(kPrefix);
    if (s.size() != n + 64 || s.compare(0, n, kPrefix) != 0) return false;
    return std::all_of(s.begin() + static_cast<std::ptrdiff_t>(n), s.end(),
                       [](char c) { return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'); });
}

Result<ContentOverlay> Service::State::resolveContent(
    const json& doc, const std::map<std::string, std::vector<std::uint8_t>>& inlineParts) {
    auto refs = collectRefs(doc);
    if (!refs) return refs.error();
    std::map<std::string, const Ref*> wanted; // address → its first use
    for (const Ref& r : *refs) {
        auto [it, added] = wanted.emplace(r.address, &r);
        if (!added && it->second->role != r.role)
            return makeError(ErrorCode::InvalidArgument, kWhere, r.field,
                             "names " + r.address.substr(0, 19) + "… as " + roleName(r.role) + ", but " +
                                 it->second->field + " names it as " + roleName(it->second->role));
    }
    ContentOverlay out;
    const auto hold = [&](const std::string& address, const ContentCache::Item& item) {
        if (item.model) out.models[address] = item.model;
        if (item.model && item.derived) out.derived[address] = item.derived;
        if (item.pattern) out.images[address] = item.pattern;
        if (item.environment) out.environments[address] = item.environment;
    };

    // The parts sent along: all checked against their names first (nothing is kept from a batch
    // with a wrong part), then decoded as the document uses them and cached. Parts the document
    // does not name are ignored (not hashed, decoded or kept).
    for (const auto& [address, bytes] : inlineParts) {
        if (!isContentAddress(address))
            return makeError(ErrorCode::InvalidArgument, kWhere, address.substr(0, 80),
                             "a content part is named \"sha256:\" followed by the 64 lower-case hex digits of its bytes' SHA-256");
        if (!wanted.count(address)) continue;
        const std::string actual = kPrefix + toHex(sha256(bytes));
        if (actual != address)
            return makeError(ErrorCode::InvalidArgument, kWhere, address,
                             "the part's bytes have the address " + actual + ", not its name");
    }
    for (const auto& [address, bytes] : inlineParts) {
        auto use = wanted.find(address);
        if (use == wanted.end()) continue;
        // Sent again although cached (the client cannot know): not decoded twice.
        if (ContentCache::Item cached = content->find(address); holds(cached, use->second->role)) {
            hold(address, cached);
            continue;
        }
        ContentCache::Item item;
        std::size_t cost = 0;
        if (use->second->role == Role::Model) {
            auto model = decodeModelBytes(bytes, limits, kWhere, address);
            if (!model) {
                Error e = model.error();
                e.message = std::string(kWhere) + ": " + address + " (" + use->second->field + "): " + e.message;
                return e;
            }
            cost = ContentCache::approxBytes(*model);
            item.model = std::make_shared<const Model>(std::move(*model));
            item.derived = std::make_shared<const ModelDerived>(item.model);
        } else if (use->second->role == Role::Environment) {
            auto env = decodeEnvironmentBytes(bytes, store->dir(), limits.maxImageSide, address);
            if (!env) {
                Error e = env.error();
                e.message = std::string(kWhere) + ": " + address + " (" + use->second->field + "): " + e.message;
                return e;
            }
            item.environment = std::make_shared<const EnvironmentImage>(std::move(*env));
            cost = ContentCache::approxBytes(*item.environment);
        } else {
            auto img = decodePatternBytes(bytes, limits, kWhere, address, decodeBudget.get());
            if (!img) {
                Error e = img.error();
                e.message = std::string(kWhere) + ": " + address + " (" + use->second->field + "): " + e.message;
                return e;
            }
            item.pattern = makePatternImage(std::move(*img));
            cost = ContentCache::approxBytes(*item.pattern);
        }
        hold(address, item);
        // What the cache lets go is freed on the GPU too (a later use uploads it again).
        for (const ContentCache::Item& gone : content->put(address, std::move(item), cost)) {
            if (gone.pattern) renderer->forgetPattern(gone.pattern->contentId);
            if (gone.model) renderer->forgetModel(gone.model);
        }
    }

    // The rest: the content cache, then stored uploads with that SHA-256.
    std::vector<std::string> missing;
    std::string firstField;
    std::shared_lock<std::shared_mutex> lock(mutex);
    std::vector<std::pair<std::string, std::string>> storedEnvironments; // address, upload id
    for (const auto& [address, ref] : wanted) {
        if (out.models.count(address) || out.images.count(address) || out.environments.count(address)) continue;
        ContentCache::Item item = content->find(address);
        if (!holds(item, ref->role)) {
            item = {};
            const std::string hex = address.substr(std::char_traits<char>::length(kPrefix));
            if (ref->role == Role::Environment) {
                // An upload's id is its SHA-256's prefix (Store::contentId); decoded below, unlocked.
                const std::string id = Store::contentId("e", hex);
                if (environments.count(id)) {
                    storedEnvironments.emplace_back(address, id);
                    continue;
                }
            } else if (ref->role == Role::Model) {
                for (const auto& [id, e] : models)
                    if (e.sha256 == hex) {
                        item.model = e.model;
                        if (e.derived) item.derived = e.derived->get(e.model);
                    }
            } else {
                for (const auto& [id, e] : patterns)
                    if (e.sha256 == hex)
                        if (auto img = images.find(id); img != images.end()) item.pattern = img->second;
            }
        }
        if (holds(item, ref->role)) {
            hold(address, item);
            continue;
        }
        missing.push_back(address);
    }
    lock.unlock();
    if (!missing.empty()) {
        for (const Ref& r : *refs)
            if (std::find(missing.begin(), missing.end(), r.address) != missing.end()) {
                firstField = r.field;
                break;
            }
        Error e = makeError(ErrorCode::MissingContent, kWhere, firstField,
                            "this server lacks " + std::to_string(missing.size()) +
                                " content item(s) the batch names by address: send the batch again as "
                                "multipart/form-data, part \"request\" with the JSON and one part per "
                                "listed address (named by it) with the bytes");
        e.missing = std::move(missing);
        return e;
    }
    for (const auto& [address, id] : storedEnvironments) {
        auto image = environmentImage(id);
        if (!image) return image.error();
        out.environments[address] = std::move(*image);
    }
    return out;
}

} // namespace dermis
