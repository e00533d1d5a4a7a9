// Dermis service — the server's state and operations, without HTTP: models, patterns and scene
// documents (persisted through Store), edits, renders through one injected FrameRenderer, live
// change events. The HTTP layer (server/http/api.cpp) maps requests to these calls and their
// errors to statuses in one place; tests drive it directly (ServiceTest, with a CPU fake
// renderer).
//
// Threads: every method may be called from any thread. Mutations (edits, uploads, deletes) are
// serialised by one writer lock and hold it while they validate the whole new state, write it
// durably and swap it in, so a failed edit changes nothing and an acknowledged one survives a
// crash. Readers and renders take a shared lock only to copy what they need (documents, the
// model, the pattern images they use: shared, immutable): no reader waits for a render or for
// a disk write, and a render never blocks an upload. GL work goes to the renderer's thread; at
// most `limits.queueLength` renders wait for it, more are refused with ErrorCode::Unavailable
// (503 + Retry-After).
//
// Files: service.cpp (open, info), service_models.cpp, service_patterns.cpp,
// service_scenes.cpp (documents and edits), service_history.cpp (revisions, revert, presence),
// service_inspect.cpp (pick, outline, probe, activation, lint), service_sweep.cpp (sweeps),
// service_renders.cpp (frames, maps, batch), service_view.cpp (focus, turntable),
// service_events.cpp; shared private state in
// service_state.hpp.
//
// Documents that arrive here name models and patterns only by generated ids ("m_…", "p_…") or
// built-in names ("builtin:default", "crease"); never by path.
#pragma once

#include "core/result.hpp"
#include "core/scene.hpp"
#include "gl/renderer.hpp"
#include "service/store.hpp"

#include <nlohmann/json.hpp>

#include <array>
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <shared_mutex>
#include <string>
#include <vector>

