#include "service/history_format.hpp"

#include <algorithm>
#include <array>
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

/// Index just past the string that starts at s[i] ('"'), or npos when it is not closed.
std::size_t skipString(std::string_view s, std::size_t i) {
    const char* p = s.data();
    for (++i; i < s.size(); ++i) {
        const char c = p[i];
        if (c == '\\') ++i;
        else if (c == '"') return i + 1;
    }
    return std::string_view::npos;
}

/// The characters skipValue stops at inside an object or array.
constexpr std::array<bool, 256> kStructural = [] {
    std::array<bool, 256> t{};
    for (unsigned char c : {'"', '{', '}', '[', ']'}) t[c] = true;
    return t;
}();

/// Index just past the value that starts at s[i] in compact text (dump()'s: no whitespace), or
/// npos when it is not closed: strings, brackets balanced, or a scalar up to , ] or }.
std::size_t skipValue(std::string_view s, std::size_t i) {
    if (i >= s.size()) return std::string_view::npos;
    if (s[i] == '"') return skipString(s, i);
    if (s[i] == '{' || s[i] == '[') {
        const char* p = s.data();
        int depth = 0;
        while (i < s.size()) {
            const char c = p[i];
            if (!kStructural[static_cast<unsigned char>(c)]) {
                ++i;
                continue;
            }
            if (c == '"') {
                i = skipString(s, i);
                if (i == std::string_view::npos) return i;
                continue;
            }
            if (c == '{' || c == '[') ++depth;
            else if (--depth == 0) return i + 1;
            ++i;
        }
        return std::string_view::npos;
    }
    const std::size_t start = i;
    while (i < s.size() && s[i] != ',' && s[i] != ']' && s[i] != '}' && s[i] != ' ' && s[i] != '\n') ++i;
    return i > start ? i : std::string_view::npos;
}

/// The reference tokens of a JSON Pointer ("/a/b~1c" → a, b/c); nullopt when it is not one.
std::optional<std::vector<std::string>> pointerTokens(const std::string& path) {
    if (path.empty()) return std::vector<std::string>{};
    if (path[0] != '/') return std::nullopt;
    std::vector<std::string> tokens;
    std::string t;
    for (std::size_t i = 1; i <= path.size(); ++i) {
        if (i == path.size() || path[i] == '/') {
            tokens.push_back(std::move(t));
            t.clear();
        } else if (path[i] == '~') {
            if (i + 1 >= path.size() || (path[i + 1] != '0' && path[i + 1] != '1')) return std::nullopt;
            t += path[++i] == '0' ? '~' : '/';
        } else {
            t += path[i];
        }
    }
    return tokens;
}

/// An array index token: digits without a leading zero, ≤ `limit`; nullopt otherwise.
std::optional<std::size_t> indexToken(const std::string& t, std::size_t limit) {
    if (t.empty() || t.size() > 9 || (t.size() > 1 && t[0] == '0')) return std::nullopt;
    std::size_t n = 0;
    for (char c : t) {
        if (c < '0' || c > '9') return std::nullopt;
        n = n * 10 + static_cast<std::size_t>(c - '0');
    }
    if (n > limit) return std::nullopt;
    return n;
}

