// Dermis GL shell — the GPU renderer: the paper's two stages (§4, Fig. 4), headless.
//
//   stage 1: height maps by render-to-texture — one quad per placement over its footprint, the
//            deformation model of SPEC §2 in the fragment shader, additive blending into the
//            bump and displacement channels of one float target, plus the static base map; a
//            surface placement (SPEC §8) evaluates its decal per texel from the layout's
//            rest-surface map (HeightMapInput::rest, uploaded as two RGB32F textures cached by
//            content id like the patterns); skipped when a frame's inputs equal those of the
//            maps already rendered;
//   stage 2: the character — linear blend skinning in the vertex shader, displacement along the
//            skinned normal (per vertex, or per tessellated vertex), bump mapping (the maps
//            sampled with the height-map layout's UVs, a second UV attribute), base colour (the
//            model's own UVs),
//            simple lighting, MSAA, sRGB output, an orbit camera framed on the posed bounds
//            (core/camera.hpp: the same matrices a pick uses to cast rays from pixels).
//
// Files: this façade and the render thread in renderer.cpp; Renderer::Impl in renderer_impl.hpp;
// model uploads in gpu_model.cpp; stage 1 in height_pass.cpp; stage 2 in frame_pass.cpp.
//
// Ownership and threads: a Renderer owns one GL context and one render thread that is the only
// thread ever touching GL. Every public method may be called from any thread: it queues a job to
// the render thread and waits for it, so calls are serialised. One Renderer per process at a time
// (the GL entry points are process-wide). This header includes no EGL/GL.
//
// Caches: a model's buffers and textures are uploaded once per Model object; pattern and base
// textures are cached by content id (see HeightPassInput), so a deleted image whose reused address
// holds a new one is never mistaken for it. Both share one byte budget (RendererOptions): before
// an upload, and after every job, the least recently used entries not needed by the running job
// are freed until the cache fits (a job that needs more than the budget gets it, and its entries
// are trimmed when it ends). forgetPattern / forgetModel free the entries of deleted content at
// once; a model whose owner is gone is dropped at the next job. Errors: Result<…> with ErrorCode::Unavailable when no backend starts (the
// message lists what was tried), InvalidArgument for bad inputs (field named), Internal for GL
// failures (shader compile log, incomplete framebuffer).
#pragma once

// The renderer draws models and maps, never scene documents: it includes the render settings
// (core/render_settings.hpp), not core/scene.hpp (LayersTest checks this).
#include "core/camera.hpp"
#include "core/environment.hpp"
#include "core/heightmap.hpp"
#include "core/model.hpp"
#include "core/render_settings.hpp"
#include "core/result.hpp"
#include "core/rig.hpp"
#include "gl/gl_backend.hpp"

#include <glm/glm.hpp>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace dermis {

struct FramePlan; // core/frame_plan.hpp

struct RendererInfo {
    std::string backend;    ///< the backend that started: "egl-device", "egl-surfaceless", "osmesa"
    std::string device;     ///< EGL device/driver description where known
    std::string vendor, renderer, version, glslVersion; ///< glGetString
    int maxTextureSize = 0;
    int maxSamples = 0;
    /// A software rasterizer (Mesa llvmpipe / softpipe / swrast): `render.aa: auto` is post-process
    /// AA there (core resolveAntiAliasing), and big height passes are baked on the CPU.
    bool software = false;
    /// Start-up: milliseconds to create the context (EGL/OSMesa, driver strings) and to build the
    /// programs and shared objects (`render --timings`, dermis-coldbench).
    double contextMs = 0.0, programsMs = 0.0;
    std::vector<std::string> tried; ///< one line per backend tried before this one, with why it failed
};

/// Default byte budget of the renderer's GPU cache (pattern textures and model uploads).
inline constexpr std::size_t kDefaultGpuCacheBytes = std::size_t{512} << 20;

struct RendererOptions {
    /// Bytes of pattern/base textures and model buffers/textures kept between jobs (estimated
    /// from their formats and sizes). The render targets are not counted.
    std::size_t cacheBudgetBytes = kDefaultGpuCacheBytes;
    /// On a software rasterizer (Mesa llvmpipe / softpipe / swrast), a height pass whose
    /// footprints cover more than this many map areas (Σ scale.u·scale.v over active placements)
    /// is baked by the CPU (dermis::bakeHeightMapsInto, all cores) and uploaded instead: llvmpipe
    /// shades the pass ≈ 5–10× slower per texel than the CPU bake, so hundreds of placements
    /// would make the frame time jump. Same maps up to float rounding; Stats::heightPassesOnCpu
    /// counts them. 0 = always the GL pass. Hardware GLs always run the GL pass.
    double softwareCpuBakeCoverage = 2.0;
    /// Before every draw, checks that each uniform and storage block of the program in use has a
    /// buffer bound, with a range inside the buffer's store and at least the block's size. GL
    /// leaves such a draw undefined; Mesa's llvmpipe copies every bound uniform range on every
    /// draw and so reads past a store that shrank under a stale range. The first violation fails
    /// the job (ErrorCode::Internal, naming the draw, the block and the range). Costs a few GL
    /// queries per draw: for tests (RendererGLTest), off by default.
    bool checkBindings = false;
};