namespace dermis {

/// Configurable limits, reported by GET /info.
struct ServerLimits {
    std::size_t maxUploadBytes = 64u << 20; ///< model and pattern uploads, request bodies
    int maxImageSide = 4096;                ///< uploaded pattern images
    int maxMapSide = 4096;                  ///< heightmap.size
    int maxRenderSide = 4096;               ///< frame width/height
    std::size_t maxTriangles = 1000000;
    std::size_t maxJoints = 1024;
    std::size_t maxPlacements = 256;
    int queueLength = 16;          ///< renders waiting for the GL thread
    int requestTimeoutSeconds = 30;
    std::size_t maxBatchFrames = 512;
    /// Decoded models and patterns that batches sent inline, kept by content address (LRU).
    std::size_t contentCacheBytes = 256u << 20;
    /// Memory of pattern decodes in flight (uploads and batch parts), estimated before each
    /// decode (DecodeBudget): a decode that does not fit waits up to 2 s, then Unavailable.
    std::size_t decodeBudgetBytes = 512u << 20;
    double presenceSeconds = 30.0; ///< a presence entry lapses this long after its last refresh
    /// How much of each scene's history is kept (`serve --history-keep`; default all): older
    /// revisions answer Gone and their files are compacted away (Store::dropRevisionsBefore).
    HistoryRetention historyKeep;
    nlohmann::json toJson() const;
};

/// An encoded image answer.
struct EncodedImage {
    std::vector<std::uint8_t> bytes;
    std::string contentType;
    std::string backend; ///< which GL backend rendered it ("" for CPU-only answers)
    std::string antiAliasing = {}; ///< frames: what render.aa resolved to ("post", "msaa4", "none"; header X-Dermis-AA)
    std::int64_t changedPixels = -1; ///< frame-diff only: pixels that differ (−1: not a diff)
    /// Frames: the camera the renderer used, "auto" distance and target resolved: distance,
    /// target x, y, z (headers X-Dermis-Camera-Distance / -Target). Absent for other images.
    std::optional<std::array<double, 4>> camera = std::nullopt;
};

/// One file of a multi-file upload.
struct UploadFile {
    std::string name; ///< plain file name, as the .gltf's URIs name it
    std::vector<std::uint8_t> bytes;
};

/// The frame formats of the frame route and batches: "png", "jpeg" (quality 90, for previews)
/// and "webp" (lossless, Content-Type image/webp).
inline bool isFrameFormat(const std::string& f) { return f == "png" || f == "jpeg" || f == "webp"; }

/// A revision number as text: 1 to 18 decimal digits, ≥ 1 (no sign, point or exponent); nothing
/// otherwise. The one parse of a revision number (query parameters, frame-diff's `against`).
std::optional<std::uint64_t> parseRevisionNumber(const std::string& text);

/// Query parameters of a frame.
struct FrameParams {
    std::string format = "png"; ///< png | jpeg | webp (lossless); see isFrameFormat
    std::optional<int> width, height, msaa;
    std::optional<AntiAliasing> aa; ///< `aa`; see FrameOverrides for how it meets `msaa`
    std::optional<Shading> shading;         ///< `shading`: legacy | pbr (render.shading)
    std::optional<double> exposure;         ///< `exposure` (render.exposure)
    std::optional<ToneMapping> toneMapping; ///< `tone_mapping` (render.tone_mapping)
    /// `key_light`: on — the scene's render.key_light, or the default light (shadowed) when it
    /// has none; off — none. Absent: the scene's.
    std::optional<bool> keyLight;
    std::optional<double> yaw, pitch, distance, time;
    std::optional<std::array<double, 3>> target; ///< the camera's target (core Camera::target)
    // Outlines on the skin (the editor's selection, hover and place brush; nothing when empty:
    // the frame is byte for byte the one without them). Unknown ids fail (field "highlight" /
    // "hover").
    std::vector<std::string> highlight; ///< placements outlined as selected (≤ kMaxHighlights)
    std::string hover;                  ///< a placement outlined as hovered ("" = none)
    /// A brush footprint outlined at UV centre (u, v), size (su, sv), rotation (degrees).
    std::optional<std::array<double, 5>> brush;
    /// A surface brush (SPEC §8) outlined as a circle on the rest surface: anchor position x, y, z
    /// (bind space), normal x, y, z, diameter (model units) — the decal the 3D view's place tool
    /// would add.
    std::optional<std::array<double, 7>> surfaceBrush;
    // Compare (SPEC §6): which version of the scene the frame shows.
    bool patternsOff = false;          ///< no dynamic patterns (every placement disabled)
    std::vector<std::string> only;     ///< solo: only these placements (others disabled)
    std::optional<std::uint64_t> revision; ///< the document as it was at this revision
    FrameView view = FrameView::Shaded;    ///< shaded, or an unlit view of the maps
    /// Preview: placement id → a JSON merge patch applied to that placement for this frame only
    /// (nothing is stored, no revision is made) — the editor's frames while a drag runs. Empty:
    /// none. Unknown ids and patches that make the document invalid fail (field "preview").
    nlohmann::json preview = nlohmann::json::object();
};

/// Query parameters of a sweep (SPEC §6 Sweep). `frame` carries the camera, msaa, time and what
/// to compare exactly as a frame's (its width/height are not used: each cell is size × size).
struct SweepParams {
    std::string placement;    ///< the placement whose joint is swept, or whose t labels a clip sweep
    std::string clip;         ///< sweep this clip's time instead of a joint ("" = a joint sweep)
    int steps = 8;            ///< 2..kMaxSweepCells for a sheet, 2..kMaxSweepSteps (1000) for JSON
    int size = 128;           ///< each cell's side in pixels
    FrameParams frame;
};

/// Most cells of one contact sheet.
inline constexpr int kMaxSweepCells = 64;

/// Most placements one frame outlines as selected (FrameParams::highlight).
inline constexpr std::size_t kMaxHighlights = 6;

/// Query parameters of a turntable (range-of-motion preview): `frames` frames of `size` × `size`
/// pixels in which the placement's driver joint goes θmin → θmax → θmin while the camera's yaw
/// turns once (starting at `frame`'s yaw); `frame` carries camera, time, msaa, view, compare and
/// outlines as for a frame. `fps` sets the WebP's frame delay.
struct TurntableParams {
    std::string placement;
    int frames = 36;  ///< kMinTurntableFrames..kMaxTurntableFrames
    int size = 256;   ///< kMinTurntableSize..kMaxTurntableSize
    double fps = 12;  ///< 1..50
    FrameParams frame;
};
inline constexpr int kMinTurntableFrames = 4, kMaxTurntableFrames = 120;
inline constexpr int kMinTurntableSize = 64, kMaxTurntableSize = 512;

/// A server-sent-events subscription to one scene: events (whole SSE messages) queue up until
/// taken. A reader that falls kMaxQueued events behind loses them: the queue is replaced by one
/// `resync` event ({"type": "resync", "scene"}) telling it to read the scene again, and nothing
/// more is queued until it has taken that event, so a stalled reader costs bounded memory.
/// A live change event of a scene, typed: its name ("hello", "change", "presence", "resync") and
/// its JSON data (as text: serialized once for every subscriber). The HTTP layer frames it as a
/// server-sent event; the service knows no wire format.
struct SceneEvent {
    std::string name;
    std::string data;
};

class Subscription {
public:
    static constexpr std::size_t kMaxQueued = 1000;

