#include "service/history_format.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>

namespace dermis {

using json = nlohmann::json;

namespace {

/// Equal as stored: the same JSON type and value, doubles bit for bit (so equal dumps).
bool sameJson(const json& a, const json& b) {
    if (a.type() != b.type()) return false;
    switch (a.type()) {
    case json::value_t::object: {
        if (a.size() != b.size()) return false;
        for (auto i = a.begin(), j = b.begin(); i != a.end(); ++i, ++j)
            if (i.key() != j.key() || !sameJson(i.value(), j.value())) return false;
        return true;
    }
    case json::value_t::array: {
        if (a.size() != b.size()) return false;
        for (std::size_t k = 0; k < a.size(); ++k)
            if (!sameJson(a[k], b[k])) return false;
        return true;
    }
    case json::value_t::number_float: {
        const double x = a.get<double>(), y = b.get<double>();
        return std::memcmp(&x, &y, sizeof x) == 0;
    }
    default: return a == b;
    }
}

/// A member name as a JSON Pointer reference token (RFC 6901: "~" → "~0", "/" → "~1").
std::string token(const std::string& key) {
    std::string out;
    out.reserve(key.size());
    for (char c : key) {
        if (c == '~') out += "~0";
        else if (c == '/') out += "~1";
        else out += c;
    }
    return out;
}

json op(const char* name, const std::string& path) { return {{"op", name}, {"path", path}}; }
json op(const char* name, const std::string& path, const json& value) {
    return {{"op", name}, {"path", path}, {"value", value}};
}

void diffInto(const json& a, const json& b, const std::string& path, json& ops);

/// The operations of an object or array `b` that differs from `a`, or one "replace" when most of
/// its parts changed (fewer bytes, and a whole value is what an edit of most of it means).
void diffContainer(const json& a, const json& b, const std::string& path, json& ops) {
    json sub = json::array();
    if (a.is_object()) {
        for (auto it = a.begin(); it != a.end(); ++it)
            if (!b.contains(it.key())) sub.push_back(op("remove", path + "/" + token(it.key())));
        for (auto it = b.begin(); it != b.end(); ++it) {
            const std::string at = path + "/" + token(it.key());
            if (auto f = a.find(it.key()); f == a.end()) sub.push_back(op("add", at, it.value()));
            else diffInto(*f, it.value(), at, sub);
        }
    } else {
        // The common head and tail stay; the middle pairs up element by element, and what one
        // side has more is removed (from the same index, each shifting the rest) or added.
        const std::size_t na = a.size(), nb = b.size();
        std::size_t head = 0, tail = 0;
        while (head < na && head < nb && sameJson(a[head], b[head])) ++head;
        while (tail < na - head && tail < nb - head && sameJson(a[na - 1 - tail], b[nb - 1 - tail])) ++tail;
        const std::size_t midA = na - head - tail, midB = nb - head - tail;
        const std::size_t paired = std::min(midA, midB);
        for (std::size_t k = 0; k < paired; ++k)
            diffInto(a[head + k], b[head + k], path + "/" + std::to_string(head + k), sub);
        for (std::size_t k = paired; k < midA; ++k)
            sub.push_back(op("remove", path + "/" + std::to_string(head + paired)));
        for (std::size_t k = paired; k < midB; ++k)
            sub.push_back(op("add", path + "/" + std::to_string(head + k), b[head + k]));
    }
    if (!path.empty() && sub.size() > std::max<std::size_t>(1, b.size() / 2)) {
        ops.push_back(op("replace", path, b));
        return;
    }
    for (json& o : sub) ops.push_back(std::move(o));
}

void diffInto(const json& a, const json& b, const std::string& path, json& ops) {
    if (sameJson(a, b)) return;
    if ((a.is_object() && b.is_object()) || (a.is_array() && b.is_array())) {
        diffContainer(a, b, path, ops);
        return;
    }
    ops.push_back(op("replace", path, b));
}

/// The revision at the start of a line (`{"revision":<digits>,`) and where the rest begins;
/// 0 when the line does not start so.
std::uint64_t lineRevision(std::string_view line, std::size_t& rest) {
    static constexpr std::string_view kHead = "{\"revision\":";
    if (line.substr(0, kHead.size()) != kHead) return 0;
    std::size_t k = kHead.size();
    std::uint64_t n = 0;
    const std::size_t digits0 = k;
    while (k < line.size() && line[k] >= '0' && line[k] <= '9' && k - digits0 < 19)
        n = n * 10 + static_cast<std::uint64_t>(line[k++] - '0');
    if (k == digits0 || k >= line.size() || line[k] != ',') return 0;
    rest = k + 1;
    return n;
}

} // namespace

json historyDiff(const json& from, const json& to) {
    json ops = json::array();
    diffInto(from, to, "", ops);
    return ops;
}

Status applyHistoryPatch(json& doc, const json& patch, const char* where) {
    try {
        doc.patch_inplace(patch);
    } catch (const json::exception& e) {
        return makeError(ErrorCode::Parse, where, "patch", std::string("does not apply: ") + e.what());
    }
    return Ok{};
}

std::string snapshotLine(std::uint64_t revision, std::string_view docText) {
    std::string line = "{\"revision\":" + std::to_string(revision) + ",\"scene\":";
    line.reserve(line.size() + docText.size() + 2);
    line.append(docText);
    line += "}\n";
    return line;
}

std::string patchLine(std::uint64_t revision, const json& patch) {
    return "{\"revision\":" + std::to_string(revision) + ",\"patch\":" + patch.dump() + "}\n";
}

std::vector<ChunkLine> scanChunk(std::string_view bytes, std::uint64_t upTo) {
    std::vector<ChunkLine> lines;
    std::size_t at = 0;
    while (at < bytes.size()) {
        const std::size_t nl = bytes.find('\n', at);
        if (nl == std::string_view::npos) break; // torn: an interrupted append
        const std::string_view line = bytes.substr(at, nl - at);
        std::size_t rest = 0;
        const std::uint64_t revision = lineRevision(line, rest);
        if (revision == 0 || line.back() != '}') break;
        const std::string_view kind = line.substr(rest);
        ChunkLine l;
        l.revision = revision;
        l.begin = at;
        l.end = nl + 1;
        if (kind.substr(0, 8) == "\"scene\":") l.snapshot = true;
        else if (kind.substr(0, 8) != "\"patch\":") break;
        lines.push_back(l);
        if (revision == upTo) break;
        at = nl + 1;
    }
    return lines;
}

Result<json> replayChunk(std::string_view bytes, std::uint64_t base, std::uint64_t revision,
                         const std::string& file, const char* where) {
    const std::vector<ChunkLine> lines = scanChunk(bytes, revision);
    auto damaged = [&](const std::string& what) {
        return makeError(ErrorCode::Parse, where, file, "damaged history chunk: " + what);
    };
    if (lines.empty() || !lines[0].snapshot || lines[0].revision != base)
        return damaged("its first line is not the snapshot of revision " + std::to_string(base));
    json doc;
    for (std::size_t k = 0; k < lines.size(); ++k) {
        const ChunkLine& l = lines[k];
        if (l.revision != base + k || (k > 0 && l.snapshot))
            return damaged("line " + std::to_string(k + 1) + " is not revision " + std::to_string(base + k));
        json rec = json::parse(bytes.begin() + static_cast<std::ptrdiff_t>(l.begin),
                               bytes.begin() + static_cast<std::ptrdiff_t>(l.end), nullptr, false);
        if (!rec.is_object()) return damaged("revision " + std::to_string(l.revision) + " is not JSON");
        if (k == 0) {
            auto scene = rec.find("scene");
            if (scene == rec.end()) return damaged("no snapshot document");
            doc = std::move(*scene);
        } else {
            auto patch = rec.find("patch");
            if (patch == rec.end() || !patch->is_array())
                return damaged("revision " + std::to_string(l.revision) + " has no patch");
            if (auto s = applyHistoryPatch(doc, *patch, where); !s)
                return damaged("revision " + std::to_string(l.revision) + ": " + s.error().message);
        }
        if (l.revision == revision) return doc;
    }
    return makeError(ErrorCode::NotFound, where, "revision",
                     "the history holds no revision " + std::to_string(revision));
}

std::string HistoryRetention::text() const {
    if (keepsAll()) return "all";
    if (revisions > 0) return std::to_string(revisions);
    std::ostringstream days;
    days << seconds / 86400.0;
    return days.str() + "d";
}

std::string HistoryRetention::flag() const { return keepsAll() ? "" : "--history-keep " + text(); }

Result<HistoryRetention> parseHistoryRetention(const std::string& text) {
    auto bad = [&] {
        return makeError(ErrorCode::InvalidArgument, "dermis::parseHistoryRetention", "--history-keep",
                         "\"" + text + "\": give a number of revisions (e.g. 500), a number of days "
                         "(e.g. 30d) or all");
    };
    HistoryRetention r;
    if (text == "all") return r;
    if (text.empty() || text.size() > 24) return bad();
    const bool days = text.back() == 'd';
    const std::string number = days ? text.substr(0, text.size() - 1) : text;
    if (number.empty()) return bad();
    int dots = 0;
    for (char c : number) {
        if (c == '.') ++dots;
        else if (c < '0' || c > '9') return bad();
    }
    if (dots > (days ? 1 : 0) || number.front() == '.' || number.back() == '.') return bad();
    if (days) {
        const double d = std::strtod(number.c_str(), nullptr);
        if (!(d > 0.0) || d > 1.0e6) return bad();
        r.seconds = d * 86400.0;
    } else {
        if (number.size() > 18) return bad();
        r.revisions = std::stoull(number);
        if (r.revisions == 0) return bad();
    }
    return r;
}

std::uint64_t oldestKept(const std::vector<RevisionInfo>& history, const HistoryRetention& retention,
                         double now) {
    if (history.empty()) return 0;
    std::size_t first = 0;
    if (retention.revisions > 0 && history.size() > retention.revisions)
        first = history.size() - static_cast<std::size_t>(retention.revisions);
    if (retention.seconds > 0.0) {
        const double cutoff = now - retention.seconds;
        std::size_t k = history.size() - 1; // the current revision stays
        while (k > first && history[k - 1].time >= cutoff) --k;
        first = std::max(first, k);
    }
    return history[first].revision;
}

} // namespace dermis
