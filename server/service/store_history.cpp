// Scene documents and their history in the data folder: the current record, the chunks of
// revisions (a snapshot, then patches: history_format.hpp), whole-revision files of earlier
// versions, an append-only index of revisions, and the retention's compaction. See store.hpp for
// the layout and the order of writes that makes a commit survive kill -9 at any point.
#include "service/store.hpp"

#include "io/atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <sstream>

namespace dermis {

namespace fs = std::filesystem;

namespace {

const char* const kWhere = "dermis::Store";
constexpr std::uint64_t kNoEnd = std::numeric_limits<std::uint64_t>::max();
/// Revisions below the window a compaction waits for before it rewrites the index (so that a
/// history whose chunks are short — a small scene — is not compacted at every edit).
constexpr std::uint64_t kCompactionStep = kChunkRevisions / 8;

fs::path historyDir(const std::string& dir, const std::string& id) {
    return fs::path(dir) / "scenes" / (id + ".history");
}

std::string revisionFile(std::uint64_t revision) {
    return "r" + std::to_string(revision) + ".json";
}

std::string chunkFile(std::uint64_t base) { return "c" + std::to_string(base) + ".jsonl"; }

std::vector<std::uint8_t> bytesOf(const std::string& text) {
    return {text.begin(), text.end()};
}

std::string_view viewOf(const std::vector<std::uint8_t>& bytes) {
    return {reinterpret_cast<const char*>(bytes.data()), bytes.size()};
}

nlohmann::json metaJson(const Store::RevisionInfo& info) {
    return {{"revision", info.revision}, {"time", info.time}, {"op", info.op},
            {"client", info.client}};
}

/// The number in a name "<prefix><digits><suffix>" (no leading zero), or 0.
std::uint64_t numberIn(const std::string& name, const char* prefix, const char* suffix) {
    const std::size_t p = std::strlen(prefix), q = std::strlen(suffix);
    if (name.size() <= p + q || name.compare(0, p, prefix) != 0 ||
        name.compare(name.size() - q, q, suffix) != 0)
        return 0;
    const std::string digits = name.substr(p, name.size() - p - q);
    if (digits.size() > 19 || digits[0] == '0') return 0;
    for (char c : digits)
        if (c < '0' || c > '9') return 0;
    return std::stoull(digits);
}

/// What a history folder holds.
struct Listing {
    std::vector<std::uint64_t> chunks; ///< chunk bases, ascending
    std::vector<std::uint64_t> wholes; ///< whole-revision files (r<N>.json), ascending
    std::vector<fs::path> temps;       ///< leftovers of interrupted writes
};

Listing listHistory(const fs::path& hist) {
    Listing l;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(hist, ec)) {
        const std::string name = e.path().filename().string();
        if (isTempName(name)) l.temps.push_back(e.path());
        else if (std::uint64_t b = numberIn(name, "c", ".jsonl")) l.chunks.push_back(b);
        else if (std::uint64_t r = numberIn(name, "r", ".json")) l.wholes.push_back(r);
    }
    std::sort(l.chunks.begin(), l.chunks.end());
    std::sort(l.wholes.begin(), l.wholes.end());
    return l;
}

/// The first revision past chunk `k` of `chunks`: the next chunk's base (kNoEnd for the last).
std::uint64_t chunkEnd(const std::vector<std::uint64_t>& chunks, std::size_t k) {
    return k + 1 < chunks.size() ? chunks[k + 1] : kNoEnd;
}

/// Appends `text` to `file` (created when missing) and syncs it (O_APPEND: concurrent appends
/// never interleave within a line; the store's caller serialises writers anyway). On failure
/// the file is cut back to its length before (best effort) and an Io error returned.
Status appendDurably(const fs::path& file, const std::string& text) {
    const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
    if (fd < 0)
        return makeError(ErrorCode::Io, kWhere, file.string(),
                         std::string("cannot open: ") + std::strerror(errno));
    struct stat st {};
    const bool sized = ::fstat(fd, &st) == 0;
    std::size_t done = 0;
    int err = 0;
    while (done < text.size() && err == 0) {
        const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) err = errno;
        else done += static_cast<std::size_t>(n);
    }
    if (err == 0 && ::fsync(fd) != 0) err = errno;
    if (err != 0 && sized && ::ftruncate(fd, st.st_size) == 0) (void)::fsync(fd);
    ::close(fd);
    if (err != 0)
        return makeError(ErrorCode::Io, kWhere, file.string(),
                         std::string("cannot append: ") + std::strerror(err));
    return Ok{};
}