    explicit Subscription(std::string sceneId = "");
    /// Waits up to `timeoutMs` for an event; nullopt on timeout or when closed.
    std::optional<SceneEvent> next(int timeoutMs);
    void push(SceneEvent event);
    void close();
    bool closed() const;

private:
    mutable std::mutex mutex_;
    std::condition_variable cv_;
    std::deque<SceneEvent> events_;
    std::string sceneId_;
    bool closed_ = false;
    bool resyncQueued_ = false;
};

/// Who makes an edit and which revision it was based on (SPEC §6 Concurrency).
struct EditContext {
    /// The revision the client read (If-Match: "r<N>"). When set and older than the scene's
    /// current revision, an edit of one placement, of the pose or of the order applies only when
    /// that is the same in N as now (and a new placement unless its given id came or went since
    /// N): the server rebases it; otherwise, and always for whole-document edits (PUT, revert,
    /// delete), it fails with ErrorCode::StaleRevision (Error::currentRevision set) and nothing
    /// changes. Unset: the edit applies to whatever is current.
    std::optional<std::uint64_t> ifMatch;
    /// X-Dermis-Client: recorded in the history and carried by events. ≤ 64 printable ASCII
    /// characters ("" = not named); checked by the HTTP layer (checkClientName).
    std::string client;
};

/// Empty when `name` may name a client (≤ 64 characters, printable ASCII), else why not.
std::string checkClientName(const std::string& name);

/// Where a service keeps things and how far it goes.
struct ServiceConfig {
    std::string dataDir;    ///< uploads and scenes, written durably (`serve --data`)
    std::string contentDir; ///< built-in content, read only (`serve --content`; dermisContentDir())
    ServerLimits limits;
};

class Service {
public:
    /// Loads the built-in content (pattern library, default character, default pattern set),
    /// then opens the data directory (every stored model, pattern and scene; unreadable ones are
    /// skipped and listed in warnings()). Renders go to `renderer` (owned). Fails when the content
    /// is missing or corrupt — including a default.scene.json that exists but cannot be read,
    /// parsed or validated (named in the message) — or the data directory cannot be written.
    static Result<std::unique_ptr<Service>> open(const ServiceConfig& config,
                                                 std::unique_ptr<FrameRenderer> renderer);
    /// Same with the GL renderer on `backend` and the content in dermisContentDir().
    static Result<std::unique_ptr<Service>> open(const std::string& dataDir, GlBackend backend,
                                                 const ServerLimits& limits);
    ~Service();

    const ServerLimits& limits() const { return limits_; }
    const std::vector<std::string>& warnings() const { return warnings_; }
    nlohmann::json info() const;

