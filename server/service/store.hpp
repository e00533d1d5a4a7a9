// Dermis service — the server's data directory: uploaded models and patterns, and scene
// documents, each written atomically and durably before a call returns (writeFileAtomically with
// Durability::Durable: temp file in the same folder, fsync, rename over the target, fsync of the
// folder), so that an acknowledged edit survives a crash or kill -9. Store::open removes what an
// interrupted write left (names holding kTempMarker, at the top and in the three folders); the
// store knows no other temporary names.
//
// Layout under the data directory:
//   models/<id>.glb      + models/<id>.json    (metadata, written last: the commit record)
//   patterns/<id>.<ext>  + patterns/<id>.json
//   scenes/<id>.json     ({"id", "revision", "scene"}: the current revision)
//   scenes/<id>.history/ (r<N>.json per kept revision, index.jsonl: one line per revision)
// Ids are generated ("m_…", "p_…", "s_…": 16 hex digits) — never taken from a client — so no file
// name comes from a request. Scene ids are random; model and pattern ids are content addresses
// (contentId: the first 16 hex digits of the SHA-256 of the uploaded bytes), so one upload of the
// same bytes is stored once. Random model and pattern ids of earlier versions stay valid. Thread-safe: the caller serialises mutations (Service's lock).
#pragma once

#include "core/result.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <map>
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
    /// lower-case hex, io/sha256 toHex), so it has the shape of newId's ids.
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

    /// One kept revision of a scene (SPEC §6 History).
    struct RevisionInfo {
        std::uint64_t revision = 0;
        double time = 0.0;  ///< seconds since the Unix epoch
        std::string op;     ///< what made it, e.g. "patch placement elbow_l"
        std::string client; ///< X-Dermis-Client of the edit ("" = not named)
    };
    /// Writes a new revision of a scene, each step durable, in this order: the revision's own
    /// document scenes/<id>.history/r<N>.json = {"revision", "time", "op", "client", "scene"},
    /// a line {"revision", "time", "op", "client"} appended to scenes/<id>.history/index.jsonl,
    /// then the current record scenes/<id>.json = {"id", "revision", "scene"} — the commit
    /// point: a crash before it leaves the scene at its previous revision (loadHistory forgets
    /// the newer leftovers).
    Status putScene(const std::string& id, const RevisionInfo& info, const nlohmann::json& doc);
    /// Same with no op or client and the current time (tests, tools).
    Status putScene(const std::string& id, std::uint64_t revision, const nlohmann::json& doc);
    /// Removes the current record, then the scene's history.
    Status removeScene(const std::string& id);
    /// The document of revision `revision` of scene `id` (history/r<N>.json): NotFound (field
    /// "revision") when that revision is not kept, Parse when its file is damaged.
    Result<nlohmann::json> readRevision(const std::string& id, std::uint64_t revision) const;
    /// The kept revisions of a scene whose current record says `current`, oldest first, from
    /// the index (later lines win over earlier ones for the same revision; a torn last line is
    /// ignored; revisions above `current` — an interrupted commit — are dropped). A scene written
    /// before history existed, or whose current revision is missing from the index, gets that
    /// revision written now from `currentDoc` (op "imported"). Io error when that write fails.
    Result<std::vector<RevisionInfo>> loadHistory(const std::string& id, std::uint64_t current,
                                                  const nlohmann::json& currentDoc);
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
    Status putSceneImpl(const std::string& id, const RevisionInfo& info, const nlohmann::json& doc);
    Status removeSceneImpl(const std::string& id);
    Result<nlohmann::json> readRevisionImpl(const std::string& id, std::uint64_t revision) const;
    Result<std::vector<RevisionInfo>> loadHistoryImpl(const std::string& id, std::uint64_t current,
                                                      const nlohmann::json& currentDoc);
    /// `r` with the data folder written "<data>" in its error's message and field.
    template <class R> R hidden(R r) const {
        if (r) return r;
        Error e = r.error();
        for (std::string* text : {&e.message, &e.field})
            for (std::size_t at = text->find(dir_); !dir_.empty() && at != std::string::npos; at = text->find(dir_, at + 6))
                text->replace(at, dir_.size(), "<data>");
        return R(std::move(e));
    }

    std::string dir_;
};

} // namespace dermis
