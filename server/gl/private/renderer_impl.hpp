// Dermis GL shell (internal) — Renderer::Impl, the render thread's side of the renderer, and the
// GL objects it owns. Included only by the renderer's own files; it includes GL (glad).
//
//   renderer.cpp    job queue, init/shutdown, introspection, the public façade;
//   gpu_cache.cpp   the byte budget of pattern textures and model uploads: LRU eviction,
//                   forgetting deleted content, the published figures;
//   gpu_model.cpp   a model's buffers and textures (uploaded once per Model), the joint palette;
//   height_pass.cpp stage 1: pattern/base texture caches by content id, the height targets, the
//                   height pass, readback and upload of maps;
//   frame_pass.cpp  stage 2: frame targets, the skin pass (camera from core/camera.hpp),
//                   readback, transform-feedback skinning.
//
// Threads: everything below except `run` (and the queue members it uses) belongs to the render
// thread, which owns the GL context. Ownership: Impl owns every GL object named here and deletes
// them in shutdown(); the structs' destroy() delete their own objects and need the context.
// Errors: Status/Result with kWhere as the function name, ErrorCode::Internal for GL failures.
#pragma once

#include "core/camera.hpp"
#include "core/environment.hpp"
#include "core/render_settings.hpp"
#include "core/rig.hpp"
#include "core/texture_layout.hpp"
#include "uniform_blocks.hpp"
#include "gl_context.hpp"
#include "gl/renderer.hpp"