    // --- models
    nlohmann::json listModels() const;
    /// Uploads are content-addressed: the id is "m_" + the first 16 hex digits of the SHA-256 of
    /// the bytes (contentModelId), and bytes uploaded before answer the existing model's summary
    /// unchanged (its first name kept) with `*existing` set to true (when given) instead of
    /// storing a copy. Models stored with random ids by earlier versions keep those ids.
    Result<nlohmann::json> addModel(const std::vector<std::uint8_t>& glb, const std::string& name,
                                    bool* existing = nullptr);
    /// A .gltf (`gltfName`, one of `files`) with its external buffers and images as the other
    /// files. File names must be plain ([A-Za-z0-9._ -]); the loader reads only these files.
    /// Content-addressed like addModel over the files (names and bytes, contentModelId).
    Result<nlohmann::json> addModelFiles(const std::vector<UploadFile>& files,
                                         const std::string& gltfName, const std::string& name,
                                         bool* existing = nullptr);
    Result<nlohmann::json> getModel(const std::string& id) const;
    /// The summary of model `id` when it is loaded (as listModels has it), else nullopt.
    std::optional<nlohmann::json> storedModel(const std::string& id) const;
    Status deleteModel(const std::string& id);
    /// The wireframe (core uvEdges) of the height-map layout `mode` names (SPEC §8; auto: the one a
    /// scene with `uv_layout: auto` uses): {"id", "layout": "model"|"generated", "edge_count",
    /// "edges": [u0,v0,u1,v1, …], "convention"} (json), or a size×size PNG (rasterizeUvEdges).
    /// `model` on a model without UVs: InvalidArgument, field "layout".
    Result<nlohmann::json> uvLayout(const std::string& id, UvLayoutMode mode = UvLayoutMode::Auto) const;
    Result<EncodedImage> uvLayoutPng(const std::string& id, int size,
                                     UvLayoutMode mode = UvLayoutMode::Auto) const;
    /// The model's base-colour texture as PNG, for the editor to draw the UV layout over: the
    /// image covering the most triangles (Model::dominantBaseColorImage), as decoded (RGBA8;
    /// alpha kept only when some pixel is not opaque), fitted into maxSide × maxSide with its
    /// aspect kept when `maxSide` is given (core downsizeImage: box filter, never enlarged).
    /// Fails: maxSide outside [16, 4096] (InvalidArgument, "size"), an unknown model (NotFound,
    /// "id"), a model without a base-colour texture (NotFound, "texture").
    Result<EncodedImage> modelTexture(const std::string& id, std::optional<int> maxSide) const;

    // --- patterns
    nlohmann::json listPatterns() const;
    /// Content-addressed like addModel: "p_" + 16 hex digits of the SHA-256 of the bytes; the same
    /// bytes again answer the existing pattern with `*existing` set.
    Result<nlohmann::json> addPattern(const std::vector<std::uint8_t>& bytes, const std::string& name,
                                      bool* existing = nullptr);
    /// A grey PNG preview whose longer side is `size` pixels, the aspect kept (core heightPreview).
    /// Fails: size outside [1, 2048] (InvalidArgument, "size"), an unknown pattern (NotFound, "id").
    Result<EncodedImage> patternImage(const std::string& id, int size) const;
    /// Fails: Conflict while a built-in, or named by a scene's heightmap base or placement (an alias
    /// no placement names is dropped when a document is prepared, so it never holds a pattern).
    Status deletePattern(const std::string& id);

    // --- environments (image-based light of pbr and skin frames: `render.environment`)
    /// {"environments": [{"id", "name", "builtin"[, "width", "height", "bytes"]}]}: the built-in
    /// studio ("builtin:studio") first, then every upload.
    nlohmann::json listEnvironments() const;
    /// Stores a Radiance .hdr or OpenEXR image of linear radiance (equirectangular, core/
    /// environment.hpp), content-addressed: "e_" + 16 hex digits of the SHA-256 of the bytes; the
    /// same bytes again answer the stored one with `*existing` set. Decoded once to check it
    /// (and kept as the one decoded environment in memory). Fails: past maxUploadBytes
    /// (TooLarge, "body"); neither format by its signature, or not decodable (Parse, "body");
    /// a side over maxImageSide (TooLarge); negative or non-finite radiance (InvalidArgument);
    /// no image module (Unavailable).
    Result<nlohmann::json> addEnvironment(const std::vector<std::uint8_t>& bytes, const std::string& name,
                                          bool* existing = nullptr);
    /// Fails: NotFound for an unknown id; Conflict for the built-in or one a scene names.
    Status deleteEnvironment(const std::string& id);