/// Cuts `file` to `length` bytes and syncs it (best effort: a failure leaves lines that no
/// reader reaches, see loadHistory).
void truncateDurably(const fs::path& file, std::uint64_t length) {
    const int fd = ::open(file.c_str(), O_WRONLY | O_CLOEXEC);
    if (fd < 0) return;
    if (::ftruncate(fd, static_cast<off_t>(length)) == 0) (void)::fsync(fd);
    ::close(fd);
}

double now() {
    using namespace std::chrono;
    return duration<double>(system_clock::now().time_since_epoch()).count();
}

/// Creates the history folder (and syncs the scenes folder when it is new).
Status ensureHistoryDir(const fs::path& hist, bool& fresh) {
    std::error_code ec;
    fresh = !fs::exists(hist, ec);
    fs::create_directories(hist, ec);
    if (ec) return makeError(ErrorCode::Io, kWhere, hist.string(), "cannot create: " + ec.message());
    if (fresh) return syncFolder(hist.parent_path().string(), kWhere);
    return Ok{};
}

} // namespace

Status Store::putSceneImpl(const std::string& id, const RevisionInfo& info,
                           std::shared_ptr<const nlohmann::json> doc) {
    const fs::path hist = historyDir(dir_, id);
    bool fresh = false;
    if (auto s = ensureHistoryDir(hist, fresh); !s) return s;
    const bool known = tails_.count(id) > 0;
    Tail& tail = tails_[id];
    if (!known && fresh) { // a new scene: its first chunk is also its oldest file
        tail.oldestFile = info.revision;
        tail.oldestChunkEnd = kNoEnd;
    }
    const std::string docText = doc->dump();
    // The revision: a patch on the previous one in its chunk, or a new chunk.
    bool appended = false;
    if (tail.lastDoc && tail.base != 0 && tail.last + 1 == info.revision &&
        info.revision - tail.base < kChunkRevisions) {
        const std::string line = patchLine(info.revision, historyDiff(*tail.lastDoc, *doc));
        if (tail.patchBytes + line.size() <= tail.snapshotBytes) {
            if (auto s = appendDurably(hist / chunkFile(tail.base), line); !s) {
                tail.lastDoc.reset(); // the next revision starts a new chunk
                return s;
            }
            tail.last = info.revision;
            tail.patchBytes += line.size();
            appended = true;
        }
    }
    if (!appended) {
        const std::string line = snapshotLine(info.revision, docText);
        if (auto s = writeFileAtomically((hist / chunkFile(info.revision)).string(), bytesOf(line),
                                         Durability::Durable, kWhere);
            !s) {
            tail.lastDoc.reset();
            return s;
        }
        if (tail.oldestFile != 0 && tail.oldestChunkEnd == kNoEnd && tail.oldestFile < info.revision)
            tail.oldestChunkEnd = info.revision; // the oldest chunk was the last one until now
        tail.base = tail.last = info.revision;
        tail.snapshotBytes = line.size();
        tail.patchBytes = 0;
    }
    tail.lastDoc = doc;
    if (auto s = appendDurably(hist / "index.jsonl", metaJson(info).dump() + "\n"); !s) {
        tail.lastDoc.reset();
        return s;
    }
    // The commit point. Keys in the order dump() writes them: id, revision, scene.
    std::string record = nlohmann::json{{"id", id}, {"revision", info.revision}}.dump();
    record.pop_back();
    record += ",\"scene\":";
    record += docText;
    record += "}";
    if (auto s = writeFileAtomically((fs::path(dir_) / "scenes" / (id + ".json")).string(),
                                     bytesOf(record), Durability::Durable, kWhere);
        !s) {
        tail.lastDoc.reset();
        return s;
    }
    return Ok{};
}

Status Store::putScene(const std::string& id, const RevisionInfo& info, const nlohmann::json& doc) {
    return putScene(id, info, std::make_shared<const nlohmann::json>(doc));
}

Status Store::putScene(const std::string& id, std::uint64_t revision, const nlohmann::json& doc) {
    return putScene(id, RevisionInfo{revision, now(), "", ""}, doc);
}

Status Store::removeSceneImpl(const std::string& id) {
    const fs::path folder = fs::path(dir_) / "scenes";
    std::error_code ec;
    fs::remove(folder / (id + ".json"), ec);
    if (ec) return makeError(ErrorCode::Io, "dermis::Store::removeScene", id, ec.message());
    if (auto s = syncFolder(folder.string(), kWhere); !s) return s;
    tails_.erase(id);
    // Without its record the scene is gone; its history is garbage from here on.
    fs::remove_all(historyDir(dir_, id), ec);
    if (ec) return makeError(ErrorCode::Io, "dermis::Store::removeScene", id, ec.message());
    return Ok{};
}

