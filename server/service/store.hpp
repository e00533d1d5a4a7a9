// Dermis service — the server's data directory: uploaded models and patterns, and scene
// documents, each written atomically and durably before a call returns (writeFileAtomically with
// Durability::Durable: temp file in the same folder, fsync, rename over the target, fsync of the
// folder) — or, for the lines of a scene's history, appended whole and fsync'd — so that an
// acknowledged edit survives a crash or kill -9. Store::open removes what an interrupted write
// left (names holding kTempMarker, at the top and in the three folders; loadHistory those in a
// history folder); the store knows no other temporary names.
//
// Layout under the data directory:
//   models/<id>.glb      + models/<id>.json    (metadata, written last: the commit record)
//   patterns/<id>.<ext>  + patterns/<id>.json
//   environments/<id>.<hdr|exr> + environments/<id>.json
//   scenes/<id>.json     ({"id", "revision", "scene"}: the current revision)
//   scenes/<id>.history/ (index.jsonl: one line per revision; c<B>.jsonl: chunks of up to
//                         kChunkRevisions revisions from B on, a snapshot then patches
//                         (history_format.hpp); r<N>.json: a whole revision, as versions before
//                         chunks wrote them: read, never written)
// Ids are generated ("m_…", "p_…", "s_…": 16 hex digits) — never taken from a client — so no file
// name comes from a request. Scene ids are random; model and pattern ids are content addresses
// (contentId: the first 16 hex digits of the SHA-256 of the uploaded bytes), so one upload of the
// same bytes is stored once. Random model and pattern ids of earlier versions stay valid.
// Thread-safe when the caller serialises mutations (Service's writer lock): the store remembers
// where each scene's history goes on (its last chunk) for its writers only; readers
// (readRevision, listScenes, listBlobs) touch nothing but files and may run meanwhile.
#pragma once

#include "core/result.hpp"
#include "service/history_format.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace dermis {

class Store {
public:
    /// Creates the folders if needed. Fails (Io) when the directory cannot be created or written.
    static Result<Store> open(const std::string& dataDir);

    const std::string& dir() const { return dir_; }

    /// A fresh id: `prefix` + "_" + 16 random hex digits.
    static std::string newId(const std::string& prefix);
    /// A content address: `prefix` + "_" + the first 16 hex digits of `digestHex` (a SHA-256 in
    /// lower-case hex, common/sha256 toHex), so it has the shape of newId's ids.
    static std::string contentId(const std::string& prefix, const std::string& digestHex);
    /// True for ids this store generates (prefix "m", "p" or "s").
    static bool isGeneratedId(const std::string& id, char prefix);

    struct Blob {
        std::string id;
        std::string file;   ///< absolute path of the bytes
        nlohmann::json meta; ///< as stored by putBlob
    };
    /// Writes <kind>/<id>.<ext> then <kind>/<id>.json (`meta` plus "id", "file").
    Status putBlob(const std::string& kind, const std::string& id, const std::string& ext,
                   const std::vector<std::uint8_t>& bytes, nlohmann::json meta);
    /// Writes a multi-file blob: every file into <kind>/<id>.d/ (a temp folder renamed into place,
    /// each file fsync'd), then <kind>/<id>.json with "file" = "<id>.d/<mainFile>". Names must be
    /// plain file names (checked: no '/', no "..", [A-Za-z0-9._ -] only).
    Status putBlobFolder(const std::string& kind, const std::string& id,
                         const std::map<std::string, std::vector<std::uint8_t>>& files,
                         const std::string& mainFile, nlohmann::json meta);
    /// A plain file name a client may give a file: [A-Za-z0-9._ -], not "." or "..", ≤ 128 chars.
    static bool isSafeFileName(const std::string& name);
    /// Every blob of `kind` with a readable metadata record (others are reported in `skipped`).
    std::vector<Blob> listBlobs(const std::string& kind, std::vector<std::string>& skipped) const;
    Status removeBlob(const std::string& kind, const std::string& id);

    /// One kept revision of a scene (SPEC §6 History): history_format.hpp.
    using RevisionInfo = dermis::RevisionInfo;
    /// Writes a new revision of a scene, each step durable, in this order: the revision itself in
    /// its chunk, scenes/<id>.history/c<B>.jsonl — a patch line appended (and fsync'd) to the
    /// chunk the previous revision ends, or a new chunk starting with the whole document (temp
    /// file, fsync, rename: a snapshot) when this store did not write the previous revision since
    /// it opened, that chunk holds kChunkRevisions revisions, or its patches would outweigh its
    /// snapshot —; a line {"revision", "time", "op", "client"} appended to index.jsonl; then
    /// the current record scenes/<id>.json = {"id", "revision", "scene"} — the commit point: a
    /// crash before it leaves the scene at its previous revision (loadHistory forgets the newer
    /// leftovers). The store keeps `doc` (shared, not copied) to diff the next revision against.
    /// Io error when a step fails; what it appended is cut off again and the next revision starts
    /// a new chunk.
    Status putScene(const std::string& id, const RevisionInfo& info,
                    std::shared_ptr<const nlohmann::json> doc);
    /// Same with a copy of `doc`.
    Status putScene(const std::string& id, const RevisionInfo& info, const nlohmann::json& doc);
    /// Same with no op or client and the current time (tests, tools).
    Status putScene(const std::string& id, std::uint64_t revision, const nlohmann::json& doc);
    /// Removes the current record, then the scene's history.
    Status removeScene(const std::string& id);
    /// The text of revision `revision` of scene `id`: byte for byte the dump() of the document
    /// putScene was given. From a whole-revision file r<N>.json when there is one, else from the
    /// chunk c<B>.jsonl with the largest B ≤ N (at most kChunkRevisions − 1 below), replayed up to
    /// N (replayChunk: the snapshot's text is split, not parsed). NotFound (field "revision") when
    /// no file holds that revision, Parse when one on the way is damaged. Does not know the
    /// retention window (the service answers dropped revisions).
    Result<std::string> readRevisionText(const std::string& id, std::uint64_t revision) const;
    /// The same document parsed (Parse when its text is not JSON).
    Result<nlohmann::json> readRevision(const std::string& id, std::uint64_t revision) const;