/// What the renderer's GPU cache holds, as of the last job that ended.
struct GpuCacheStats {
    std::size_t textures = 0;     ///< pattern and base textures
    std::size_t textureBytes = 0; ///< their bytes (R32F: 4 per texel)
    std::size_t models = 0;       ///< models with uploaded buffers and textures
    std::size_t modelBytes = 0;   ///< their bytes (vertex attributes, indices, textures with mips)
    std::size_t budgetBytes = 0;  ///< RendererOptions::cacheBudgetBytes
    std::size_t evictions = 0;    ///< entries freed for the budget since creation (not forgotten ones)
    std::size_t forgotten = 0;    ///< entries freed by forgetPattern / forgetModel since creation
};

/// Input of the GPU height pass: the same as the CPU reference's (core/frame_plan.hpp). Pattern
/// and base textures are cached by content id (BakePlacement::patternId, HeightMapInput::baseId),
/// never by address; an image without an id (0) is cached by a hash of its pixels.
using HeightPassInput = HeightMapInput;

/// Wall-clock milliseconds of a frame's stages (with glFinish between them when profiling).
struct FrameTimings {
    double heightMs = 0.0;   ///< height pass (or upload of CPU maps)
    double skinMs = 0.0;     ///< skin pass incl. MSAA resolve
    double postAaMs = 0.0;   ///< post-process AA on the read-back frame (render.aa "post")
    double readbackMs = 0.0; ///< glReadPixels into the frame
};

/// An outline drawn on the skin: the editor's selection, hover and place brush. A band about 2
/// pixels wide, any view. Shapes: `UvRect` where the surface's height-map UV lies on the border
/// of a footprint rectangle (SPEC §2 footprint: centre, size, rotation in degrees about the
/// centre); `SurfaceRect` where the rest surface lies on the border of a surface decal (SPEC §8:
/// the frame of core surfaceFrameOf — anchor, unit normal, unit tangent with the rotation applied,
/// size, depth; surfaces facing away or beyond the depth get none); `SurfaceCircle` a circle of
/// diameter size.x about the anchor on the rest surface (the surface place brush).
struct FrameOutline {
    enum Kind { Selected = 0, Hovered = 1, Brush = 2 };
    enum Shape { UvRect = 0, SurfaceRect = 1, SurfaceCircle = 2 };
    glm::vec2 center{0.5f}, scale{0.1f};
    float rotation = 0.0f; ///< degrees
    Kind kind = Selected;
    Shape shape = UvRect;
    // Surface shapes (bind space, model units).
    glm::vec3 anchor{0.0f}, normal{0.0f, 0.0f, 1.0f}, tangent{1.0f, 0.0f, 0.0f};
    glm::vec2 size{0.1f};
    float depth = 0.05f;
};

/// Most outlines of one frame (the size of the shader's array).
inline constexpr std::size_t kMaxFrameOutlines = 8;

struct FrameRequest {
    std::shared_ptr<const Model> model;
    std::vector<glm::mat4> world; ///< worldMatrices(model, pose): one per node
    /// LocalPose::morphWeights: one per Model::morphWeights; empty: their rest values.
    std::vector<float> morphWeights;
    RenderSettings render;        ///< size, camera, displacement scale/mode, bump strength, MSAA
    FrameView view = FrameView::Shaded; ///< shaded, or an unlit view of the maps (render_settings.hpp)
    /// Height maps from the GPU height pass when set; else `cpuMaps` (uploaded); else flat.
    std::optional<HeightPassInput> heights;
    const HeightMaps* cpuMaps = nullptr;
    bool readHeightMaps = false; ///< also return the maps the frame used (GPU pass only)
    bool profile = false;        ///< glFinish after each stage so that timings are per stage
    /// Outlines on the skin (at most kMaxFrameOutlines; none: the frame is exactly as without).
    std::vector<FrameOutline> outlines;
    /// The layout the height maps live in (SPEC §8): its UVs are the second UV attribute the maps
    /// and outlines are sampled with, while the base colour keeps the model's UVs. Null: the
    /// model's own UVs for both. Must belong to `model` (one PartLayout per part, `source` within
    /// the part's vertices; triangles with an index out of range are dropped). Buffers for a
    /// layout are uploaded once per (model, layout object) and freed with either.
    std::shared_ptr<const TextureLayout> layout;
    /// The light of a `pbr` frame (core/environment.hpp); null: the default studio environment.
    /// Prefiltered once per image object and kept while it lives (one custom image at a time).
    std::shared_ptr<const EnvironmentImage> environment;
};

