// Dermis service — private: the state every service_*.cpp file shares, its locks and the helpers
// they have in common. Not installed, not included outside server/service/.
//
// Locks (order: writeMutex, then mutex):
//   writeMutex  serialises mutations (edits, uploads, deletes). A mutation holds it for its whole
//               run: validate against the current state, write durably, swap in, announce. So
//               nothing changes between its check and its swap, and its events go out in order.
//   mutex       guards the maps below. Mutations take it exclusively only to swap (no I/O and no
//               parsing under it); readers and renders take it shared to copy what they need.
// Pattern images are shared and immutable (core PatternImage): a render keeps the ones it uses
// alive after the lock is released, so deleting a pattern never waits for a render.
#pragma once

#include "service/decode_budget.hpp"
#include "service/service.hpp"

#include "core/environment.hpp"
#include "core/frame_plan.hpp"
#include "core/model_derived.hpp"
#include "io/gltf_loader.hpp"
#include "service/content_cache.hpp"
#include "service/layout_cache.hpp"

#include <atomic>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <shared_mutex>
#include <string>

namespace dermis {

using json = nlohmann::json;

struct SurfaceOutline;

namespace detail {

inline constexpr const char* kBuiltinDefault = "builtin:default";

struct ModelEntry {
    std::string id, name;
    std::shared_ptr<const Model> model;
    std::size_t bytes = 0;
    bool builtin = false;
    std::string sha256; ///< hex SHA-256 of an uploaded .glb ("" otherwise): content address
    /// The model's derived data (UV index, symmetry plane), made on first use (State::derivedOf)
    /// and shared by the copies of this entry; it goes with the entry when the model is deleted
    /// (requests still holding it keep it, and the model, until they finish).
    std::shared_ptr<ModelDerivedSlot> derived = std::make_shared<ModelDerivedSlot>();
};

struct PatternEntry {
    std::string id, name;
    bool builtin = false;
    std::size_t bytes = 0;
    const PatternInfo* info = nullptr; ///< manifest entry of a built-in pattern
    std::string sha256; ///< hex SHA-256 of an uploaded pattern's bytes ("" for built-ins)
};

/// An uploaded environment (service_environments.cpp): the file is decoded when a frame needs
/// it (State::environmentImage), not kept decoded per entry.
struct EnvironmentEntry {
    std::string id, name;
    std::string file; ///< absolute path of the stored .hdr / .exr
    bool builtin = false;
    std::size_t bytes = 0;
    int width = 0, height = 0;
};

/// Content a batch names by address ("sha256:<hex>", SPEC §7), resolved for one request: from
/// its inline parts, the content cache or stored uploads. Keys are the addresses; holding the
/// pointers keeps the content alive for the request even if the cache lets it go.
struct ContentOverlay {
    std::map<std::string, std::shared_ptr<const Model>> models;
    /// The derived data of `models` (by the same address), where the content cache or a stored
    /// upload keeps one: snapshots of the model share it instead of baking their own.
    std::map<std::string, std::shared_ptr<const ModelDerived>> derived;
    PatternImages images;
    /// Environments (`render.environment` "sha256:<hex>"), decoded.
    std::map<std::string, std::shared_ptr<const EnvironmentImage>> environments;
    bool empty() const { return models.empty() && images.empty() && environments.empty(); }
};

/// "sha256:" followed by 64 lower-case hex digits.
bool isContentAddress(const std::string& s);

/// An uploaded model's bytes decoded and checked against `limits` (.glb, or a .gltf whose
/// buffers and images are data: URIs — no file is read); errors name `where` and `field`.
Result<Model> decodeModelBytes(const std::vector<std::uint8_t>& bytes, const ServerLimits& limits,
                               const char* where, const std::string& field);
/// An uploaded pattern image decoded and checked against `limits` (sides from the header of a
/// PNG or JPEG before anything is decoded).
/// The decode's memory is reserved in `budget` first (when given): the declared w·h·8 bytes for
/// PNG and JPEG, the worst case maxImageSide²·8 for other formats (whose sides the decoder
/// checks from its spec before any pixel); Unavailable when the budget has no room within 2 s.
Result<HeightImage> decodePatternBytes(const std::vector<std::uint8_t>& bytes, const ServerLimits& limits,
                                       const char* where, const std::string& field,
                                       DecodeBudget* budget = nullptr);
/// An environment's bytes (a Radiance .hdr or an OpenEXR, recognised by their signature)
/// decoded through a temporary file in data folder `dataDir`'s environments/ (the image module
/// reads files; the name carries the temp marker, which Store::open sweeps should the process die
/// there), sides within `maxSide`. Parse with `field` for bytes that are neither format or do not
/// decode; messages show `dataDir` as <data>.
Result<EnvironmentImage> decodeEnvironmentBytes(const std::vector<std::uint8_t>& bytes, const std::string& dataDir,
                                                int maxSide, const std::string& field);

/// One revision of a scene as it was validated: its canonical document and its scene (shared,
/// immutable: readers keep them after the lock is released).
struct SceneVersion {
    std::uint64_t revision = 0;
    std::shared_ptr<const json> doc;    ///< canonical document (toJson of scene)
    std::shared_ptr<const Scene> scene; ///< unresolved (aliases kept), as parsed
};

/// How many recent revisions of a scene stay in memory (SceneEntry::recent): what an If-Match
/// a few edits behind is rebased against, and what a frame of a recent revision renders without
/// parsing its document again. Older revisions are read from the store's history.
inline constexpr std::size_t kRecentRevisions = 16;

struct SceneEntry {
    std::shared_ptr<const json> doc;    ///< canonical document of the current revision
    std::shared_ptr<const Scene> scene; ///< the current revision's scene
    std::uint64_t revision = 1;
    std::vector<Store::RevisionInfo> history; ///< kept revisions, oldest first (last = current)
    /// Revisions below it were dropped by the history retention (0: none were): read, revert and
    /// frames of them answer Gone (keptRevision).
    std::uint64_t droppedBefore = 0;
    /// The last kRecentRevisions revisions, oldest first; back() is the current one (the same
    /// pointers as doc and scene). Revisions loaded from the data folder start with the current.
    std::deque<SceneVersion> recent;