    // --- scenes (every answer is {"id", "revision", "scene"})
    // Every edit makes revision n+1 and keeps it (history), durably, with `ctx.client` and an op
    // such as "patch placement elbow_l"; events carry {type, scene, revision, client, op,
    // placement}. With `ctx.ifMatch` set to another revision than the current one, an edit
    // fails with ErrorCode::StaleRevision and changes nothing.
    nlohmann::json listScenes() const;
    /// `body` is a scene document, or {"model": …, "default_patterns": true} to start from the
    /// default pattern set (only on builtin:default).
    Result<nlohmann::json> createScene(const nlohmann::json& body, const EditContext& ctx = {});
    Result<nlohmann::json> getScene(const std::string& id) const;
    Result<nlohmann::json> replaceScene(const std::string& id, const nlohmann::json& doc,
                                        const EditContext& ctx = {});
    Status deleteScene(const std::string& id, const EditContext& ctx = {});
    Result<nlohmann::json> addPlacement(const std::string& id, const nlohmann::json& placement,
                                        const EditContext& ctx = {});
    Result<nlohmann::json> patchPlacement(const std::string& id, const std::string& pid,
                                          const nlohmann::json& patch, const EditContext& ctx = {});
    Result<nlohmann::json> deletePlacement(const std::string& id, const std::string& pid,
                                           const EditContext& ctx = {});
    /// Adds the mirror twin of placement `pid` (SPEC §6 Mirror; core mirrorPlacement): id from
    /// core mirrorPlacementId (elbow_l → elbow_r, else the twin joint's side or "_twin"), made
    /// unique ("_2"…), label from mirrorLabel. Computed under the writer lock from the current
    /// document. Fails: InvalidArgument when the footprint centre is on no chart or the joint
    /// has no twin by name or position; Conflict (field "placement", the message naming it) when
    /// the twin is in the scene already (core findMirrorTwin) or `pid` is its own twin — unless
    /// `update`: then that twin is replaced by the new mirror image in place (its id and place
    /// in the order kept; event placement_updated, op "mirror placement <pid> onto <twin>").
    Result<nlohmann::json> mirrorPlacement(const std::string& id, const std::string& pid,
                                           const EditContext& ctx = {}, bool update = false);
    /// A full pattern set for the scene's character (SPEC §8 proposals; core proposePatterns,
    /// cached per model): {id, proposals: [{placement (canonical, surface), kind ("crease" |
    /// "bone" | "bulge"), joint, score, twin (the twin proposal's id, or null), existing (the
    /// scene's placement that already is this proposal, or null), why: {joint, role, axis,
    /// neutral, peak, peak_clip, peak_time, synthetic, planarity, compression, stretch,
    /// correlation, radius}, outline (in the layout the scene's maps live in, as the outline
    /// route answers it — layout, pieces, bounds, segments (≤ 4000), truncated, anchor_uv — or
    /// null: the texture view's ghosts)}], applied: []}. With `apply`, the proposals not in the scene yet
    /// are added in one revision (op "propose"; ids made unique, twins renamed with them) and
    /// the answer is the edit's ({id, revision, scene}) plus `applied` (the new ids) and
    /// `proposals`. Fails: NotFound (scene); Conflict ("placements") when every proposal is in
    /// the scene already; like any edit (If-Match: a whole-document edit, never rebased).
    Result<nlohmann::json> propose(const std::string& id, bool apply, const EditContext& ctx = {});
    /// Another scene's placements carried onto this scene's character (SPEC §8 transfer; core
    /// transferPlacements): `body` = {"from": scene id, "joint_map": {source joint: this
    /// character's joint}?}. Answers {id, from, transferred: [{from (source id), placement
    /// (canonical, surface)}], unmapped: [{placement, field, reason}], joints: {source: target}};
    /// with `apply` the transferred placements are added in one revision (op "transfer from
    /// <scene>"; ids made unique) and the answer is the edit's ({id, revision, scene}) plus
    /// those members. Fails: InvalidArgument for a malformed body ("/from", "/joint_map",
    /// unknown members) or when nothing could follow (with apply); NotFound ("/from") for an
    /// unknown source scene; like any edit.
    Result<nlohmann::json> transfer(const std::string& id, const nlohmann::json& body, bool apply,
                                    const EditContext& ctx = {});
    /// `order`: every placement id once, in the new order.
    Result<nlohmann::json> reorderPlacements(const std::string& id, const nlohmann::json& order,
                                             const EditContext& ctx = {});
    Result<nlohmann::json> putPose(const std::string& id, const nlohmann::json& pose,
                                   const EditContext& ctx = {});
    /// Merges: "animation"/"time" replace, "joints" entries replace per joint (null removes).
    Result<nlohmann::json> patchPose(const std::string& id, const nlohmann::json& patch,
                                     const EditContext& ctx = {});