struct FrameResult {
    Image8 image;                   ///< RGBA8, sRGB, row 0 = top; alpha 255
    std::optional<HeightMaps> maps; ///< when readHeightMaps and the GPU pass ran
    FrameTimings timings;
    glm::vec3 boundsMin{0.0f}, boundsMax{0.0f}; ///< posed bounds used for framing
    glm::vec3 cameraTarget{0.0f}; ///< the point the camera looked at (FrameCamera::target)
    float cameraDistance = 0.0f;  ///< eye to target ("auto" resolved)
    std::string antiAliasing;     ///< what render.aa resolved to: ResolvedAntiAliasing::label()
};

/// What a service needs of a renderer, so that it can be injected: Renderer is the GL one; tests
/// use a CPU fake. Implementations may be called from any thread.
class FrameRenderer {
public:
    virtual ~FrameRenderer() = default;
    virtual const RendererInfo& info() const = 0;
    /// Both height maps of `in`, row 0 first (SPEC conventions).
    virtual Result<HeightMaps> bakeHeightMaps(const HeightPassInput& in) = 0;
    /// One frame (and the maps it used when asked).
    virtual Result<FrameResult> renderFrame(const FrameRequest& request) = 0;
    /// The pattern or base image with this content id (PatternImage::contentId) was deleted:
    /// whatever was uploaded of it may be freed. Returns at once (queued behind the jobs already
    /// waiting); a later job that still uses the image uploads it again. Never fails.
    virtual void forgetPattern(std::uint64_t contentId) { (void)contentId; }
    /// Same for a model (the caller's pointer identifies it; the renderer keeps no reference).
    virtual void forgetModel(const std::shared_ptr<const Model>& model) { (void)model; }
    /// The GPU cache's figures; nullopt for renderers without one. Cheap: takes no GL job.
    virtual std::optional<GpuCacheStats> cacheStats() const { return std::nullopt; }
};

class Renderer final : public FrameRenderer {
public:
    /// Starts the render thread and a GL 4.3 core context on it. Fails (Unavailable) with every
    /// backend tried and why when none starts; never aborts the process.
    static Result<std::unique_ptr<Renderer>> create(GlBackend backend = GlBackend::Auto,
                                                    const RendererOptions& options = {});
    ~Renderer() override; ///< finishes queued jobs, destroys GL objects and the context, joins the thread
    Renderer(const Renderer&) = delete;
    Renderer& operator=(const Renderer&) = delete;

    const RendererInfo& info() const override;

    /// Stage 1 alone: both maps at the input's size, read back (row 0 first, SPEC conventions).
    /// Matches the CPU reference within float rounding away from footprint edges.
    Result<HeightMaps> bakeHeightMaps(const HeightPassInput& in) override;

    /// Stage 1 (optional) + stage 2 + readback of one frame.
    /// Render settings are checked by validateRenderSettings, then against the GL's limits.
    Result<FrameResult> renderFrame(const FrameRequest& request) override;

    void forgetPattern(std::uint64_t contentId) override;
    void forgetModel(const std::shared_ptr<const Model>& model) override;
    std::optional<GpuCacheStats> cacheStats() const override;

    /// Stage 2's morphing and skinning alone, captured with transform feedback: per part, the
    /// skinned positions and unit normals without displacement — the GPU twin of dermis::skin
    /// (same `morphWeights`: one per Model::morphWeights, empty for the rest values).
    Result<std::vector<SkinnedPart>> skinOnGpu(const std::shared_ptr<const Model>& model,
                                               const std::vector<glm::mat4>& world,
                                               const std::vector<float>& morphWeights = {});

    /// Counters since creation: height passes run, and skipped because the targets already held
    /// the same inputs (same placements, t values, patterns, base and size).
    struct Stats {
        std::size_t heightPasses = 0, heightPassesSkipped = 0;
        std::size_t heightPassesOnCpu = 0; ///< of heightPasses: baked by the CPU (RendererOptions)
    };
    Stats stats();

    /// Drops the cached pattern and base textures (next use re-uploads them) and forgets what the
    /// height targets hold, so the next height pass runs. Models are not touched here: a model
    /// whose owner is gone is dropped at the next frame or skinning job.
    void forgetPatterns();

    /// Introspection for UniformBlockGLTest: the GL's size of a uniform block and the offsets of
    /// its members, from the linked programs ("HeightPassBlock", "FrameBlock", "PartBlock",
    /// "OutlineBlock").
    struct BlockLayout {
        int size = -1;
        std::vector<std::pair<std::string, int>> offsets; ///< member name → byte offset
    };
    Result<BlockLayout> blockLayout(const std::string& block);

    struct Impl;

private:
    explicit Renderer(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

/// A frame request for `plan` (world matrices, render settings, view, GPU height pass on its
/// heights, the height-map layout of its heights).
/// The request points into the plan's images: keep `plan` alive while the request is used.
FrameRequest frameRequest(const FramePlan& plan, std::shared_ptr<const Model> model);


} // namespace dermis
