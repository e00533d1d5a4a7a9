#include "service/store.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <algorithm>
#include <atomic>
#include <cctype>
#include <cstdio>
#include <random>

namespace dermis {

namespace fs = std::filesystem;

namespace {

std::string errnoText() { return std::strerror(errno); }

Status fsyncPath(const std::string& path, int flags) {
    const int fd = ::open(path.c_str(), flags | O_CLOEXEC);
    if (fd < 0) return makeError(ErrorCode::Io, "dermis::Store", path, "cannot open: " + errnoText());
    const int rc = ::fsync(fd);
    ::close(fd);
    if (rc != 0) return makeError(ErrorCode::Io, "dermis::Store", path, "fsync failed: " + errnoText());
    return Ok{};
}

} // namespace

Result<std::vector<std::uint8_t>> Store::readFile(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return makeError(ErrorCode::NotFound, "dermis::Store::readFile", path, "cannot read");
    return std::vector<std::uint8_t>(std::istreambuf_iterator<char>(in), {});
}

Status Store::writeFileDurably(const std::string& path, const std::vector<std::uint8_t>& bytes) {
    const char* where = "dermis::Store::writeFileDurably";
    static std::atomic<unsigned> counter{0};
    const std::string tmp = path + ".tmp." + std::to_string(::getpid()) + "." +
                            std::to_string(counter.fetch_add(1));
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) return makeError(ErrorCode::Io, where, path, "cannot create a temp file: " + errnoText());
    std::size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            const std::string why = errnoText();
            ::close(fd);
            ::unlink(tmp.c_str());
            return makeError(ErrorCode::Io, where, path, "write failed: " + why);
        }
        done += static_cast<std::size_t>(n);
    }
    if (::fsync(fd) != 0 || ::close(fd) != 0) {
        const std::string why = errnoText();
        ::unlink(tmp.c_str());
        return makeError(ErrorCode::Io, where, path, "fsync failed: " + why);
    }
    if (::rename(tmp.c_str(), path.c_str()) != 0) {
        const std::string why = errnoText();
        ::unlink(tmp.c_str());
        return makeError(ErrorCode::Io, where, path, "rename failed: " + why);
    }
    return fsyncPath(fs::path(path).parent_path().string(), O_RDONLY | O_DIRECTORY);
}

Result<Store> Store::open(const std::string& dataDir) {
    Store s;
    std::error_code ec;
    s.dir_ = fs::absolute(dataDir, ec).lexically_normal().string();
    if (ec) s.dir_ = dataDir;
    for (const char* sub : {"models", "patterns", "scenes"}) {
        fs::create_directories(fs::path(s.dir_) / sub, ec);
        if (ec)
            return makeError(ErrorCode::Io, "dermis::Store::open", s.dir_,
                             std::string("cannot create ") + sub + "/: " + ec.message());
    }
    // Leftover temp files of an interrupted write are garbage: the rename never happened.
    std::vector<fs::path> leftovers;
    for (const char* sub : {"models", "patterns", "scenes"})
        for (const auto& e : fs::directory_iterator(fs::path(s.dir_) / sub, ec))
            if (e.path().filename().string().find(".tmp.") != std::string::npos)
                leftovers.push_back(e.path());
    for (const auto& e : fs::directory_iterator(fs::path(s.dir_), ec)) {
        const std::string name = e.path().filename().string();
        if (name.rfind("upload.tmp.", 0) == 0 || name.rfind("tmp_", 0) == 0) leftovers.push_back(e.path());
    }
    for (const fs::path& p : leftovers)
        fs::remove_all(p, ec);
    return s;
}

std::string Store::newId(const std::string& prefix) {
    static thread_local std::mt19937_64 rng{std::random_device{}()};
    char buf[17];
    std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(rng()));
    return prefix + "_" + buf;
}

bool Store::isGeneratedId(const std::string& id, char prefix) {
    if (id.size() != 18 || id[0] != prefix || id[1] != '_') return false;
    for (std::size_t i = 2; i < id.size(); ++i)
        if (!std::isxdigit(static_cast<unsigned char>(id[i])) || std::isupper(static_cast<unsigned char>(id[i])))
            return false;
    return true;
}

Status Store::putBlob(const std::string& kind, const std::string& id, const std::string& ext,
                      const std::vector<std::uint8_t>& bytes, nlohmann::json meta) {
    const fs::path folder = fs::path(dir_) / kind;
    const std::string file = (folder / (id + "." + ext)).string();
    if (auto s = writeFileDurably(file, bytes); !s) return s;
    meta["id"] = id;
    meta["file"] = id + "." + ext;
    const std::string text = meta.dump();
    return writeFileDurably((folder / (id + ".json")).string(),
                            std::vector<std::uint8_t>(text.begin(), text.end()));
}

bool Store::isSafeFileName(const std::string& name) {
    if (name.empty() || name.size() > 128 || name == "." || name == ".." || name[0] == '.') return false;
    for (char c : name)
        if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-' || c == ' '))
            return false;
    return true;
}