    /// A scene's history as loadHistory finds it.
    struct History {
        std::vector<RevisionInfo> revisions; ///< kept, oldest first; the last is the current one
        /// Revisions below it were dropped by the history retention (0: none were), as the last
        /// compaction recorded (index.jsonl's first line {"dropped_before": N}).
        std::uint64_t droppedBefore = 0;
    };
    /// The kept revisions of a scene whose current record says `current`, from the index
    /// (later lines win over earlier ones for the same revision; a torn last line is ignored;
    /// revisions above `current` — an interrupted commit — and below the recorded retention
    /// window are dropped). Tidies the folder of what a crash left: temp files, chunks and
    /// whole-revision files above `current` or wholly below the window, chunk lines after
    /// `current`'s. A scene written before history existed, or whose current revision is not
    /// readable, gets that revision written now from `currentDoc` (op "imported", a new chunk).
    /// Io error when that write fails.
    Result<History> loadHistory(const std::string& id, std::uint64_t current,
                                const nlohmann::json& currentDoc);
    /// Whether dropRevisionsBefore(id, oldestKept, …) would remove files now: the history holds
    /// a whole chunk (or whole-revision file) below `oldestKept`'s chunk. Cheap (no I/O).
    bool compactionDue(const std::string& id, std::uint64_t oldestKept) const;
    /// Compacts a scene's history to the retention window that starts at `oldestKept` (a kept
    /// revision), `kept` being the kept revisions, oldest first. Crash-safe in three steps: (1)
    /// the new index — {"dropped_before": oldestKept}, then the lines of `kept` — is written
    /// beside the old one, fsync'd and renamed over it (the switch: before it the old history
    /// stands whole, after it the new one); (2) then the chunks whose every revision is below
    /// `oldestKept`'s chunk and the whole-revision files below `oldestKept` are deleted (a crash
    /// in between leaves files loadHistory deletes). No snapshot is written: the chunk holding
    /// `oldestKept` stays whole (its first revisions, below the window, are no longer listed
    /// or served, and go with that chunk). Io error when the index cannot be written (nothing
    /// changed) or a file not deleted (the next compaction or open tries again).
    Status dropRevisionsBefore(const std::string& id, std::uint64_t oldestKept,
                               const std::vector<RevisionInfo>& kept);
    struct SceneRecord {
        std::string id;
        std::uint64_t revision = 0;
        nlohmann::json doc;
    };
    std::vector<SceneRecord> listScenes(std::vector<std::string>& skipped) const;

private:
    // The work behind the public methods of the same name; those return what these do with the
    // data folder written "<data>" in every message and field (an answer never names a server
    // path, e.g. an io_error when the disk is full).
    Status putBlobImpl(const std::string& kind, const std::string& id, const std::string& ext,
                       const std::vector<std::uint8_t>& bytes, nlohmann::json meta);
    Status putBlobFolderImpl(const std::string& kind, const std::string& id,
                             const std::map<std::string, std::vector<std::uint8_t>>& files,
                             const std::string& mainFile, nlohmann::json meta);
    Status removeBlobImpl(const std::string& kind, const std::string& id);
    Status putSceneImpl(const std::string& id, const RevisionInfo& info,
                        std::shared_ptr<const nlohmann::json> doc);
    Status removeSceneImpl(const std::string& id);
    Result<std::string> readRevisionTextImpl(const std::string& id, std::uint64_t revision) const;
    Result<History> loadHistoryImpl(const std::string& id, std::uint64_t current,
                                    const nlohmann::json& currentDoc);
    Status dropRevisionsBeforeImpl(const std::string& id, std::uint64_t oldestKept,
                                   const std::vector<RevisionInfo>& kept);
    /// `r` with the data folder written "<data>" in its error's message and field.
    template <class R> R hidden(R r) const {
        if (r) return r;
        Error e = r.error();
        for (std::string* text : {&e.message, &e.field})
            for (std::size_t at = text->find(dir_); !dir_.empty() && at != std::string::npos; at = text->find(dir_, at + 6))
                text->replace(at, dir_.size(), "<data>");
        return R(std::move(e));
    }

    /// Where a scene's history goes on, for its writers (putScene, dropRevisionsBefore).
    struct Tail {
        std::uint64_t base = 0;         ///< the last chunk, c<base>.jsonl (0: none yet)
        std::uint64_t last = 0;         ///< its last revision
        std::size_t snapshotBytes = 0;  ///< its first line
        std::size_t patchBytes = 0;     ///< its other lines
        std::shared_ptr<const nlohmann::json> lastDoc; ///< `last`'s document as written; null
                                                       ///< after an open: the next one is a snapshot
        std::uint64_t oldestFile = 0;   ///< the oldest revision a file holds (0: unknown)
        std::uint64_t oldestChunkEnd = 0; ///< the first revision past that file (its successor's start)
    };
    std::map<std::string, Tail> tails_;
    std::string dir_;
};

} // namespace dermis