    /// Makes `v` current and keeps it among the recent ones (the oldest beyond the window go).
    void setCurrent(SceneVersion v);
    /// Revision `revision` if it is among the recent ones, else nullptr.
    const SceneVersion* recentVersion(std::uint64_t revision) const;
};

/// What an edit touches, for rebasing an If-Match on an older revision (SPEC §6 Concurrency; see
/// Service::State::checkIfMatch).
struct EditScope {
    enum class Kind {
        Whole,     ///< the whole document (PUT scene, revert, delete scene): never rebased
        Placement, ///< one placement (PATCH, DELETE, mirror of `placement`)
        Add,       ///< a new placement; `placement` its given id ("" = one will be generated)
        Order,     ///< the order of the placements
        Pose,      ///< the pose (PUT, PATCH)
    };
    Kind kind = Kind::Whole;
    std::string placement;
};

/// What an edit is, for the history and the events.
struct EditInfo {
    const char* type = "";  ///< event type: "created", "placement_updated", …
    std::string op;         ///< history op: "patch placement elbow_l", …
    std::string placement;  ///< the placement it concerns ("" = none)
};

/// Gone when revision `revision` of scene `id` (entry `e`) was dropped by the history retention
/// (`flag`: the --history-keep in force, "" when none is), naming the oldest kept revision;
/// Ok otherwise (whether the revision exists is not checked here). Caller holds the state's mutex.
Status keptRevision(const std::string& id, const SceneEntry& e, std::uint64_t revision,
                    const std::string& flag);

/// One person's presence on a scene.
struct PresenceEntry {
    json selection = json::array();
    std::string color;
    double expires = 0.0; ///< nowSeconds() at which it lapses
    std::string address;  ///< the peer address that posted it ("" when not known)
};

/// The glTF loader's limits (checked from declared sizes, before allocating) for a server's
/// limits: its triangle and joint limits; base-colour textures downscaled to maxImageSide, the
/// textures' decoded bytes at most 4 × maxImageSide² × 4 (four full-size RGBA8 textures).
GltfLimits gltfLimitsOf(const ServerLimits& limits);

/// The outline members of a placement's outline answer (SPEC §8; numbers rounded to 1e-5):
/// {pieces, bounds, segments, truncated, anchor_uv} (service_inspect.cpp).
json outlineMembers(const SurfaceOutline& outline);

/// Index of placement `pid` in doc["placements"], or −1.
int placementIndex(const json& doc, const std::string& pid);
/// `base`, or `base` + "_2", "_3"… : the first that no placement of `doc` has.
std::string uniquePlacementId(const json& doc, const std::string& base);

Error bad(const std::string& field, const std::string& what);
Error notFound(const std::string& field, const std::string& what);

/// The one rule of a placement edit (PATCH placement, and a frame's `preview`): `patch` is a JSON
/// object, it does not change the placement's id, placement `pid` exists in `doc` (scene
/// `sceneId`); then `patch` is merged into it (RFC 7386). Fails with the edit's fields: "" (not an
/// object), "/id" (id changed), 404 "pid" (no such placement); `doc` is untouched then.
Status mergePlacementPatch(json& doc, const std::string& sceneId, const std::string& pid, const json& patch);
/// The part of that rule that needs no document: the object and id checks.
Status checkPlacementPatch(const std::string& pid, const json& patch);
Error queueFull();
double nowSeconds();
/// Hands the heap's free pages back to the system (glibc: malloc_trim): after a delete, so that
/// the decode buffers of large uploads, kept by the allocator for reuse, do not stay resident.
void returnFreedMemory();
/// Buffers of 4 MB and more are mapped and unmapped, never kept in the heap (glibc: mallopt
/// M_MMAP_THRESHOLD, process-wide; called when a service opens).
void keepLargeBuffersMapped();
/// [A-Za-z0-9_. -] only, at most 64 characters.
std::string sanitizeName(const std::string& name);

/// A store failure as an answer may show it (issue #12.9): the data folder `dataDir` replaced by
/// "<data>" in the message and field, so that no answer reveals a path of the server.
Error withoutDataPath(Error e, const std::string& dataDir);

/// An error in a render setting a frame parameter overrode names the parameter ("width"), not
/// the document field ("/render/size/0").
Error asParamError(Error e, const FrameParams& p);

/// Counts renders waiting for or using the renderer; refuses beyond the queue length.
class QueueSlot {
public:
    QueueSlot(std::atomic<int>& n, int limit) : n_(n) { ok_ = n_.fetch_add(1) < limit; }
    ~QueueSlot() { n_.fetch_sub(1); }
    QueueSlot(const QueueSlot&) = delete;
    QueueSlot& operator=(const QueueSlot&) = delete;
    bool ok() const { return ok_; }

private:
    std::atomic<int>& n_;
    bool ok_ = false;
};

} // namespace detail

/// The service's cache of height-map layouts in `folder` (<data>/cache/layouts), generating with
/// core generateTextureLayout at its default options (service_layout.cpp).
std::unique_ptr<LayoutCache> makeLayoutCache(const std::string& folder);

struct Service::State {
    std::optional<Store> store;
    std::unique_ptr<DecodeBudget> decodeBudget; ///< pattern decodes in flight (limits.decodeBudgetBytes)
    std::unique_ptr<FrameRenderer> renderer;
    std::string contentDir;
    PatternManifest manifest;
    json defaultSceneDoc; ///< the default pattern set (null when not installed)
    ServerLimits limits;

