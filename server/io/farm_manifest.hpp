// Dermis io — what a render farm shard wrote, and checking a whole range afterwards (SPEC §7).
//
// Each shard of `render --frames A:B:STEP --shard I/N --out DIR/frame_%04d.png` writes
// DIR/manifest.shard-I-of-N.json when it has finished:
//   {"format": "dermis.farm-manifest/1", "frames": "A:B:STEP", "shard": "I/N",
//    "out": "frame_%04d.png", "entries": [{"frame": k, "file": "frame_0005.png",
//    "sha256": "<64 hex>", "bytes": n}, …]}
// (file names relative to DIR: the folder can be moved). verifyFarm reads every manifest in DIR
// and checks each frame of the range: the file exists (missing otherwise), its SHA-256 is the one
// a manifest lists (corrupt otherwise), or — for a frame no manifest lists — it decodes as an
// image (corrupt otherwise; reported as unlisted when it does).
//
// Not thread-safe for two writers of the same manifest (shards write different files). Fails
// with Io naming the file when a manifest cannot be written or read, Parse when one is not a
// dermis.farm-manifest/1 document. Never deletes or rewrites frames.
#pragma once

#include "core/frame_range.hpp"
#include "core/result.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace dermis {

struct ManifestEntry {
    int frame = 0;
    std::string file;   ///< relative to the manifest's folder
    std::string sha256; ///< 64 lower-case hex digits
    std::uint64_t bytes = 0;
};

/// The manifest path of `shard` for frames named by `outPattern` (…/manifest.shard-I-of-N.json).
std::string shardManifestPath(const std::string& outPattern, const Shard& shard);

/// An entry for frame `frame` whose encoded bytes are `bytes`, written to `path`.
ManifestEntry manifestEntry(int frame, const std::string& path, const std::vector<std::uint8_t>& bytes);

/// The entry of a frame file already on disk (a frame a previous run completed). Io when the
/// file cannot be read.
Result<ManifestEntry> manifestEntryOfFile(int frame, const std::string& path);

/// Writes the shard's manifest atomically (entries sorted by frame). `rangeSpec` is the --frames
/// text as given.
Status writeShardManifest(const std::string& outPattern, const std::string& rangeSpec,
                          const Shard& shard, std::vector<ManifestEntry> entries);

struct FarmReport {
    int expected = 0;           ///< frames in the range
    std::vector<int> ok;        ///< present, and matching their manifest entry (or decodable)
    std::vector<int> missing;   ///< no file
    std::vector<int> corrupt;   ///< digest differs from the manifest's, or does not decode
    std::vector<int> unlisted;  ///< present and decodable but in no manifest (also in ok)
    std::vector<std::string> manifests; ///< the manifest files read
    std::vector<std::string> problems;  ///< one line per missing/corrupt frame

    bool complete() const { return missing.empty() && corrupt.empty(); }
    nlohmann::json toJson() const;
};

/// Checks every frame of `range` named by `outPattern` against the manifests beside them
/// (unlisted frames are decoded with the pattern image decoder, io/image_io).
Result<FarmReport> verifyFarm(const std::string& outPattern, const FrameRange& range);

} // namespace dermis