/// A document kept as the text it was stored as, split into its top-level members and the
/// elements of its "placements" array: a patch operation parses only the part it touches, and
/// text() joins the parts again — dump()'s bytes for the patched document (dump() is made of
/// the dumps of the parts). Operations on the root, or other than add/remove/replace, parse the
/// document whole first.
class PartedDoc {
public:
    /// Splits compact object text (as dump() writes it); false when it is not of that shape. The
    /// "placements" array is split into its elements in the same pass (one scan of the text).
    bool load(std::string_view text) {
        std::size_t i = 0;
        if (text.size() < 2 || text[0] != '{') return false;
        ++i;
        if (text[i] == '}') return i + 1 == text.size();
        while (true) {
            if (i >= text.size() || text[i] != '"') return false;
            const std::size_t k = skipString(text, i);
            if (k == std::string_view::npos || k >= text.size() || text[k] != ':') return false;
            const json key = json::parse(text.substr(i, k - i), nullptr, false);
            if (!key.is_string()) return false;
            const bool placements = key.get_ref<const std::string&>() == "placements" &&
                                    k + 1 < text.size() && text[k + 1] == '[';
            const std::size_t v = placements ? splitElements(text, k + 1) : skipValue(text, k + 1);
            if (v == std::string_view::npos || v >= text.size()) return false;
            if (!members_.empty() && !(members_.back().first < key.get_ref<const std::string&>()))
                return false; // dump() writes members once each, in key order
            members_.push_back({key.get<std::string>(), Part{text.substr(k + 1, v - k - 1), std::nullopt}});
            i = v + 1;
            if (text[v] == '}') break;
            if (text[v] != ',') return false;
        }
        return i == text.size();
    }
    /// The fallback: `text` parsed whole. False when it is not JSON.
    bool loadWhole(std::string_view text) {
        json doc = json::parse(text, nullptr, false);
        if (doc.is_discarded()) return false;
        whole_ = std::move(doc);
        return true;
    }

    Status apply(const json& op, const char* where) {
        if (whole_) return applyHistoryPatch(*whole_, json::array({op}), where);
        const std::string name = op.is_object() ? op.value("op", "") : "";
        const auto path = op.is_object() && op.contains("path") && op["path"].is_string()
                              ? pointerTokens(op["path"].get<std::string>())
                              : std::nullopt;
        const bool plain = name == "add" || name == "remove" || name == "replace";
        if (!plain || !path || path->empty() || (name != "remove" && !op.contains("value"))) {
            makeWhole();
            return applyHistoryPatch(*whole_, json::array({op}), where);
        }
        const std::vector<std::string>& t = *path;
        auto fail = [&](const std::string& what) {
            return makeError(ErrorCode::Parse, where, "patch", op.value("path", "") + ": " + what);
        };
        const bool isPlacements = t[0] == "placements";
        auto at = std::find_if(members_.begin(), members_.end(), [&](const auto& m) { return m.first == t[0]; });
        if (t.size() == 1) { // a member itself
            if (name != "add" && at == members_.end()) return fail("no such member");
            if (name == "remove") {
                members_.erase(at);
                if (isPlacements) split_ = false, elements_.clear();
                return Ok{};
            }
            const json& value = op["value"];
            if (at == members_.end())
                at = members_.insert(std::lower_bound(members_.begin(), members_.end(), t[0],
                                                      [](const auto& m, const std::string& k) { return m.first < k; }),
                                     {t[0], Part{}});
            at->second = Part{{}, value};
            if (isPlacements) {
                split_ = value.is_array();
                elements_.clear();
                if (split_)
                    for (const json& e : value) elements_.push_back(Part{{}, e});
            }
            return Ok{};
        }
        if (at == members_.end()) return fail("no such member");
        if (isPlacements && split_) {
            if (t.size() == 2) { // an element itself
                const bool add = name == "add";
                const auto k = t[1] == "-" && add ? std::optional<std::size_t>(elements_.size())
                                                  : indexToken(t[1], add ? elements_.size() : elements_.size() - 1);
                if (!k || (!add && elements_.empty())) return fail("no such element");
                const auto pos = elements_.begin() + static_cast<std::ptrdiff_t>(*k);
                if (name == "remove") elements_.erase(pos);
                else if (add) elements_.insert(pos, Part{{}, op["value"]});
                else *pos = Part{{}, op["value"]};
                return Ok{};
            }
            const auto k = indexToken(t[1], elements_.empty() ? 0 : elements_.size() - 1);
            if (!k || elements_.empty()) return fail("no such element");
            if (t.size() == 3 && spliceMember(elements_[*k], name, t[2], op)) return Ok{};
            return applyWithin(elements_[*k], t, 2, op, where);
        }
        return applyWithin(at->second, t, 1, op, where);
    }