Result<std::string> Store::readRevisionTextImpl(const std::string& id, std::uint64_t revision) const {
    const char* where = "dermis::Store::readRevision";
    const fs::path hist = historyDir(dir_, id);
    auto notKept = [&] {
        return makeError(ErrorCode::NotFound, where, "revision",
                         "scene " + id + " keeps no revision " + std::to_string(revision));
    };
    if (revision == 0) return notKept();
    // A whole revision, as versions before chunks wrote every one.
    const fs::path whole = hist / revisionFile(revision);
    auto bytes = readWholeFile(whole.string(), std::size_t(1) << 30, where);
    if (bytes) {
        const nlohmann::json record = nlohmann::json::parse(bytes->begin(), bytes->end(), nullptr, false);
        if (!record.is_object() || !record.contains("scene") ||
            record.value("revision", std::uint64_t{0}) != revision)
            return makeError(ErrorCode::Parse, where, whole.string(), "damaged revision record");
        return record["scene"].dump();
    }
    if (bytes.error().code != ErrorCode::NotFound) return bytes.error();
    // The chunk with the largest base ≤ revision: at most kChunkRevisions − 1 below it.
    for (std::uint64_t k = 0; k < kChunkRevisions && k < revision; ++k) {
        const fs::path chunk = hist / chunkFile(revision - k);
        auto text = readWholeFile(chunk.string(), std::size_t(1) << 30, where);
        if (!text) {
            if (text.error().code == ErrorCode::NotFound) continue;
            return text.error();
        }
        auto doc = replayChunk(viewOf(*text), revision - k, revision, chunk.string(), where);
        if (!doc && doc.error().code == ErrorCode::NotFound) return notKept();
        return doc;
    }
    return notKept();
}

Result<Store::History> Store::loadHistoryImpl(const std::string& id, std::uint64_t current,
                                              const nlohmann::json& currentDoc) {
    const fs::path hist = historyDir(dir_, id);
    History out;
    std::map<std::uint64_t, RevisionInfo> byRevision;
    if (auto text = readWholeFile((hist / "index.jsonl").string()); text) {
        std::istringstream in(std::string(text->begin(), text->end()));
        std::string line;
        while (std::getline(in, line)) {
            const nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
            if (!j.is_object()) continue; // a torn line of an interrupted append
            if (auto d = j.find("dropped_before"); d != j.end() && d->is_number_unsigned()) {
                out.droppedBefore = std::max(out.droppedBefore, d->get<std::uint64_t>());
                continue;
            }
            if (!j.contains("revision") || !j["revision"].is_number_unsigned()) continue;
            RevisionInfo info;
            info.revision = j["revision"].get<std::uint64_t>();
            if (info.revision == 0 || info.revision > current) continue; // never committed
            info.time = j.value("time", 0.0);
            info.op = j.value("op", "");
            info.client = j.value("client", "");
            byRevision[info.revision] = std::move(info);
        }
    }
    out.droppedBefore = std::min(out.droppedBefore, current);
    byRevision.erase(byRevision.begin(), byRevision.lower_bound(out.droppedBefore));

    // Tidy what a crash left: temp files, revisions above `current` (an interrupted commit),
    // files wholly below the retention window (an interrupted compaction).
    std::error_code ec;
    Listing l = listHistory(hist);
    bool removed = false;
    for (const fs::path& p : l.temps)
        removed |= fs::remove_all(p, ec) > 0;
    std::vector<std::uint64_t> chunks, wholes;
    for (std::size_t k = 0; k < l.chunks.size(); ++k) {
        const std::uint64_t b = l.chunks[k];
        if (b > current || chunkEnd(l.chunks, k) <= out.droppedBefore)
            removed |= fs::remove(hist / chunkFile(b), ec);
        else chunks.push_back(b);
    }
    for (std::uint64_t r : l.wholes) {
        if (r > current || r < out.droppedBefore) removed |= fs::remove(hist / revisionFile(r), ec);
        else wholes.push_back(r);
    }
    if (removed) (void)syncFolder(hist.string(), kWhere);

    // Is `current` readable? Its whole file, or a line of the last chunk (cut after that line).
    bool readable = std::binary_search(wholes.begin(), wholes.end(), current);
    if (!readable && !chunks.empty()) {
        const fs::path last = hist / chunkFile(chunks.back());
        if (auto text = readWholeFile(last.string(), std::size_t(1) << 30); text) {
            const auto lines = scanChunk(viewOf(*text), current);
            if (!lines.empty() && lines.back().revision == current && lines[0].snapshot &&
                lines[0].revision == chunks.back()) {
                readable = true;
                if (text->size() > lines.back().end) truncateDurably(last, lines.back().end);
            }
        }
    }
    Tail& tail = tails_[id];
    tail = Tail{};
    tail.oldestFile = !wholes.empty() ? wholes.front() : chunks.empty() ? 0 : chunks.front();
    tail.oldestChunkEnd = !wholes.empty() ? wholes.front() + 1 : chunkEnd(chunks, 0);
    if (!byRevision.count(current) || !readable) {
        RevisionInfo info{current, now(), "imported", ""};
        if (auto s = putSceneImpl(id, info, std::make_shared<const nlohmann::json>(currentDoc)); !s)
            return s.error();
        byRevision[current] = info;
        if (tail.oldestFile == 0 || tail.oldestFile > current) {
            tail.oldestFile = current;
            tail.oldestChunkEnd = kNoEnd;
        }
    }
    tail.lastDoc.reset(); // the next revision starts a chunk: this store did not write `current`
    out.revisions.reserve(byRevision.size());
    for (auto& [revision, info] : byRevision)
        out.revisions.push_back(std::move(info));
    return out;
}