    // --- history (SPEC §6 History; service_history.cpp)
    /// {"id", "revision" (current), "revisions": [{revision, time (RFC 3339, UTC), op, client}]},
    /// newest first: at most `limit` (1..1000) revisions below `before` (all when unset).
    Result<nlohmann::json> listRevisions(const std::string& id, std::size_t limit,
                                         std::optional<std::uint64_t> before) const;
    /// {"id", "revision": N, "current_revision", "scene"}: the document as it was at revision N.
    /// NotFound for a revision the scene never had (or never kept); Gone for one the history
    /// retention dropped (limits.historyKeep).
    Result<nlohmann::json> getSceneRevision(const std::string& id, std::uint64_t revision) const;
    /// The same answer as JSON text (what GET ?revision=N sends): a revision read from the
    /// history is put together from the stored text, never parsed whole (Store::readRevisionText).
    Result<std::string> getSceneRevisionText(const std::string& id, std::uint64_t revision) const;
    /// A new revision whose document equals revision N's (undo and redo are reverts). Fails
    /// (NotFound, field "revision") for a revision the scene does not keep, and like any edit
    /// when N's document no longer validates (a model or pattern it used was deleted).
    Result<nlohmann::json> revert(const std::string& id, std::uint64_t revision,
                                  const EditContext& ctx = {});
    /// Presence (what each person has selected): `body` = {client, selection: [pid…] (≤ 256),
    /// color}; broadcast as a `presence` event and listed until limits.presenceSeconds (30 s)
    /// after the last refresh; the next presence call on the scene after that announces
    /// {"type": "presence", "client", "selection": [], "left": true}.
    /// Answers {"scene", "presence": [{client, selection, color, expires_in}]}.
    /// Bounded (issue #27): at most kMaxPresencePerAddress live entries per scene from one peer
    /// `address` (a new name from an address at its cap replaces that address's entry nearest to
    /// lapsing) and kMaxPresencePerScene per scene (past it a new name is refused: Unavailable),
    /// so a scene's presence answer stays under ~1 MB.
    Result<nlohmann::json> postPresence(const std::string& id, const nlohmann::json& body,
                                        const std::string& address = "");
    static constexpr std::size_t kMaxPresencePerScene = 64;
    static constexpr std::size_t kMaxPresencePerAddress = 16;
    Result<nlohmann::json> listPresence(const std::string& id);