    std::mutex writeMutex;
    mutable std::shared_mutex mutex;
    std::map<std::string, detail::ModelEntry> models;
    std::map<std::string, detail::PatternEntry> patterns;
    std::map<std::string, detail::EnvironmentEntry> environments; ///< uploads, by id
    /// The one environment kept decoded (id, image): the last a frame or an upload used. An
    /// equirectangular float image is large (a 4096 × 2048 one is 100 MB), and an editor session
    /// frames one environment at a time; the renderer keeps its prefiltered light while this
    /// image lives (RendererOptions: the custom light is kept while its owner lives).
    mutable std::mutex environmentCacheMutex;
    mutable std::pair<std::string, std::shared_ptr<const EnvironmentImage>> environmentCache;
    /// The image `render.environment` names: null for the studio (empty or builtin:studio),
    /// the cached or freshly decoded upload otherwise. Takes `mutex` shared, then the cache's.
    /// Fails: NotFound ("/render/environment") for an unknown id; the decoder's error.
    Result<std::shared_ptr<const EnvironmentImage>> environmentImage(const std::string& id) const;
    PatternImages images; ///< by pattern id, built-in and uploaded
    std::map<std::string, detail::SceneEntry> scenes;

    std::mutex subsMutex;
    std::multimap<std::string, std::shared_ptr<Subscription>> subs;

    std::atomic<int> inFlight{0};
    std::unique_ptr<ContentCache> content; ///< by address; its own lock (no order with the others)
    std::unique_ptr<LayoutCache> layouts;  ///< height-map layouts per model; its own lock