bool Store::compactionDue(const std::string& id, std::uint64_t oldestKept) const {
    auto it = tails_.find(id);
    if (it == tails_.end() || it->second.oldestFile == 0) return false;
    const Tail& t = it->second;
    return t.oldestChunkEnd <= oldestKept && oldestKept - t.oldestFile >= kCompactionStep;
}

Status Store::dropRevisionsBeforeImpl(const std::string& id, std::uint64_t oldestKept,
                                      const std::vector<RevisionInfo>& kept) {
    const fs::path hist = historyDir(dir_, id);
    // (1) The switch: the new index, whole and synced, renamed over the old one.
    std::string index = nlohmann::json{{"dropped_before", oldestKept}}.dump() + "\n";
    for (const RevisionInfo& info : kept)
        if (info.revision >= oldestKept) index += metaJson(info).dump() + "\n";
    if (auto s = writeFileAtomically((hist / "index.jsonl").string(), bytesOf(index),
                                     Durability::Durable, kWhere);
        !s)
        return s;
    // (2) Files that hold only dropped revisions.
    const Listing l = listHistory(hist);
    std::error_code ec;
    std::string failed;
    std::vector<std::uint64_t> chunks, wholes;
    for (std::size_t k = 0; k < l.chunks.size(); ++k) {
        if (chunkEnd(l.chunks, k) <= oldestKept) {
            if (!fs::remove(hist / chunkFile(l.chunks[k]), ec) && ec) failed = chunkFile(l.chunks[k]);
        } else {
            chunks.push_back(l.chunks[k]);
        }
    }
    for (std::uint64_t r : l.wholes) {
        if (r < oldestKept) {
            if (!fs::remove(hist / revisionFile(r), ec) && ec) failed = revisionFile(r);
        } else {
            wholes.push_back(r);
        }
    }
    Tail& tail = tails_[id];
    tail.oldestFile = !wholes.empty() ? wholes.front() : chunks.empty() ? 0 : chunks.front();
    tail.oldestChunkEnd = !wholes.empty() ? wholes.front() + 1 : chunkEnd(chunks, 0);
    if (auto s = syncFolder(hist.string(), kWhere); !s) return s;
    if (!failed.empty())
        return makeError(ErrorCode::Io, "dermis::Store::dropRevisionsBefore", (hist / failed).string(),
                         "cannot delete: " + ec.message());
    return Ok{};
}

// --- the public entry points: the data folder is "<data>" in every message ---------------------------

Status Store::putScene(const std::string& id, const RevisionInfo& info,
                       std::shared_ptr<const nlohmann::json> doc) {
    return hidden(putSceneImpl(id, info, std::move(doc)));
}
Status Store::removeScene(const std::string& id) { return hidden(removeSceneImpl(id)); }
Result<std::string> Store::readRevisionText(const std::string& id, std::uint64_t revision) const {
    return hidden(readRevisionTextImpl(id, revision));
}
Result<nlohmann::json> Store::readRevision(const std::string& id, std::uint64_t revision) const {
    auto text = readRevisionText(id, revision);
    if (!text) return text.error();
    nlohmann::json doc = nlohmann::json::parse(*text, nullptr, false);
    if (doc.is_discarded())
        return makeError(ErrorCode::Parse, "dermis::Store::readRevision", "revision",
                         "scene " + id + ": revision " + std::to_string(revision) + " is damaged");
    return doc;
}
Result<Store::History> Store::loadHistory(const std::string& id, std::uint64_t current,
                                          const nlohmann::json& currentDoc) {
    return hidden(loadHistoryImpl(id, current, currentDoc));
}
Status Store::dropRevisionsBefore(const std::string& id, std::uint64_t oldestKept,
                                  const std::vector<RevisionInfo>& kept) {
    return hidden(dropRevisionsBeforeImpl(id, oldestKept, kept));
}

} // namespace dermis
