// Dermis core — the pattern manifest `dermis.patterns/1` (SPEC §3): parsing with JSON-pointer
// errors and per-kind defaults (parsePatternManifest), lookup by id, serialisation. The reader and
// the shared predicates live in scene_json.hpp.
#include "scene.hpp"

#include "scene_json.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <set>
#include <string_view>
#include <utility>

namespace dermis {

using namespace scene_detail;

namespace {

constexpr const char* kManifestWhere = "dermis::parsePatternManifest";
constexpr const char* kManifestFormat = "dermis.patterns/1";

/// Built-in pattern ids: [a-z0-9_]+.
bool isManifestId(std::string_view s) {
    if (s.empty() || s.size() > kMaxIdLength) return false;
    return std::all_of(s.begin(), s.end(), [](char c) {
        return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
    });
}

/// A manifest's file name: relative, '/'-separated, no empty, "." or ".." segments, no backslash,
/// colon (drive letters, URLs) or control characters — it must stay inside the manifest's folder.
bool isPlainRelativePath(std::string_view f) {
    if (f.empty() || f.size() > kMaxPathLength) return false;
    for (char c : f)
        if (c == '\\' || c == ':' || static_cast<unsigned char>(c) < 0x20) return false;
    std::size_t start = 0;
    while (true) {
        const std::size_t slash = f.find('/', start);
        const std::string_view seg = f.substr(
            start, slash == std::string_view::npos ? std::string_view::npos : slash - start);
        if (seg.empty() || seg == "." || seg == "..") return false;
        if (slash == std::string_view::npos) return true;
        start = slash + 1;
    }
}

} // namespace

const PatternInfo* PatternManifest::find(const std::string& id) const {
    for (const PatternInfo& p : patterns)
        if (p.id == id) return &p;
    return nullptr;
}

Result<PatternManifest> parsePatternManifest(const json& doc) {
    const Reader rd(kManifestWhere);
    if (auto s = rd.object(doc, ""); !s) return s.error();
    const json* format = Reader::find(doc, "format");
    if (!format) return rd.bad("/format", std::string("is required (\"") + kManifestFormat + "\")");
    auto f = rd.string(*format, "/format");
    if (!f) return f.error();
    if (*f != kManifestFormat)
        return rd.bad("/format",
                      "must be \"" + std::string(kManifestFormat) + "\", got '" + *f + "'",
                      formatErrorCode(*f, "dermis.patterns/"));

    const json* list = Reader::find(doc, "patterns");
    if (!list) return rd.bad("/patterns", "is required");
    if (auto s = rd.array(*list, "/patterns"); !s) return s.error();

    PatternManifest out;
    std::set<std::string> ids;
    for (std::size_t i = 0; i < list->size(); ++i) {
        const json& e = (*list)[i];
        const std::string ptr = member("/patterns", i);
        if (auto s = rd.object(e, ptr); !s) return s.error();
        PatternInfo info;

        const json* id = Reader::find(e, "id");
        if (!id) return rd.bad(ptr + "/id", "is required");
        auto idStr = rd.string(*id, ptr + "/id");
        if (!idStr) return idStr.error();
        if (!isManifestId(*idStr))
            return rd.bad(ptr + "/id", "pattern id '" + *idStr + "' must match [a-z0-9_]+");
        if (!ids.insert(*idStr).second)
            return rd.bad(ptr + "/id", "duplicate pattern id '" + *idStr + "'");
        info.id = *idStr;

        const json* file = Reader::find(e, "file");
        if (!file) return rd.bad(ptr + "/file", "is required");
        auto fileStr = rd.string(*file, ptr + "/file");
        if (!fileStr) return fileStr.error();
        if (!isPlainRelativePath(*fileStr))
            return rd.bad(ptr + "/file", "'" + *fileStr +
                                             "' must be a relative path inside the manifest's "
                                             "folder (no '..', '\\', ':' or leading '/')");
        info.file = *fileStr;

        const json* kind = Reader::find(e, "kind");
        if (!kind) return rd.bad(ptr + "/kind", "is required");
        auto k = rd.enumeration(*kind, ptr + "/kind", patternKindFromString,
                                "\"wrinkle\", \"bulge\" or \"bone\"");
        if (!k) return k.error();
        info.kind = *k;
        info.model = defaultModel(*k);
        info.target = defaultTarget(*k);

        if (const json* m = Reader::find(e, "model")) {
            auto parsed =
                rd.enumeration(*m, ptr + "/model", deformModelFromString, "\"scale\" or \"bias\"");
            if (!parsed) return parsed.error();
            info.model = *parsed;
        }
        if (const json* t = Reader::find(e, "target")) {
            auto parsed = rd.enumeration(*t, ptr + "/target", targetFromString,
                                         "\"bump\" or \"displacement\"");
            if (!parsed) return parsed.error();
            info.target = *parsed;
        }
        if (const json* j = Reader::find(e, "joint")) {
            auto s = rd.string(*j, ptr + "/joint", false);
            if (!s) return s.error();
            info.joint = *s;
        }
        if (const json* a = Reader::find(e, "axis")) {
            auto s = rd.string(*a, ptr + "/axis");
            if (!s) return s.error();
            if (!namedAxis(*s)) return rd.bad(ptr + "/axis", "must be \"x\", \"y\" or \"z\"");
            info.axis = *s;
        }
        if (const json* t = Reader::find(e, "theta_min")) {
            auto d = rd.number(*t, ptr + "/theta_min");
            if (!d) return d.error();
            info.thetaMin = *d;
        }
        if (const json* t = Reader::find(e, "theta_max")) {
            auto d = rd.number(*t, ptr + "/theta_max");
            if (!d) return d.error();
            info.thetaMax = *d;
        }
        if (info.thetaMin == info.thetaMax)
            return rd.bad(ptr + "/theta_max", "must differ from theta_min");
        if (const json* d = Reader::find(e, "description")) {
            auto s = rd.string(*d, ptr + "/description", false);
            if (!s) return s.error();
            info.description = *s;
        }
        out.patterns.push_back(std::move(info));
    }
    return out;
}

json toJson(const PatternManifest& manifest) {
    json list = json::array();
    for (const PatternInfo& p : manifest.patterns) {
        json e = json::object();
        e["id"] = p.id;
        e["file"] = p.file;
        e["kind"] = std::string(toString(p.kind));
        e["model"] = std::string(toString(p.model));
        e["target"] = std::string(toString(p.target));
        e["joint"] = p.joint;
        e["axis"] = p.axis;
        e["theta_min"] = p.thetaMin;
        e["theta_max"] = p.thetaMax;
        e["description"] = p.description;
        list.push_back(std::move(e));
    }
    json doc = json::object();
    doc["format"] = kManifestFormat;
    doc["patterns"] = std::move(list);
    return doc;
}

} // namespace dermis
