#include "io/farm_manifest.hpp"

#include "io/atomic_file.hpp"
#include "io/image_io.hpp"
#include "common/sha256.hpp"

#include <algorithm>
#include <filesystem>
#include <map>
#include <set>

namespace dermis {
namespace fs = std::filesystem;

namespace {

constexpr const char* kFormat = "dermis.farm-manifest/1";

fs::path folderOf(const std::string& outPattern) {
    fs::path folder = fs::path(outPattern).parent_path();
    return folder.empty() ? fs::path(".") : folder;
}

std::string hexOf(const std::vector<std::uint8_t>& bytes) { return toHex(sha256(bytes)); }

/// True for frames the frame writers produce and the readers decode (PNG, JPEG, EXR, WebP …).
bool decodes(const std::vector<std::uint8_t>& bytes) {
    if (auto img = decodeImage8(bytes); img.ok() && img->width > 0 && img->height > 0) return true;
    auto height = readHeightImageFromMemory(bytes); // EXR frames decode as float images
    return height.ok() && height->width > 0 && height->height > 0;
}

} // namespace

std::string shardManifestPath(const std::string& outPattern, const Shard& shard) {
    return (folderOf(outPattern) / ("manifest.shard-" + std::to_string(shard.index) + "-of-" +
                                    std::to_string(shard.count) + ".json"))
        .string();
}

ManifestEntry manifestEntry(int frame, const std::string& path, const std::vector<std::uint8_t>& bytes) {
    return ManifestEntry{frame, fs::path(path).filename().string(), hexOf(bytes), bytes.size()};
}

Result<ManifestEntry> manifestEntryOfFile(int frame, const std::string& path) {
    auto bytes = readWholeFile(path, std::size_t(1) << 32, "dermis::manifestEntryOfFile");
    if (!bytes) return bytes.error();
    return manifestEntry(frame, path, *bytes);
}

Status writeShardManifest(const std::string& outPattern, const std::string& rangeSpec,
                          const Shard& shard, std::vector<ManifestEntry> entries) {
    std::sort(entries.begin(), entries.end(),
              [](const ManifestEntry& a, const ManifestEntry& b) { return a.frame < b.frame; });
    nlohmann::json list = nlohmann::json::array();
    for (const ManifestEntry& e : entries)
        list.push_back({{"frame", e.frame}, {"file", e.file}, {"sha256", e.sha256}, {"bytes", e.bytes}});
    const nlohmann::json doc = {
        {"format", kFormat},
        {"frames", rangeSpec},
        {"shard", std::to_string(shard.index) + "/" + std::to_string(shard.count)},
        {"out", fs::path(outPattern).filename().string()},
        {"entries", list}};
    const std::string text = doc.dump(1) + "\n";
    return writeFileAtomically(shardManifestPath(outPattern, shard),
                               std::vector<std::uint8_t>(text.begin(), text.end()),
                               Durability::Atomic, "dermis::writeShardManifest");
}

nlohmann::json FarmReport::toJson() const {
    return {{"complete", complete()}, {"expected", expected}, {"ok", ok.size()},
            {"missing", missing},     {"corrupt", corrupt},   {"unlisted", unlisted},
            {"manifests", manifests}, {"problems", problems}};
}

Result<FarmReport> verifyFarm(const std::string& outPattern, const FrameRange& range) {
    const char* where = "dermis::verifyFarm";
    const fs::path folder = folderOf(outPattern);
    FarmReport report;
    report.expected = range.count;
    // Every manifest in the folder: file name → the digest it lists (two manifests that disagree
    // about a file make it corrupt unless the file matches one of them).
    std::map<std::string, std::set<std::string>> listed;
    std::error_code ec;
    std::vector<fs::path> manifests;
    if (fs::is_directory(folder, ec)) {
        for (const auto& e : fs::directory_iterator(folder, ec)) {
            const std::string name = e.path().filename().string();
            if (name.rfind("manifest.shard-", 0) == 0 && e.path().extension() == ".json")
                manifests.push_back(e.path());
        }
    }
    std::sort(manifests.begin(), manifests.end());
    for (const fs::path& m : manifests) {
        auto bytes = readWholeFile(m.string(), std::size_t(64) << 20, where);
        if (!bytes) return bytes.error();
        nlohmann::json doc = nlohmann::json::parse(bytes->begin(), bytes->end(), nullptr, false);
        if (doc.is_discarded() || !doc.is_object() || doc.value("format", "") != kFormat ||
            !doc.contains("entries") || !doc["entries"].is_array())
            return makeError(ErrorCode::Parse, where, m.filename().string(),
                             "not a " + std::string(kFormat) + " document");
        for (const auto& e : doc["entries"]) {
            if (!e.is_object() || !e.contains("file") || !e["file"].is_string() ||
                !e.contains("sha256") || !e["sha256"].is_string())
                return makeError(ErrorCode::Parse, where, m.filename().string(),
                                 "an entry without file and sha256");
            listed[e["file"].get<std::string>()].insert(e["sha256"].get<std::string>());
        }
        report.manifests.push_back(m.filename().string());
    }
    for (int k = 0; k < range.count; ++k) {
        const std::string path = framePath(outPattern, k);
        const std::string name = fs::path(path).filename().string();
        auto bytes = readWholeFile(path, std::size_t(1) << 32, where);
        if (!bytes) {
            if (bytes.error().code != ErrorCode::NotFound) return bytes.error();
            report.missing.push_back(k);
            report.problems.push_back("frame " + std::to_string(k) + ": " + name + " is missing");
            continue;
        }
        auto it = listed.find(name);
        if (it != listed.end()) {
            if (it->second.count(hexOf(*bytes))) {
                report.ok.push_back(k);
            } else {
                report.corrupt.push_back(k);
                report.problems.push_back("frame " + std::to_string(k) + ": " + name +
                                          " differs from its manifest's SHA-256");
            }
        } else if (decodes(*bytes)) {
            report.ok.push_back(k);
            report.unlisted.push_back(k);
        } else {
            report.corrupt.push_back(k);
            report.problems.push_back("frame " + std::to_string(k) + ": " + name +
                                      " is in no manifest and does not decode");
        }
    }
    return report;
}

} // namespace dermis