    /// The height-map layout `mode` names for the model of `derived` (SPEC §8; service_layout.cpp,
    /// the one place it is chosen): the model's own UVs (ModelDerived::modelLayout) for Model, the
    /// generated layout (`layouts`) for Generated, and for Auto the model's UVs when the UV
    /// diagnosis finds them usable (present, overlap < 0.5 % of used texels), else generated.
    /// Needs no lock. Fails for Model on a model without UVs (InvalidArgument, field `field`)
    /// and as the generator does.
    Result<std::shared_ptr<const TextureLayout>> layoutOf(const ModelDerived& derived, UvLayoutMode mode,
                                                          const std::string& field) const;

    /// The scene a document describes, validated against this server's models and patterns.
    struct Prepared {
        Scene scene;
        json canonical;
        std::shared_ptr<const Model> model;
    };
    /// Caller holds `mutex` (shared is enough). Without `withLimits` only the document and its
    /// references are checked, not this server's configured limits (the default pattern set).
    /// `overlay` (batches only) lets the model, pattern values, placement patterns and the base
    /// name content addresses it holds; stored scenes never do (the cache may forget).
    Result<Prepared> prepare(const json& doc, bool withLimits = true,
                             const detail::ContentOverlay* overlay = nullptr) const;
    /// Placement patterns with their aliases replaced by pattern ids.
    Scene resolved(const Scene& scene) const;

    /// What a render needs, copied under a shared lock so that it runs unlocked.
    struct Snapshot {
        Scene scene; ///< resolved
        std::shared_ptr<const Model> model;
        PatternImages images; ///< the ones the scene uses
        std::shared_ptr<const PatternImage> base;
        /// The model's derived data (its model entry's, or a fresh one for a model that is not
        /// listed: a batch's content-addressed model); null when made elsewhere (derivedOf
        /// finds it then).
        std::shared_ptr<const ModelDerived> derived;
        /// A batch's environment named by content address (from its overlay); null: the one
        /// `scene.render.environment` names (environmentImage).
        std::shared_ptr<const EnvironmentImage> environment;
    };
    Result<Snapshot> snapshot(const std::string& id) const;
    /// The derived data of `snap`'s model (service_inspect.cpp): the one its model entry keeps,
    /// made on the first call (what it computes is built on use, unlocked). A model that is not
    /// (or no longer) the entry's — deleted since the snapshot — gets a fresh, uncached one.
    /// Takes `mutex` shared itself (caller holds none). Never fails.
    std::shared_ptr<const ModelDerived> derivedOf(const Snapshot& snap) const;
    /// The derived data of `snap`'s model in the texture space its scene's height maps live in
    /// (service_layout.cpp): derivedOf(snap) when that is the model's own UVs (or the layout
    /// cannot be had: the tools then say what is missing), else its throughLayout(the layout) —
    /// what pick by UV, focus, mirror and lint look UVs up in.
    std::shared_ptr<const ModelDerived> derivedInLayout(const Snapshot& snap) const;
    /// The height-map layout `scene` uses on the model of `derived` (SPEC §8 uv_layout):
    /// layoutOf(derived, scene.uvLayout, "/uv_layout").
    Result<std::shared_ptr<const TextureLayout>> layoutFor(const Scene& scene, const ModelDerived& derived) const;
    /// `o` given the layout of `scene` (layoutFor) and, when an enabled surface placement needs
    /// one, the rest-surface map at the scene's height-map size from `derived`'s cache. Fails
    /// like layoutFor.
    Status withLayout(const Scene& scene, const ModelDerived& derived, FrameOverrides& o) const;
    /// Same for a document that is not stored (batch); caller holds `mutex` shared.
    Snapshot snapshotOf(const Scene& scene, std::shared_ptr<const Model> model,
                        const detail::ContentOverlay* overlay = nullptr) const;

    /// The content addresses batch document `doc` names, resolved (service_content.cpp):
    /// `inlineParts` (address → bytes, from a multipart batch) are checked against their
    /// address, decoded by the role the document gives them and cached; the rest come from the
    /// cache or from uploads with that SHA-256. Takes `mutex` shared itself (caller holds none).
    /// Fails: MissingContent listing every address not found (field: the first one's pointer);
    /// InvalidArgument for a malformed address, bytes whose SHA-256 differs from their part's
    /// name, or one address used as both model and pattern; decode errors of the parts.
    Result<detail::ContentOverlay> resolveContent(
        const json& doc, const std::map<std::string, std::vector<std::uint8_t>>& inlineParts);