    // --- inspection (CPU only; service_inspect.cpp)
    /// Pixel (x, y) of the frame `params` render (SPEC §6 Pick; format/msaa ignored) → {hit:
    /// false} or {hit: true, uv, position, part, triangle, joints: [{name, weight}] (top 4),
    /// suggested: {joint, axis, theta_min, theta_max}} (core pickFrame, suggestDriver). Fails
    /// on a pixel outside the frame (field "x"/"y") and like frame() on bad parameters.
    Result<nlohmann::json> pick(const std::string& id, const FrameParams& params, double x, double y);
    /// The same answer for texture point (u, v) (the texture view's pick; core pickUv): the rest
    /// mesh there, `position` in bind space. {hit: false} where no UV chart is; fails on u, v
    /// outside [0, 1] (field "u"/"v") and on a model without UVs (field "u").
    Result<nlohmann::json> pickUv(const std::string& id, double u, double v);
    /// The outline of placement `pid`'s footprint in the height-map layout the scene uses (SPEC
    /// §8; core surfaceFootprintOutline) for the texture view: {placement, projection ("uv" |
    /// "surface"), layout ("model" | "generated"), pieces (how many connected pieces the layout's
    /// seams cut it into), bounds ([u0, v0, u1, v1] per piece), segments ([u0, v0, u1, v1]: the
    /// border), truncated (more than kMaxOutlineSegments)}, numbers rounded to 1e-5; with `at`
    /// (a texture point u, v) also hit: whether it lies inside (core footprintContains). The
    /// document of `revision` when given. Fails: NotFound "id" (scene), "placement", "revision";
    /// InvalidArgument "u"/"v" outside [0, 1], "/uv_layout" when the layout cannot be had.
    Result<nlohmann::json> placementOutline(const std::string& id, const std::string& pid,
                                            std::optional<std::uint64_t> revision = std::nullopt,
                                            std::optional<std::array<double, 2>> at = std::nullopt);
    /// What drives each placement at the frame `params` describe (time, revision, camera):
    /// {scene, revision, time, camera: {yaw, pitch, distance} (the renderer's, "auto" resolved),
    /// placements: [{placement, joint, axis, theta, t, enabled}]} — θ in degrees (SPEC §2) and t
    /// = clamp((θ − θmin)/(θmax − θmin), 0, 1), for the editor's dial and sliders. Fails like
    /// frame() on bad parameters.
    Result<nlohmann::json> drivers(const std::string& id, const FrameParams& params);
    /// Why a texel has its height (SPEC §6 Probe): {u, v, texel: [x, y], map_size, base, bump,
    /// displacement, contributions: [{placement, pattern, target, t, L, height}]} at the texel of
    /// the scene's maps containing (u, v), at `time` (default the scene's pose time). Fails on u
    /// or v outside [0, 1] (field "u"/"v") or a bad time (field "time").
    Result<nlohmann::json> probe(const std::string& id, double u, double v,
                                 std::optional<double> time);
    /// Each placement's t over clip `clip` at `fps` (SPEC §6 Activation): {scene, clip, fps,
    /// times, placements: {pid: [t…]}, flags: [{placement, kind, at}]} (core clipActivation).
    Result<nlohmann::json> activation(const std::string& id, const std::string& clip, double fps);
    /// What may be wrong with a scene that validates (SPEC §6 Lint): [{code, severity, placement,
    /// message}] from core lintScene, plus `unused_upload` (info) for every uploaded pattern no
    /// scene uses.
    Result<nlohmann::json> lint(const std::string& id);

    // --- sweeps (service_sweep.cpp)
    /// The steps of a sweep as JSON (core jointSweep / clipSweep on the frame's snapshot):
    /// joint sweeps {scene, placement, joint, axis, theta_min, theta_max, time, steps: [{theta,
    /// t}], placements: {pid: [t…]}}; clip sweeps {scene, clip, duration, placement (or null),
    /// steps: [{time, t: {pid: t}}]} (t of every placement, or of `placement` alone when given).
    /// Fails: InvalidArgument "placement" when neither placement nor clip is given, "steps"
    /// outside 2..1000; NotFound "placement" / "clip" for unknown ones; like frame() otherwise.
    Result<nlohmann::json> sweepSteps(const std::string& id, const SweepParams& params);
    /// The sweep rendered as a PNG contact sheet: one size × size cell per step, laid out by
    /// core sheetLayout, each labelled (θ and t; or the clip time and the t of `placement`, or of
    /// every placement with t ≥ 0.005, most active first, as many lines as fit 40% of the cell).
    /// The renderer has no batch call: the cells are N renderFrame calls made in this one request,
    /// holding one render-queue slot. Fails like sweepSteps, with "steps" outside 2..kMaxSweepCells, "size" outside
    /// 1..8192 (InvalidArgument) or over the render-side limit, alone or as the sheet's side
    /// (TooLarge).
    Result<EncodedImage> sweep(const std::string& id, const SweepParams& params);