    std::string text() const {
        if (whole_) return whole_->dump();
        std::string out = "{";
        for (const auto& [key, part] : members_) {
            if (out.size() > 1) out += ',';
            out += json(key).dump();
            out += ':';
            if (key == "placements" && split_) {
                out += '[';
                for (std::size_t k = 0; k < elements_.size(); ++k) {
                    if (k) out += ',';
                    elements_[k].appendTo(out);
                }
                out += ']';
            } else {
                part.appendTo(out);
            }
        }
        out += '}';
        return out;
    }

private:
    struct Part {
        std::string_view text;       ///< as stored, while `value` is empty and `edited` unset
        std::optional<json> value;   ///< parsed (or replaced) once an operation needed the tree
        std::optional<std::string> edited = std::nullopt; ///< the text after spliceMember
        std::string_view view() const { return edited ? std::string_view(*edited) : text; }
        json& get() {
            if (!value) value = json::parse(view(), nullptr, false);
            return *value;
        }
        void appendTo(std::string& out) const {
            if (value) out += value->dump();
            else out.append(view());
        }
    };

    /// `op` (add, replace or remove of member `key` of the object `part` holds as compact text)
    /// applied to the text itself: the member's value replaced by the new value's dump(), a new
    /// member put where dump() puts it (key order), a removed one cut out with its comma. No parse
    /// of the object: the drag of a placement ("replace /placements/i/center") costs a scan of
    /// that placement's text. False, and nothing changed, where the text path does not apply (a
    /// key written with escapes, a replace or remove of a missing member, text not of that
    /// shape): the caller parses instead and gets the tree's answer.
    static bool spliceMember(Part& part, const std::string& name, const std::string& key, const json& op) {
        if (part.value) return false;
        const std::string_view t = part.view();
        if (t.size() < 2 || t[0] != '{' || t.back() != '}') return false;
        // Each member as [begin of key, end of value); keys compared as written (no escapes).
        std::size_t insertAt = t.size() - 1, i = 1;
        bool found = false;
        std::size_t mBegin = 0, vBegin = 0, vEnd = 0;
        if (t[i] != '}') {
            while (true) {
                if (t[i] != '"') return false;
                const std::size_t k = skipString(t, i);
                if (k == std::string_view::npos || k >= t.size() || t[k] != ':') return false;
                const std::string_view raw = t.substr(i + 1, k - i - 2);
                if (raw.find('\\') != std::string_view::npos) return false;
                const std::size_t v = skipValue(t, k + 1);
                if (v == std::string_view::npos || v >= t.size()) return false;
                if (raw == key) {
                    found = true;
                    mBegin = i, vBegin = k + 1, vEnd = v;
                    break;
                }
                if (insertAt == t.size() - 1 && key < raw) insertAt = i;
                if (t[v] == '}') break;
                if (t[v] != ',') return false;
                i = v + 1;
            }
        }
        std::string out;
        if (name == "remove") {
            if (!found) return false;
            // Cut "key":value and the comma after it, or the comma before it when it is last.
            std::size_t cutBegin = mBegin, cutEnd = vEnd;
            if (t[vEnd] == ',') ++cutEnd;
            else if (mBegin != 1) --cutBegin; // not the first member: a comma before it
            out.assign(t.substr(0, cutBegin));
            out.append(t.substr(cutEnd));
        } else if (found) { // add of an existing member replaces it, as replace does
            out.assign(t.substr(0, vBegin));
            out += op["value"].dump();
            out.append(t.substr(vEnd));
        } else {
            if (name != "add") return false;
            const std::string member = json(key).dump() + ":" + op["value"].dump();
            out.assign(t.substr(0, insertAt));
            if (insertAt == t.size() - 1) { // at the end
                if (t.size() > 2) out += ',';
                out += member;
            } else {
                out += member;
                out += ',';
            }
            out.append(t.substr(insertAt));
        }
        part.edited = std::move(out);
        return true;
    }