    /// Validates `newDoc`, writes it durably as a new revision (history included), swaps it in
    /// and announces it. Caller holds `writeMutex` (and not `mutex`).
    Result<json> commit(const std::string& id, const json& newDoc, const detail::EditInfo& info,
                        const EditContext& ctx, bool create);
    /// Drops scene `id`'s revisions beyond `retention` from its history (they answer Gone from
    /// here on) and compacts its files when Store::compactionDue says so. Caller holds
    /// `writeMutex` (and not `mutex`). A failed compaction changes nothing on disk and is tried
    /// again at the next edit; it never fails the edit that triggered it.
    void applyRetention(const std::string& id);
    /// Takes `writeMutex`, checks ctx.ifMatch against `scope` (checkIfMatch), copies scene `id`'s
    /// document, lets `change` modify the copy (it may also complete `info`), commits. `change`
    /// runs under `writeMutex` (not `mutex`): the scene stays as it read it until the commit.
    Result<json> edit(const std::string& id, const EditContext& ctx, detail::EditInfo& info,
                      const detail::EditScope& scope, const std::function<Status(json&)>& change);
    /// Whether an edit of `scope` based on revision ctx.ifMatch may apply to scene `id` now, at
    /// revision `current` with document `now` (SPEC §6 Concurrency): always without If-Match or
    /// when it names `current`; for an older revision N (rebase), when what the edit touches is
    /// the same in N as now and the model is the same — the placement (its JSON, or its absence)
    /// for Placement and for Add with a given id, the list of placement ids for Order, the pose
    /// for Pose; an Add without id always rebases; Whole never. N's document comes from the
    /// recent revisions or else the store. Caller holds `writeMutex`, not `mutex`. Fails:
    /// StaleRevision (Error::currentRevision set, the message saying what changed); NotFound
    /// when the scene does not exist.
    Status checkIfMatch(const std::string& id, const EditContext& ctx, const detail::EditScope& scope);
    /// Counts frames whose scene was parsed and validated again from a document (a revision not
    /// among the recent ones, a preview), as opposed to taken from a cached scene. For tests.
    mutable std::atomic<std::uint64_t> framesPrepared{0};
    /// Sends `event` to the scene's subscribers as an SSE message named `name`.
    void publish(const std::string& sceneId, const json& event, const char* name = "change");

    std::mutex presenceMutex;
    std::map<std::string, std::map<std::string, detail::PresenceEntry>> presence; ///< scene → client
    /// Drops lapsed presence entries of a scene, announcing each; the live ones as JSON.
    /// Caller holds presenceMutex.
    json livePresence(const std::string& sceneId);

    /// The snapshot a frame with `p` shows: the current document or p.revision's, with
    /// p.patternsOff / p.only applied to the placements' `enabled`.
    Result<Snapshot> frameSnapshot(const std::string& id, const FrameParams& p) const;
    /// Whether a scene validated earlier still renders as it did: its model and every pattern it
    /// names (through its aliases) are still here. Caller holds `mutex` (shared is enough).
    bool cachedRenders(const Scene& scene) const;
    /// `snap` with p.patternsOff / p.only applied to its placements' `enabled` (an unknown id in
    /// p.only: InvalidArgument, field "only").
    Result<Snapshot> withCompare(Snapshot snap, const std::string& id, const FrameParams& p) const;
    /// Plans and renders one frame of `snap` with `p`'s overrides and outlines (not encoded);
    /// `camera` (when given) receives the camera used: distance, target x, y, z; `antiAliasing`
    /// what render.aa resolved to (FrameResult::antiAliasing).
    Result<Image8> renderImage(const Snapshot& snap, const FrameParams& p,
                               std::optional<std::array<double, 4>>* camera = nullptr,
                               std::string* antiAliasing = nullptr);
    /// The frame plan of `snap` with `p`'s overrides (errors name the parameters).
    Result<FramePlan> plan(const Snapshot& snap, const FrameParams& p) const;
    /// Plans and renders one frame of `snap` with `p`'s overrides; encodes it.
    Result<EncodedImage> render(const Snapshot& snap, const FrameParams& p);

    /// Stores an accepted model through `write` (given the metadata record, under `writeMutex`)
    /// and then lists it; the model's summary. Nothing is listed when `write` fails.
    Result<json> addModelEntry(detail::ModelEntry e,
                               const std::function<Status(Store&, const json&)>& write);

    /// Loading at open: built-in content, then stored uploads and scenes (warnings collected).
    Status loadContent();
    void loadStored(std::vector<std::string>& warnings);
};

} // namespace dermis