    // --- 3D view helpers (service_view.cpp)
    /// Where the camera should look to frame placement `pid` (the editor's F): {placement,
    /// target: [x, y, z] (the posed surface point at the footprint's centre, or the centre of the
    /// posed skin inside the footprint when no triangle lies under the centre), radius (of the
    /// posed skin inside the footprint), distance (that fits a sphere of 1.5 × radius in a
    /// square frame's 30° field of view), hit (a triangle lies under the centre)}; the pose is
    /// the frame's (params: time, revision, preview). NotFound "placement"; InvalidArgument
    /// "placement" when no skin lies inside the footprint or the model has no UVs.
    Result<nlohmann::json> focus(const std::string& id, const std::string& pid, const FrameParams& params);
    /// An animated WebP (lossy, looping) of the range of motion of a placement: see
    /// TurntableParams. Holds one render-queue slot for every frame. Fails: NotFound
    /// "placement"; InvalidArgument "frames", "size", "fps" out of range; TooLarge "size" over
    /// the render-side limit; like frame() otherwise.
    Result<EncodedImage> turntable(const std::string& id, const TurntableParams& params);

    // --- renders
    /// A frame of scene `id` with `params`' overrides; `patternsOff`, `only` (unknown ids fail,
    /// field "only") and `revision` (NotFound, field "revision") choose what it shows. The
    /// current revision and the 15 before it render from the scene validated
    /// when they were committed; an older revision's document is read and validated again
    /// (Conflict when it no longer renders: a pattern or model it names was deleted since).
    Result<EncodedImage> frame(const std::string& id, const FrameParams& params);
    /// How many frames, sweeps and driver answers so far parsed and validated their scene again
    /// from a document (an older revision, a preview) instead of taking the cached one. For tests.
    std::uint64_t framesPrepared() const;
    /// PNG heat map of the per-pixel difference between the frame `params` describe and the same
    /// frame `against` "off" (no dynamic patterns) or a revision number (SPEC §6 Compare): black
    /// where equal, red → yellow → white as the largest channel difference grows;
    /// `changedPixels` counts the pixels that differ at all. InvalidArgument ("against") for
    /// anything else.
    Result<EncodedImage> frameDiff(const std::string& id, const FrameParams& params,
                                   const std::string& against);
    /// which: bump | displacement | normal; format: png16 | exr | f32 (normal: png | exr).
    Result<EncodedImage> heightmap(const std::string& id, const std::string& which,
                                   const std::string& format);
    /// Validates a stateless batch ({"scene", "frames": [{"time"} | {"pose"}], "format",
    /// "view"?, "size"?}); returns a job that renders frame k on demand.
    /// The scene may name its model, pattern values, placement patterns and base by content
    /// address "sha256:<64 hex>" (SPEC §7): found in `content` (address → bytes sent along, each
    /// checked against its address, decoded and kept in this server's LRU content cache), in that
    /// cache, or among uploads with that SHA-256. Fails: MissingContent (409) with
    /// Error::missing listing what this server lacks; InvalidArgument for malformed addresses or
    /// bytes that do not match their address; the scene's and the parts' decode errors.
    struct BatchJob {
        std::size_t frames = 0;
        std::function<Result<EncodedImage>(std::size_t k)> render;
    };
    Result<BatchJob> batch(const nlohmann::json& body,
                           const std::map<std::string, std::vector<std::uint8_t>>& content = {});

    // --- events
    Result<std::shared_ptr<Subscription>> subscribe(const std::string& id);
    void unsubscribe(const std::string& id, const std::shared_ptr<Subscription>& s);
    /// Closes every subscription (server shutdown).
    void closeSubscriptions();

    struct State;

private:
    Service() = default;
    std::unique_ptr<State> state_;
    ServerLimits limits_;
    std::vector<std::string> warnings_;
};

} // namespace dermis