Status Store::putBlobFolder(const std::string& kind, const std::string& id,
                            const std::vector<std::pair<std::string, std::vector<std::uint8_t>>>& files,
                            const std::string& mainFile, nlohmann::json meta) {
    const char* where = "dermis::Store::putBlobFolder";
    const fs::path folder = fs::path(dir_) / kind;
    const fs::path tmp = folder / (id + ".d.tmp." + std::to_string(::getpid()));
    const fs::path final = folder / (id + ".d");
    std::error_code ec;
    fs::remove_all(tmp, ec);
    fs::create_directories(tmp, ec);
    if (ec) return makeError(ErrorCode::Io, where, tmp.string(), "cannot create: " + ec.message());
    for (const auto& [name, bytes] : files) {
        if (!isSafeFileName(name)) {
            fs::remove_all(tmp, ec);
            return makeError(ErrorCode::InvalidArgument, where, name, "not a plain file name");
        }
        if (auto s = writeFileDurably((tmp / name).string(), bytes); !s) {
            fs::remove_all(tmp, ec);
            return s;
        }
    }
    fs::rename(tmp, final, ec);
    if (ec) {
        fs::remove_all(tmp, ec);
        return makeError(ErrorCode::Io, where, final.string(), "rename failed: " + ec.message());
    }
    if (auto s = fsyncPath(folder.string(), O_RDONLY | O_DIRECTORY); !s) return s;
    meta["id"] = id;
    meta["file"] = id + ".d/" + mainFile;
    const std::string text = meta.dump();
    return writeFileDurably((folder / (id + ".json")).string(),
                            std::vector<std::uint8_t>(text.begin(), text.end()));
}

std::vector<Store::Blob> Store::listBlobs(const std::string& kind,
                                          std::vector<std::string>& skipped) const {
    std::vector<Blob> out;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(fs::path(dir_) / kind, ec)) {
        if (e.path().extension() != ".json") continue;
        auto bytes = readFile(e.path().string());
        nlohmann::json meta = bytes ? nlohmann::json::parse(bytes->begin(), bytes->end(), nullptr, false)
                                    : nlohmann::json();
        if (!meta.is_object() || !meta.contains("id") || !meta["id"].is_string() ||
            !meta.contains("file") || !meta["file"].is_string()) {
            skipped.push_back(e.path().string() + ": unreadable metadata");
            continue;
        }
        Blob b;
        b.id = meta["id"].get<std::string>();
        b.file = (fs::path(dir_) / kind / meta["file"].get<std::string>()).string();
        b.meta = std::move(meta);
        if (b.id + ".json" != e.path().filename().string() || !fs::exists(b.file, ec)) {
            skipped.push_back(e.path().string() + ": no data file");
            continue;
        }
        out.push_back(std::move(b));
    }
    std::sort(out.begin(), out.end(), [](const Blob& a, const Blob& b) {
        return a.meta.value("created", 0.0) < b.meta.value("created", 0.0) ||
               (a.meta.value("created", 0.0) == b.meta.value("created", 0.0) && a.id < b.id);
    });
    return out;
}

Status Store::removeBlob(const std::string& kind, const std::string& id) {
    std::vector<std::string> skipped;
    const fs::path folder = fs::path(dir_) / kind;
    std::error_code ec;
    // Metadata first: without it the blob is no longer listed, even if the data file stays.
    fs::remove(folder / (id + ".json"), ec);
    if (ec) return makeError(ErrorCode::Io, "dermis::Store::removeBlob", id, ec.message());
    std::vector<fs::path> doomed;
    for (const auto& e : fs::directory_iterator(folder, ec))
        if (e.path().stem() == id) doomed.push_back(e.path());
    for (const fs::path& path : doomed)
        fs::remove_all(path, ec);
    return fsyncPath(folder.string(), O_RDONLY | O_DIRECTORY);
}

Status Store::putScene(const std::string& id, std::uint64_t revision, const nlohmann::json& doc) {
    const nlohmann::json record = {{"id", id}, {"revision", revision}, {"scene", doc}};
    const std::string text = record.dump();
    return writeFileDurably((fs::path(dir_) / "scenes" / (id + ".json")).string(),
                            std::vector<std::uint8_t>(text.begin(), text.end()));
}

Status Store::removeScene(const std::string& id) {
    const fs::path folder = fs::path(dir_) / "scenes";
    std::error_code ec;
    fs::remove(folder / (id + ".json"), ec);
    if (ec) return makeError(ErrorCode::Io, "dermis::Store::removeScene", id, ec.message());
    return fsyncPath(folder.string(), O_RDONLY | O_DIRECTORY);
}

std::vector<Store::SceneRecord> Store::listScenes(std::vector<std::string>& skipped) const {
    std::vector<SceneRecord> out;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(fs::path(dir_) / "scenes", ec)) {
        if (e.path().extension() != ".json") continue;
        auto bytes = readFile(e.path().string());
        nlohmann::json rec = bytes ? nlohmann::json::parse(bytes->begin(), bytes->end(), nullptr, false)
                                   : nlohmann::json();
        if (!rec.is_object() || !rec.contains("id") || !rec["id"].is_string() ||
            !rec.contains("revision") || !rec["revision"].is_number_unsigned() || !rec.contains("scene")) {
            skipped.push_back(e.path().string() + ": unreadable scene record");
            continue;
        }
        out.push_back({rec["id"].get<std::string>(), rec["revision"].get<std::uint64_t>(), rec["scene"]});
    }
    std::sort(out.begin(), out.end(),
              [](const SceneRecord& a, const SceneRecord& b) { return a.id < b.id; });
    return out;
}

} // namespace dermis
