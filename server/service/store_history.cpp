// Scene documents and their history in the data folder: the current record, one document per
// kept revision and an append-only index of revisions. See store.hpp for the layout and the
// order of writes that makes a commit survive kill -9 at any point.
#include "service/store.hpp"

#include "io/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <map>
#include <sstream>

namespace dermis {

namespace fs = std::filesystem;

namespace {

const char* const kWhere = "dermis::Store";

fs::path historyDir(const std::string& dir, const std::string& id) {
    return fs::path(dir) / "scenes" / (id + ".history");
}

std::string revisionFile(std::uint64_t revision) {
    return "r" + std::to_string(revision) + ".json";
}

std::vector<std::uint8_t> bytesOf(const std::string& text) {
    return {text.begin(), text.end()};
}

nlohmann::json metaJson(const Store::RevisionInfo& info) {
    return {{"revision", info.revision}, {"time", info.time}, {"op", info.op},
            {"client", info.client}};
}

/// Appends one line to the index and syncs it (O_APPEND: concurrent appends never interleave
/// within a line; the store's caller serialises writers anyway).
Status appendLine(const fs::path& file, const std::string& line) {
    const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
    if (fd < 0)
        return makeError(ErrorCode::Io, kWhere, file.string(),
                         std::string("cannot open: ") + std::strerror(errno));
    std::size_t done = 0;
    int err = 0;
    while (done < line.size() && err == 0) {
        const ssize_t n = ::write(fd, line.data() + done, line.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) err = errno;
        else done += static_cast<std::size_t>(n);
    }
    if (err == 0 && ::fsync(fd) != 0) err = errno;
    ::close(fd);
    if (err != 0)
        return makeError(ErrorCode::Io, kWhere, file.string(),
                         std::string("cannot append: ") + std::strerror(err));
    return Ok{};
}

double now() {
    using namespace std::chrono;
    return duration<double>(system_clock::now().time_since_epoch()).count();
}

/// Writes revision `info.revision`'s document and its index line.
Status putRevision(const fs::path& hist, const Store::RevisionInfo& info,
                   const nlohmann::json& doc) {
    std::error_code ec;
    const bool fresh = !fs::exists(hist, ec);
    fs::create_directories(hist, ec);
    if (ec) return makeError(ErrorCode::Io, kWhere, hist.string(), "cannot create: " + ec.message());
    if (fresh)
        if (auto s = syncFolder(hist.parent_path().string(), kWhere); !s) return s;
    nlohmann::json record = metaJson(info);
    record["scene"] = doc;
    if (auto s = writeFileAtomically((hist / revisionFile(info.revision)).string(),
                                     bytesOf(record.dump()), Durability::Durable, kWhere);
        !s)
        return s;
    return appendLine(hist / "index.jsonl", metaJson(info).dump() + "\n");
}

} // namespace

Status Store::putSceneImpl(const std::string& id, const RevisionInfo& info, const nlohmann::json& doc) {
    if (auto s = putRevision(historyDir(dir_, id), info, doc); !s) return s;
    const nlohmann::json record = {{"id", id}, {"revision", info.revision}, {"scene", doc}};
    return writeFileAtomically((fs::path(dir_) / "scenes" / (id + ".json")).string(),
                               bytesOf(record.dump()), Durability::Durable, kWhere);
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
    // Without its record the scene is gone; its history is garbage from here on.
    fs::remove_all(historyDir(dir_, id), ec);
    if (ec) return makeError(ErrorCode::Io, "dermis::Store::removeScene", id, ec.message());
    return Ok{};
}

Result<nlohmann::json> Store::readRevisionImpl(const std::string& id, std::uint64_t revision) const {
    const char* where = "dermis::Store::readRevision";
    const fs::path file = historyDir(dir_, id) / revisionFile(revision);
    auto bytes = readWholeFile(file.string(), std::size_t(1) << 30, where);
    if (!bytes) {
        if (bytes.error().code == ErrorCode::NotFound)
            return makeError(ErrorCode::NotFound, where, "revision",
                             "scene " + id + " keeps no revision " + std::to_string(revision));
        return bytes.error();
    }
    nlohmann::json record = nlohmann::json::parse(bytes->begin(), bytes->end(), nullptr, false);
    if (!record.is_object() || !record.contains("scene") ||
        record.value("revision", std::uint64_t{0}) != revision)
        return makeError(ErrorCode::Parse, where, file.string(), "damaged revision record");
    return std::move(record["scene"]);
}

Result<std::vector<Store::RevisionInfo>> Store::loadHistoryImpl(const std::string& id,
                                                            std::uint64_t current,
                                                            const nlohmann::json& currentDoc) {
    const fs::path hist = historyDir(dir_, id);
    std::map<std::uint64_t, RevisionInfo> byRevision;
    if (auto text = readWholeFile((hist / "index.jsonl").string()); text) {
        std::istringstream in(std::string(text->begin(), text->end()));
        std::string line;
        while (std::getline(in, line)) {
            const nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
            if (!j.is_object() || !j.contains("revision") || !j["revision"].is_number_unsigned())
                continue; // a torn line of an interrupted append
            RevisionInfo info;
            info.revision = j["revision"].get<std::uint64_t>();
            if (info.revision == 0 || info.revision > current) continue; // never committed
            info.time = j.value("time", 0.0);
            info.op = j.value("op", "");
            info.client = j.value("client", "");
            byRevision[info.revision] = std::move(info);
        }
    }
    std::error_code ec;
    if (!byRevision.count(current) || !fs::exists(hist / revisionFile(current), ec)) {
        RevisionInfo info{current, now(), "imported", ""};
        if (auto s = putRevision(hist, info, currentDoc); !s) return s.error();
        byRevision[current] = info;
    }
    std::vector<RevisionInfo> out;
    out.reserve(byRevision.size());
    for (auto& [revision, info] : byRevision)
        out.push_back(std::move(info));
    return out;
}

// --- the public entry points: the data folder is "<data>" in every message ---------------------------

Status Store::putScene(const std::string& id, const RevisionInfo& info, const nlohmann::json& doc) {
    return hidden(putSceneImpl(id, info, doc));
}
Status Store::removeScene(const std::string& id) { return hidden(removeSceneImpl(id)); }
Result<nlohmann::json> Store::readRevision(const std::string& id, std::uint64_t revision) const {
    return hidden(readRevisionImpl(id, revision));
}
Result<std::vector<Store::RevisionInfo>> Store::loadHistory(const std::string& id, std::uint64_t current,
                                                            const nlohmann::json& currentDoc) {
    return hidden(loadHistoryImpl(id, current, currentDoc));
}

} // namespace dermis
