// Dermis service — the pure part of a scene's history in the data folder (store_history.cpp does
// the files): the JSON Patch a revision is stored as, the lines of a chunk file, and the retention
// window of `serve --history-keep`. No file I/O, no clock (callers pass the time), no locks.
//
// A chunk file (scenes/<id>.history/c<B>.jsonl, store.hpp) holds revisions B, B+1, … B+k−1
// (k ≤ kChunkRevisions), one line each, every line written whole and ending in '\n':
//   {"revision":B,"scene":{…}}        the full canonical document of B (the snapshot)
//   {"revision":B+i,"patch":[…]}      an RFC 6902 JSON Patch from revision B+i−1's document
// so that revision R is the snapshot of its chunk plus at most kChunkRevisions − 1 patches.
// Every line starts with {"revision":<n>, so a chunk is scanned without parsing its documents.
#pragma once

#include "core/result.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace dermis {

/// One kept revision of a scene (SPEC §6 History), as its index line holds it.
struct RevisionInfo {
    std::uint64_t revision = 0;
    double time = 0.0;  ///< seconds since the Unix epoch
    std::string op;     ///< what made it, e.g. "patch placement elbow_l"
    std::string client; ///< X-Dermis-Client of the edit ("" = not named)
};

/// Most revisions in one chunk: a read replays at most kChunkRevisions − 1 patches. 256 keeps a
/// one-placement edit of a 1,000-placement scene (262 KB snapshot) near 1.2 KB on disk, the
/// snapshot's share included (docs/scenes.md "Scene documents"). Readers rely on it: the chunk holding
/// revision R starts at most kChunkRevisions − 1 revisions before R.
inline constexpr std::uint64_t kChunkRevisions = 256;

/// An RFC 6902 JSON Patch that turns `from` into `to` exactly: applied to a copy of `from` (as
/// parsed back from its dump), it gives a document whose dump is byte for byte `to`'s. Values are
/// compared strictly (same JSON type, doubles bit for bit: 1 and 1.0, 0.0 and −0.0 differ), unlike
/// nlohmann::json::diff. Arrays keep their common head and tail, so inserting or deleting one
/// element of a long array (a placement) is one "add" or "remove"; a member or element most of
/// whose parts changed is one "replace". Never fails; equal documents give [].
nlohmann::json historyDiff(const nlohmann::json& from, const nlohmann::json& to);

/// Applies RFC 6902 `patch` to `doc` in place. Parse (naming `where`, field "patch") when the patch
/// does not apply (a path that does not exist, a malformed operation); `doc` is then unspecified.
Status applyHistoryPatch(nlohmann::json& doc, const nlohmann::json& patch, const char* where);

/// The line that makes `revision` a snapshot: {"revision":N,"scene":<docText>}\n. `docText` is
/// the document's dump (not checked).
std::string snapshotLine(std::uint64_t revision, std::string_view docText);
/// The line that stores `revision` as `patch` against the revision before it.
std::string patchLine(std::uint64_t revision, const nlohmann::json& patch);

/// One complete line of a chunk: its revision and where it lies in the chunk's bytes.
struct ChunkLine {
    std::uint64_t revision = 0;
    bool snapshot = false;  ///< a "scene" line (else a "patch" line)
    std::size_t begin = 0;  ///< offset of its '{'
    std::size_t end = 0;    ///< offset just past its '\n'
};
/// The lines of a chunk's bytes from the start, up to and including the first one whose
/// revision is `upTo`: the scan stops at the first line that is torn (no '\n': an interrupted
/// append) or not of either shape. Never fails; garbage gives fewer lines.
std::vector<ChunkLine> scanChunk(std::string_view bytes,
                                 std::uint64_t upTo = ~std::uint64_t(0));

/// The text of revision `revision`'s document — byte for byte the dump() of the document that
/// was stored — from the bytes of chunk c<base>: its snapshot (first line, of revision `base`),
/// then each patch line in turn (revisions base+1, base+2, …). The snapshot is not parsed whole:
/// it is split into its top-level members and the elements of "placements", and a patch parses
/// and dumps again only the parts it touches (so reading a revision of a 1,000-placement scene
/// costs a scan of its text, not a parse); an operation elsewhere (the root, move/copy/test)
/// parses the document whole. NotFound (field "revision") when the chunk's lines stop before
/// `revision`; Parse (field `file`) when a line on the way is damaged, out of order or does not
/// apply. The snapshot's text is checked for shape (strings closed, brackets balanced, members
/// in order), not validated as JSON throughout.
Result<std::string> replayChunk(std::string_view bytes, std::uint64_t base, std::uint64_t revision,
                                const std::string& file, const char* where);

/// `serve --history-keep`: how much of each scene's history is kept. Default: everything.
struct HistoryRetention {
    std::uint64_t revisions = 0; ///< keep the newest N revisions (0 = no count limit)
    double seconds = 0.0;        ///< keep revisions made in the last S seconds (0 = no age limit)
    bool keepsAll() const { return revisions == 0 && seconds <= 0.0; }
    /// The flag's value: "500", "30d" (days as a shortest decimal), "all" when keepsAll.
    std::string text() const;
    /// The flag as given, e.g. "--history-keep 500", "--history-keep 30d"; "" when keepsAll.
    std::string flag() const;
};

/// Parses the flag's value: "N" (a count ≥ 1: the newest N revisions) or "Nd" (days > 0, a
/// decimal like "0.5d" allowed: the revisions of the last N days); "all" keeps everything.
/// InvalidArgument (field "--history-keep") for anything else, saying what is accepted.
Result<HistoryRetention> parseHistoryRetention(const std::string& text);

/// The oldest revision `retention` keeps of `history` (kept revisions, oldest first, the last
/// the current one) at time `now` (seconds since the epoch): the newest `revisions` of them,
/// and of those the ones from `now − seconds` on, walking back from the current one (the first
/// older revision ends the window, so a clock that stepped back never keeps a gap). The current
/// revision is always kept. 0 when `history` is empty.
std::uint64_t oldestKept(const std::vector<RevisionInfo>& history,
                         const HistoryRetention& retention, double now);

} // namespace dermis