    /// The elements of the array at text[at] ('[') into elements_; the index just past the array,
    /// or npos when it is not closed.
    std::size_t splitElements(std::string_view text, std::size_t at) {
        split_ = true;
        elements_.clear();
        if (text.substr(at, 2) == "[]") return at + 2;
        for (std::size_t j = at + 1; j < text.size();) {
            const std::size_t e = skipValue(text, j);
            if (e == std::string_view::npos || e >= text.size()) return std::string_view::npos;
            elements_.push_back(Part{text.substr(j, e - j), std::nullopt});
            if (text[e] == ']') return e + 1;
            if (text[e] != ',') return std::string_view::npos;
            j = e + 1;
        }
        return std::string_view::npos;
    }

    /// `op` applied inside `part`, at the path's tokens from `from` on.
    static Status applyWithin(Part& part, const std::vector<std::string>& t, std::size_t from,
                              const json& op, const char* where) {
        json& value = part.get();
        if (value.is_discarded())
            return makeError(ErrorCode::Parse, where, "patch", "the document is damaged there");
        std::string path;
        for (std::size_t k = from; k < t.size(); ++k) path += "/" + token(t[k]);
        json ops = json::array();
        ops.push_back(op);
        ops.back()["path"] = std::move(path);
        return applyHistoryPatch(value, ops, where);
    }
    /// Gives up the parts: the document parsed whole from them.
    void makeWhole() {
        whole_ = json::parse(text(), nullptr, false);
        members_.clear();
        elements_.clear();
        split_ = false;
    }

    std::vector<std::pair<std::string, Part>> members_; ///< in key order, as dump() writes them
    std::vector<Part> elements_;                        ///< of "placements", when split_
    bool split_ = false;
    std::optional<json> whole_;
};

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

Result<std::string> replayChunk(std::string_view bytes, std::uint64_t base, std::uint64_t revision,
                                const std::string& file, const char* where) {
    const std::vector<ChunkLine> lines = scanChunk(bytes, revision);
    auto damaged = [&](const std::string& what) {
        return makeError(ErrorCode::Parse, where, file, "damaged history chunk: " + what);
    };
    if (lines.empty() || !lines[0].snapshot || lines[0].revision != base)
        return damaged("its first line is not the snapshot of revision " + std::to_string(base));
    // The snapshot's document: the line less {"revision":B,"scene": and }\n.
    const std::string head = "{\"revision\":" + std::to_string(base) + ",\"scene\":";
    const std::string_view first = bytes.substr(lines[0].begin, lines[0].end - lines[0].begin);
    if (first.size() < head.size() + 3) return damaged("an empty snapshot");
    const std::string_view snapshot = first.substr(head.size(), first.size() - head.size() - 2);
    if (revision == base) return std::string(snapshot);
    PartedDoc doc;
    if (!doc.load(snapshot) && !doc.loadWhole(snapshot)) return damaged("the snapshot is not JSON");
    for (std::size_t k = 1; k < lines.size(); ++k) {
        const ChunkLine& l = lines[k];
        if (l.revision != base + k || l.snapshot)
            return damaged("line " + std::to_string(k + 1) + " is not revision " + std::to_string(base + k));
        const json rec = json::parse(bytes.begin() + static_cast<std::ptrdiff_t>(l.begin),
                                     bytes.begin() + static_cast<std::ptrdiff_t>(l.end), nullptr, false);
        const auto patch = rec.is_object() ? rec.find("patch") : rec.end();
        if (!rec.is_object() || patch == rec.end() || !patch->is_array())
            return damaged("revision " + std::to_string(l.revision) + " has no patch");
        for (const json& op : *patch)
            if (auto s = doc.apply(op, where); !s)
                return damaged("revision " + std::to_string(l.revision) + ": " + s.error().message);
        if (l.revision == revision) return doc.text();
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