#include <glad/gl.h>

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <future>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace dermis::gl {

inline constexpr const char* kWhere = "dermis::Renderer";

inline double msSince(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

/// A float texture: one channel (R32F), two (RG32F) or three (RGB32F; `data` interleaved), clamped to the edge,
/// with `filter` for both minification and magnification. `data` may be null (storage only).
/// The caller owns the texture. Leaves it bound to GL_TEXTURE_2D of the active unit.
GLuint makeFloatTexture(int w, int h, const float* data, GLint filter, int channels = 1);

/// A model's GL objects (gpu_model.cpp).
struct GpuModel {
    std::weak_ptr<const Model> owner;
    struct Part {
        GLuint vao = 0;
        /// position, normal, uv, joints, weights, indices, map uv (attribute slots 0–4 and 5;
        /// the model's own parts read slot 5 from the uv buffer and leave buffers[6] at 0),
        /// then tangent, uv1, colour (slots 6–8, 0 when the part has none), then the morph
        /// deltas (skin.vert's MorphDeltas storage buffer; 0 without morph targets)
        GLuint buffers[11] = {};
        GLsizei indexCount = 0, vertexCount = 0;
        int paletteOffset = 0;
        int material = -1;
        bool hasUVs = false;    ///< the model's TEXCOORD_0 (base colour)
        bool hasMapUVs = false; ///< height-map UVs (the layout covers the part)
        bool hasTangents = false, hasUVs1 = false, hasColors = false; ///< slots 6, 7, 8
        /// Morph targets (MeshPart::morphs) and where their weights start in the frame's
        /// MorphWeights buffer (uploadPalette).
        int morphTargets = 0, morphWeightOffset = 0;
    };
    std::vector<Part> parts; ///< with the model's own UVs as the maps' layout
    /// The parts drawn with another height-map layout (SPEC §8): vertices split as the layout's
    /// (each a copy of its part vertex, `source`), map UV = layout UV, base-colour UV = the
    /// part's. A layout equal to the model's own (modelTextureLayout: identity source, the part's
    /// indices and UVs) is `identity` and draws `parts`. Freed with the model, or when the
    /// layout's owner is gone.
    struct LayoutParts {
        std::weak_ptr<const TextureLayout> owner;
        bool identity = false;
        std::vector<Part> parts;
        std::size_t bytes = 0;
    };
    std::map<const TextureLayout*, LayoutParts> layouts;
    std::vector<GLuint> textures; ///< one per Model::images entry, sRGB
    /// One per Model::images entry: linear RGBA8 for the images a material reads as data
    /// (metallic-roughness, normal, occlusion), 0 for the others.
    std::vector<GLuint> dataTextures;
    int paletteSize = 0;
    int morphWeightCount = 0; ///< Σ morph targets over the parts
    double autoDisplacement = 0.01;
    std::size_t bytes = 0;     ///< estimated GPU bytes of the buffers and textures
    std::uint64_t lastUse = 0; ///< job counter of its last use, for evicting the least recent

    /// The base-colour texture of `part` (of `model`, the Model this was uploaded from), or 0
    /// when its material has none or names no uploaded image.
    GLuint baseColorTexture(const Model& model, const Part& part) const;
    void destroy();
};

/// What the height targets were last rendered from: when a frame asks for the same, the height
/// pass is skipped (a camera move or a pose change that moves no driving joint).
struct HeightKey {
    int width = 0, height = 0;
    std::uint64_t base = 0;              ///< content id of the base map (0 = none)
    std::vector<std::uint64_t> patterns; ///< content id per placement (0 = skipped)
    std::uint64_t rest = 0;              ///< content id of the rest-surface map (0 = none used)
    /// per placement: centre, scale, rotation, h, t, model, target, response; for a surface
    /// placement also its anchor, tangent, normal, size and depth
    std::vector<double> params;
    bool operator==(const HeightKey&) const = default;
};

struct PatternTexture {
    GLuint tex = 0;
    GLuint tex2 = 0;           ///< a rest-surface map's normals (tex: its positions, RGB32F); else 0
    std::size_t bytes = 0;     ///< width × height × 4 (R32F), × 24 for a rest-surface map
    std::uint64_t lastUse = 0; ///< job counter of its last use, for evicting the least recent
};

/// The content id of an image given without one: a hash of its size and pixels (FNV-1a over
/// 64-bit words), with the top bit set so that it never equals a PatternImage counter id.
std::uint64_t contentHash(const HeightImage& image);

/// The height maps as one RG32F texture (red: bump, green: displacement) — one target for the
/// height pass and one fetch for both maps in the skin pass — and its framebuffer.
struct HeightTargets {
    GLuint fbo = 0, maps = 0;
    int width = 0, height = 0;
    std::vector<float> staging; ///< interleaving buffer for CPU maps

    void destroy();
};

/// Each placement's pattern texture and content id (0 for placements that contribute nothing),
/// and the rest-surface map's textures when a surface placement contributes (SPEC §8).
struct ResolvedPatterns {
    std::vector<GLuint> textures;
    std::vector<std::uint64_t> ids;
    std::vector<TexelRect> surfaceRects; ///< per placement: the texels a surface placement may reach
    GLuint restPosition = 0, restNormal = 0;
    std::uint64_t restId = 0;
};

/// Multisampled colour + depth and the single-sampled resolve target.
struct FrameTargets {
    GLuint fbo = 0, color = 0, depth = 0, resolveFbo = 0, resolveColor = 0;
    int width = 0, height = 0, samples = 0;

    void destroy();
};

/// The key light's shadow map (shadow_pass.cpp): a depth texture compared on lookup (border 1:
/// outside the map is lit) and its framebuffer, kKeyLightShadowMapSize² once made.
struct ShadowTarget {
    GLuint fbo = 0, depth = 0;
    int size = 0;

    void destroy();
};

/// What a shadow map was drawn from (shadow_pass.cpp): the model and height-map layout (by owner,
/// so that a new object at a freed one's address is another), the pose, the light's view, the
/// displacement and the height maps' content (heightsWritten). A key-light frame whose inputs
/// equal the last drawn map's — only its camera moved, as when orbiting in the editor — reuses it.
struct ShadowInputs {
    std::weak_ptr<const Model> model;
    std::weak_ptr<const TextureLayout> layout;
    std::vector<glm::mat4> world;
    std::vector<float> morphWeights;
    glm::mat4 viewProj{1.0f};
    double dispScale = 0.0;
    GLuint heightTexture = 0;
    std::uint64_t heightsWritten = 0; ///< (new targets, of another size, count as a write)

    /// The same model and layout objects and equal values.
    bool sameAs(const ShadowInputs& o) const;
};

/// The height maps a frame samples: a texture (RG32F) and its size.
struct HeightSource {
    GLuint texture = 0;
    glm::vec2 size{1.0f};
};

// pbr_pass.cpp: the pbr shading's per-part material.
/// The glTF material of `gp` (of `model`, uploaded as `gm`) into pb's PBR members: factors,
/// which textures it samples (those whose image was uploaded and whose UV set the part has),
/// their UV sets and KHR_texture_transform, alpha mode and flags. A part without a material
/// gets the legacy skin tone as a rough dielectric.
void fillMaterialBlock(PartBlock& pb, const Model& model, const GpuModel& gm, const GpuModel::Part& gp);
/// The kMap* bits of the textures the pbr shading samples for part `gp` (PartBlock::maps.x as
/// fillMaterialBlock sets it): those whose image was uploaded and whose UV set the part has.
int materialMaps(const Model& model, const GpuModel& gm, const GpuModel::Part& gp);
/// Whether any of `parts` samples a texture besides the base colour (metallic-roughness, normal,
/// occlusion, emissive): the frame then needs the pbr program with DERMIS_PBR_MAPS.
bool needsMaterialMaps(const Model& model, const GpuModel& gm, const std::vector<GpuModel::Part>& parts);
/// The glTF material of part `gp`; null for a part without one (or with an index past the model's
/// materials), which the pbr shading draws as the default material.
const Material* materialOf(const Model& model, const GpuModel::Part& gp);
/// Binds the material's textures of `gp` to units 2–6 (pbr.glsl), `white` where it has none.
void bindMaterialTextures(const Model& model, const GpuModel& gm, const GpuModel::Part& gp, GLuint white);
/// The order to draw `parts` in: opaque and masked parts first (as given), then blended ones
/// farthest first by the distance from `eye` to the centre of their posed bounds (`posed`,
/// skin(model, world), indexed like parts).
std::vector<std::size_t> pbrDrawOrder(const Model& model, const std::vector<GpuModel::Part>& parts,
                                      const std::vector<SkinnedPart>& posed, glm::vec3 eye);
/// Computes the process-wide CPU tables of the pbr shading's default light — the studio
/// environment prefiltered and the split-sum DFG table, ≈ 0.1 s of CPU — unless done: any thread,
/// pure CPU (no GL). Renderer::create runs it beside the context's start, so that a process's
/// first pbr frame does not wait for it.
void warmStudioLighting();

} // namespace dermis::gl

namespace dermis {

struct Renderer::Impl {
    // --- job queue (any thread) ----------------------------------------------------------------
    std::thread thread;
    /// gl::warmStudioLighting on a helper thread from create (its future joins it on destruction).
    std::future<void> lightingWarm;
    std::mutex mutex;
    std::condition_variable cv;
    std::deque<std::function<void()>> jobs;
    bool stopping = false;

    /// Queues `f` for the render thread and waits for its result, which is handed back once the
    /// job has ended (endJob), so that the cache figures a caller reads next include it.
    template <class F>
    auto run(F&& f) -> decltype(f()) {
        using R = decltype(f());
        auto done = std::make_shared<std::promise<R>>();
        std::future<R> fut = done->get_future();
        post([this, &f, done] {
            try {
                R r = f();
                endJob();
                done->set_value(std::move(r));
            } catch (...) {
                endJob();
                done->set_exception(std::current_exception());
            }
        });
        return fut.get();
    }

    /// Queues `f` for the render thread and returns at once (f must not throw; it ends with
    /// endJob()).
    void post(std::function<void()> f) {
        {
            std::lock_guard<std::mutex> lock(mutex);
            jobs.push_back(std::move(f));
        }
        cv.notify_one();
    }

    /// The render thread's loop: runs jobs in order until stopping and drained, each with its own
    /// number (useCounter).
    void loop();
    /// The end of every job: the cache trimmed to its budget, its figures published.
    void endJob() {
        trimCache();
        publishCacheStats();
    }

    // --- cache figures (any thread) ---------------------------------------------------------------
    mutable std::mutex statsMutex;
    GpuCacheStats published; ///< as of the last job that ended

    // --- render-thread state ----------------------------------------------------------------------
    std::unique_ptr<gl::GlContext> context;
    RendererInfo info;
    GLuint heightProgram = 0, heightSurfaceProgram = 0, heightBaseProgram = 0, captureProgram = 0;
    /// The skin pass by [tessellated][FrameView]: skin.frag with DERMIS_VIEW = the view, so that a
    /// software rasterizer, which runs every branch for every pixel, does not shade the unlit
    /// views' code in a shaded frame (1024² skin pass on llvmpipe: 19 → 12 ms). All eight are
    /// built at start (buildPrograms), none during a frame. (The out-of-bounds reads in swrast_dri
    /// once blamed on a program linked mid-frame were a stale uniform range past a store that had
    /// shrunk; see checkDrawBindings.)
    GLuint skinPrograms[2][4] = {};
    /// The pbr programs (skin.frag + pbr.glsl with DERMIS_PBR) by the PbrVariant bits they were
    /// built with: tessellated; DERMIS_SKIN, the shaded view with `render.shading` skin;
    /// DERMIS_KEY_LIGHT (`render.key_light`); DERMIS_PBR_MAPS, for materials with textures
    /// besides the base colour; DERMIS_PBR_VIEWS, for the material views (basecolor, lighting,
    /// normal) besides the shaded one; DERMIS_OUTLINES, for frames with outlines (the editor's
    /// selection, hover, brush). Each variant leaves out code that a software rasterizer
    /// would otherwise run for every pixel (1024² pbr skin pass on llvmpipe, default scene:
    /// docs/benchmarks.md). The plain shaded ones (vertex and tessellated: the default shading)
    /// are built at start; any other on the first frame that asks for it, on the render thread
    /// before the frame's draws, and kept.
    enum PbrVariant : unsigned {
        kPbrTess = 1, kPbrSkin = 2, kPbrKeyLight = 4, kPbrMaps = 8, kPbrViews = 16, kPbrOutlines = 32
    };
    std::map<unsigned, GLuint> pbrPrograms;
    /// The depth-only programs (skin.vert with DERMIS_PBR + shadow.frag) of the key light's shadow
    /// map and of the skin pass's depth prepass (built at start): depthProgramFor chooses.
    GLuint depthProgram = 0;     ///< shadow.frag: opaque parts' depth (shadow map, depth prepass)
    GLuint depthMaskProgram = 0; ///< shadow.frag with DERMIS_MASK: glTF MASK parts' depth
    /// depthMaskProgram for a part whose material `m` (gl::materialOf; null: none) is a glTF
    /// MASK, else depthProgram.
    GLuint depthProgramFor(const Material* m) const {
        return m && m->alphaMode == AlphaMode::Mask ? depthMaskProgram : depthProgram;
    }
    GLuint depthProgramFor(const Model& model, const gl::GpuModel::Part& gp) const {
        return depthProgramFor(gl::materialOf(model, gp));
    }
    gl::ShadowTarget shadowMap;
    /// What `shadowMap` holds (drawn from); reset when the target is made anew.
    std::optional<gl::ShadowInputs> lastShadow;
    /// 1×1 depth texture (compare mode, depth 1: lit), bound for key lights without a shadow.
    GLuint noShadowTexture = 0;
    /// The KeyLightBlock, and the FrameBlock of the shadow pass (the light's view).
    GLuint keyLightUbo = 0, shadowFrameUbo = 0;
    /// The image-based light of the pbr programs (pbr_pass.cpp): for the default studio
    /// environment and for the last environment a frame brought (FrameRequest::environment, kept
    /// while its owner lives), the GGX-prefiltered radiance with one mip level per roughness step
    /// and the block with its irradiance; the split-sum table and the block's buffer are shared.
    struct EnvironmentLight {
        GLuint specular = 0;
        gl::EnvironmentBlock block{};
        void destroy() {
            glDeleteTextures(1, &specular);
            specular = 0;
        }
    };
    EnvironmentLight studioLight, customLight;
    std::weak_ptr<const EnvironmentImage> customOwner;
    const EnvironmentImage* customKey = nullptr; ///< the image customLight was made from
    GLuint brdfLutTexture = 0, environmentUbo = 0;
    GLuint emptyVao = 0, heightUbo = 0, frameUbo = 0, partUbo = 0, paletteSsbo = 0,
           feedbackBuffer = 0, outlineUbo = 0, morphWeightSsbo = 0;
    GLuint flatTexture = 0;  ///< 1×1 zero heights (RG32F), for frames without height maps
    GLuint whiteTexture = 0; ///< 1×1 white, for parts without a base-colour texture
    GLint uboAlignment = 256;
    GLint maxRenderbufferSize = 0;

    gl::HeightTargets heights;
    gl::FrameTargets frame;
    std::map<const Model*, gl::GpuModel> models;
    std::map<std::uint64_t, gl::PatternTexture> patterns; ///< by content id (base maps too)
    std::uint64_t useCounter = 0; ///< the running job's number (entries used by it are spared)
    GLuint baseTexture = 0;       ///< the base map of the running height pass (owned by `patterns`)
    std::size_t cacheBudget = kDefaultGpuCacheBytes;
    std::size_t patternBytes = 0, modelBytes = 0; ///< sums of the entries' bytes
    std::size_t evictions = 0, forgotten = 0;
    std::optional<gl::HeightKey> lastHeights; ///< what `heights` holds now, if from a height pass
    /// Counts writes of the height targets (passes drawn or baked, uploads, new targets): what a
    /// shadow map's reuse compares (vertex displacement moves what casts).
    std::uint64_t heightsWritten = 0;
    std::size_t heightPasses = 0, heightPassesSkipped = 0, heightPassesOnCpu = 0;
    double softwareCpuBakeCoverage = 2.0; ///< RendererOptions::softwareCpuBakeCoverage
    bool checkBindings = false;           ///< RendererOptions::checkBindings
    std::string bindingProblem;           ///< its first violation since the last checkGl
    HeightMaps cpuBake;                   ///< storage of height passes baked on the CPU

    /// Bytes between consecutive blocks of `size` in one uniform buffer bound by range.
    std::size_t uboStride(std::size_t size) const {
        const auto a = static_cast<std::size_t>(uboAlignment);
        return (size + a - 1) / a * a;
    }

    // renderer.cpp: life cycle and introspection.
    Status init(GlBackend backend);
    void readDriverInfo();
    Status buildPrograms();
    /// Links skin.vert/.frag (+ the tessellation stages when `tess`) with DERMIS_VIEW = `view`
    /// (+ DERMIS_PBR and pbr.glsl when `pbr`, with the defines of the PbrVariant bits in
    /// `variant`: kPbrSkin the skin shading's (DERMIS_SKIN, its constants from
    /// core/render_settings.hpp as defines), kPbrKeyLight DERMIS_KEY_LIGHT, kPbrMaps
    /// DERMIS_PBR_MAPS, kPbrViews DERMIS_PBR_VIEWS, kPbrOutlines DERMIS_OUTLINES, which the
    /// programs without `pbr` always have); fails with the GL's log. Called by
    /// buildPrograms and skinProgram, on the render thread, never between a frame's draws.
    Result<GLuint> buildSkinProgram(bool tess, FrameView view, bool pbr = false, unsigned variant = 0);
    /// The skin program of a frame: with `pbr`, the pbr variant (pbrPrograms) for `view` (the
    /// shaded view or a material view, chosen in the shader by PartBlock's u_part.w), the skin
    /// shading's with `skinShading`, the key light's with `keyLight`, sampling the material's
    /// other textures with `maps`, drawing the frame's outlines with `outlines`; without, skinPrograms'
    /// for `view` (which always draw outlines). Links a variant the first time it is asked for
    /// (fails with the GL's log).
    Result<GLuint> skinProgram(bool tess, FrameView view, bool pbr = false, bool skinShading = false,
                               bool keyLight = false, bool maps = false, bool outlines = false);
    /// The light of `env` (null: the default studio environment), prefiltered on the CPU the
    /// first time a frame asks for it (legacy frames never pay for it) and kept: the studio's for
    /// the renderer's life, a custom one until another replaces it or its owner is gone. Fails
    /// (InvalidArgument, field "environment") for an image validateEnvironment refuses.
    Result<const EnvironmentLight*> environmentLight(const std::shared_ptr<const EnvironmentImage>& env);
    /// The frame's exposure, environment rotation and tone mapping into `light`'s block, bound
    /// with its textures (units 7, 8).
    void uploadEnvironmentBlock(const EnvironmentLight& light, const RenderSettings& rs);
    void createSharedObjects();
    void shutdown();
    void dropPatternTextures(); ///< pattern and base textures, and what the targets were from
    /// The GL error state, and the first binding violation checkDrawBindings recorded (both
    /// cleared): an Internal error naming `what`, else Ok.
    Status checkGl(const char* what);
    /// With checkBindings: records in bindingProblem the first block of the current program
    /// whose binding is missing, too small or past its buffer's store (RendererOptions::
    /// checkBindings). Call right before a draw; `draw` names it. No-op otherwise.
    void checkDrawBindings(const char* draw);
    Result<Renderer::BlockLayout> blockLayout(const std::string& block);

    // gpu_cache.cpp: the byte budget.
    /// Frees least recently used entries not used by the running job until `incoming` more bytes
    /// fit the budget (or nothing more can be freed).
    void makeRoom(std::size_t incoming);
    /// Frees least recently used entries, the running job's too, until the cache fits the budget.
    void trimCache();
    /// Frees the least recently used entry (pattern only with `patternsOnly`) last used before
    /// job `before`; false if there is none.
    bool evictOldest(std::uint64_t before, bool patternsOnly = false);
    void erasePattern(std::map<std::uint64_t, gl::PatternTexture>::iterator it);
    void eraseModel(std::map<const Model*, gl::GpuModel>::iterator it);
    void forgetPattern(std::uint64_t contentId);
    void forgetModel(const std::weak_ptr<const Model>& model);
    void publishCacheStats();

    // gpu_model.cpp
    Result<gl::GpuModel*> modelFor(const std::shared_ptr<const Model>& model);
    /// The parts of `gm` to draw with height-map layout `layout` (null: the model's own UVs):
    /// `gm.parts`, or the layout's buffers, uploaded on first use (SPEC §8).
    Result<const std::vector<gl::GpuModel::Part>*> partsFor(const Model& model, gl::GpuModel& gm,
                                                            const std::shared_ptr<const TextureLayout>& layout);
    void dropOrphanedModels();
    /// The joint palette of `world` (binding kPaletteBinding) and the morph weights of every
    /// part's targets at `morphWeights` (one per Model::morphWeights; empty: rest values;
    /// binding kMorphWeightBinding).
    void uploadPalette(const Model& model, const gl::GpuModel& gm, const std::vector<glm::mat4>& world,
                       const std::vector<float>& morphWeights);
    /// Binds part `gp`'s morph deltas (kMorphDeltaBinding) for its draw.
    void bindMorphDeltas(const gl::GpuModel::Part& gp) const;

    // height_pass.cpp: stage 1.
    Status bakeHeightMaps(const HeightPassInput& in, HeightMaps& maps); ///< pass + readback
    Status heightPass(const HeightPassInput& in);
    Result<gl::ResolvedPatterns> resolvePatterns(const HeightPassInput& in);
    Result<GLuint> patternTexture(std::uint64_t id, const HeightImage& image, const std::string& field);
    Result<std::uint64_t> resolveBase(const HeightPassInput& in);
    /// The rest-surface map's textures (cached like patterns, by RestSurfaceMap::contentId) into
    /// `r` when a surface placement contributes; fails without a map of the height maps' size.
    Status resolveRest(const HeightPassInput& in, gl::ResolvedPatterns& r);
    std::size_t uploadHeightBlocks(const HeightPassInput& in, const gl::ResolvedPatterns& resolved);
    void drawHeightPass(const HeightPassInput& in, const gl::ResolvedPatterns& resolved,
                        std::size_t stride);
    Status ensureHeightTargets(int w, int h);
    Status readHeightTargets(HeightMaps& maps);
    Status uploadHeightMaps(const HeightMaps& maps);

    // frame_pass.cpp: stage 2.
    Result<FrameResult> renderFrame(const FrameRequest& req);
    Status checkFrameRequest(const FrameRequest& req) const;
    Result<gl::HeightSource> heightStage(const FrameRequest& req, FrameResult& out);
    Status ensureFrameTargets(int w, int h, int samples);
    void uploadFrameBlock(const FrameCamera& camera, double dispScale, double bumpScale,
                          glm::vec2 heightmapSize);
    void uploadOutlineBlock(const std::vector<FrameOutline>& outlines);
    std::size_t uploadPartBlocks(const Model& model, const gl::GpuModel& gm,
                                 const std::vector<gl::GpuModel::Part>& parts, FrameView view,
                                 bool pbr);
    /// `pbrOrder` (pbr shading; null otherwise): the parts' draw order (pbrDrawOrder), with
    /// their material textures bound and blending for glTF BLEND parts.
    GLuint drawSkinPass(const Model& model, const gl::GpuModel& gm,
                        const std::vector<gl::GpuModel::Part>& parts, const RenderSettings& rs,
                        GLuint skinProgram, GLuint heightTexture, std::size_t partStride, int samples,
                        const std::vector<std::size_t>* pbrOrder);
    Status readFrame(GLuint readFbo, Image8& image);

    // shadow_pass.cpp: the key light (render.key_light).
    /// The KeyLightBlock of `light` for a frame framed on `bounds` (kKeyLightBinding) and, when
    /// it casts shadows, the shadow map drawn from it: every part but glTF BLEND ones, skinned and
    /// displaced as the frame draws them (vertex displacement), MASK parts by their cutoff; the
    /// part blocks must be uploaded (uploadPartBlocks with pbr) and the palette too. Binds the
    /// map (or the 1×1 lit one) to unit 9 and leaves the frame's FrameBlock bound. The light is
    /// req.render.keyLight (set); `layout` the parts' height-map layout (null: the model's UVs).
    /// The map is not drawn again while its inputs stay the same (ShadowInputs).
    Status keyLightStage(const FrameRequest& req, const std::shared_ptr<const TextureLayout>& layout,
                         const gl::GpuModel& gm, const std::vector<gl::GpuModel::Part>& parts,
                         const Bounds& bounds, double dispScale, const gl::HeightSource& heightSource,
                         std::size_t partStride);
    Status ensureShadowTarget(int size);
    Result<std::vector<SkinnedPart>> skinOnGpu(const std::shared_ptr<const Model>& model,
                                               const std::vector<glm::mat4>& world,
                                               const std::vector<float>& morphWeights);
};

} // namespace dermis
