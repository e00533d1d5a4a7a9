#include "service/store.hpp"

#include "io/atomic_file.hpp"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <random>

namespace dermis {

namespace fs = std::filesystem;

namespace {

/// Every store write: whole, synced, and its folder synced (atomic_file.hpp).
Status writeDurably(const std::string& path, const std::vector<std::uint8_t>& bytes) {
    return writeFileAtomically(path, bytes, Durability::Durable, "dermis::Store");
}

} // namespace

Result<Store> Store::open(const std::string& dataDir) {
    Store s;
    std::error_code ec;
    s.dir_ = fs::absolute(dataDir, ec).lexically_normal().string();
    if (ec) s.dir_ = dataDir;
    for (const char* sub : {"models", "patterns", "scenes", "environments"}) {
        fs::create_directories(fs::path(s.dir_) / sub, ec);
        if (ec)
            return makeError(ErrorCode::Io, "dermis::Store::open", s.dir_,
                             std::string("cannot create ") + sub + "/: " + ec.message());
    }
    // Leftover temporary files and folders of an interrupted write are garbage: the rename
    // never happened. One rule for every writer: the name holds kTempMarker (atomic_file.hpp).
    std::vector<fs::path> leftovers;
    for (const fs::path& folder : {fs::path(s.dir_), fs::path(s.dir_) / "models", fs::path(s.dir_) / "patterns",
                                   fs::path(s.dir_) / "scenes", fs::path(s.dir_) / "environments"})
        for (const auto& e : fs::directory_iterator(folder, ec))
            if (isTempName(e.path().filename().string())) leftovers.push_back(e.path());
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

std::string Store::contentId(const std::string& prefix, const std::string& digestHex) {
    return prefix + "_" + digestHex.substr(0, 16);
}

bool Store::isGeneratedId(const std::string& id, char prefix) {
    if (id.size() != 18 || id[0] != prefix || id[1] != '_') return false;
    for (std::size_t i = 2; i < id.size(); ++i)
        if (!std::isxdigit(static_cast<unsigned char>(id[i])) || std::isupper(static_cast<unsigned char>(id[i])))
            return false;
    return true;
}

Status Store::putBlobImpl(const std::string& kind, const std::string& id, const std::string& ext,
                      const std::vector<std::uint8_t>& bytes, nlohmann::json meta) {
    const fs::path folder = fs::path(dir_) / kind;
    const std::string file = (folder / (id + "." + ext)).string();
    if (auto s = writeDurably(file, bytes); !s) return s;
    meta["id"] = id;
    meta["file"] = id + "." + ext;
    const std::string text = meta.dump();
    return writeDurably((folder / (id + ".json")).string(),
                            std::vector<std::uint8_t>(text.begin(), text.end()));
}

bool Store::isSafeFileName(const std::string& name) {
    if (name.empty() || name.size() > 128 || name == "." || name == ".." || name[0] == '.') return false;
    for (char c : name)
        if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-' || c == ' '))
            return false;
    return true;
}

Status Store::putBlobFolderImpl(const std::string& kind, const std::string& id,
                            const std::map<std::string, std::vector<std::uint8_t>>& files,
                            const std::string& mainFile, nlohmann::json meta) {
    const char* where = "dermis::Store::putBlobFolder";
    const fs::path folder = fs::path(dir_) / kind;
    const fs::path tmp = folder / (id + ".d" + kTempMarker + std::to_string(::getpid()));
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
        if (auto s = writeDurably((tmp / name).string(), bytes); !s) {
            fs::remove_all(tmp, ec);
            return s;
        }
    }
    fs::rename(tmp, final, ec);
    if (ec) {
        fs::remove_all(tmp, ec);
        return makeError(ErrorCode::Io, where, final.string(), "rename failed: " + ec.message());
    }
    if (auto s = syncFolder(folder.string(), "dermis::Store"); !s) return s;
    meta["id"] = id;
    meta["file"] = id + ".d/" + mainFile;
    const std::string text = meta.dump();
    return writeDurably((folder / (id + ".json")).string(),
                            std::vector<std::uint8_t>(text.begin(), text.end()));
}

std::vector<Store::Blob> Store::listBlobs(const std::string& kind,
                                          std::vector<std::string>& skipped) const {
    std::vector<Blob> out;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(fs::path(dir_) / kind, ec)) {
        if (e.path().extension() != ".json") continue;
        auto bytes = readWholeFile(e.path().string());
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

Status Store::removeBlobImpl(const std::string& kind, const std::string& id) {
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
    return syncFolder(folder.string(), "dermis::Store");
}

std::vector<Store::SceneRecord> Store::listScenes(std::vector<std::string>& skipped) const {
    std::vector<SceneRecord> out;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(fs::path(dir_) / "scenes", ec)) {
        if (e.path().extension() != ".json") continue;
        auto bytes = readWholeFile(e.path().string());
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

// --- the public entry points: the data folder is "<data>" in every message ---------------------------

Status Store::putBlob(const std::string& kind, const std::string& id, const std::string& ext,
                      const std::vector<std::uint8_t>& bytes, nlohmann::json meta) {
    return hidden(putBlobImpl(kind, id, ext, bytes, std::move(meta)));
}
Status Store::putBlobFolder(const std::string& kind, const std::string& id,
                            const std::map<std::string, std::vector<std::uint8_t>>& files,
                            const std::string& mainFile, nlohmann::json meta) {
    return hidden(putBlobFolderImpl(kind, id, files, mainFile, std::move(meta)));
}
Status Store::removeBlob(const std::string& kind, const std::string& id) { return hidden(removeBlobImpl(kind, id)); }

} // namespace dermis
