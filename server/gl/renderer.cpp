// The GPU renderer: render thread, GL resources, height pass, skin pass, readback.
#include "gl/renderer.hpp"

#include "gl/gl_context.hpp"
#include "gl/programs.hpp"
#include "gl/uniform_blocks.hpp"

#include "core/render_settings.hpp"

#include <glad/gl.h>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <functional>
#include <future>
#include <map>
#include <mutex>
#include <thread>

namespace dermis {

namespace {

std::pair<glm::vec3, glm::vec3> boundsOf(const std::vector<SkinnedPart>& parts) {
    glm::vec3 lo(INFINITY), hi(-INFINITY);
    for (const SkinnedPart& p : parts)
        for (const glm::vec3& v : p.positions)
            if (std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z)) {
                lo = glm::min(lo, v);
                hi = glm::max(hi, v);
            }
    if (!(lo.x <= hi.x)) return {glm::vec3(-1.0f), glm::vec3(1.0f)};
    return {lo, hi};
}

} // namespace

double autoDisplacementScale(const Model& model) {
    const auto [lo, hi] = boundsOf(skin(model, worldMatrices(model, restPose(model))));
    const glm::vec3 ext = hi - lo;
    const double m = std::max({ext.x, ext.y, ext.z});
    return m > 0.0 && std::isfinite(m) ? 0.01 * m : 0.01;
}

using namespace gl;

namespace {

constexpr const char* kWhere = "dermis::Renderer";

double msSince(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

/// A float texture: one channel (R32F) or two (RG32F, `data` interleaved).
GLuint makeFloatTexture(int w, int h, const float* data, GLint filter, int channels = 1) {
    GLuint tex = 0;
    glGenTextures(1, &tex);
    glBindTexture(GL_TEXTURE_2D, tex);
    glTexStorage2D(GL_TEXTURE_2D, 1, channels == 2 ? GL_RG32F : GL_R32F, w, h);
    if (data) {
        glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
        glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, w, h, channels == 2 ? GL_RG : GL_RED, GL_FLOAT, data);
    }
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, filter);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, filter);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    return tex;
}

/// A model's GL objects.
struct GpuModel {
    std::weak_ptr<const Model> owner;
    struct Part {
        GLuint vao = 0;
        GLuint buffers[6] = {};
        GLsizei indexCount = 0, vertexCount = 0;
        int paletteOffset = 0;
        int material = -1;
        bool hasUVs = false;
    };
    std::vector<Part> parts;
    std::vector<GLuint> textures; ///< one per Model::images entry, sRGB
    int paletteSize = 0;
    double autoDisplacement = 0.01;

    void destroy() {
        for (Part& p : parts) {
            glDeleteVertexArrays(1, &p.vao);
            glDeleteBuffers(6, p.buffers);
        }
        if (!textures.empty()) glDeleteTextures(static_cast<GLsizei>(textures.size()), textures.data());
        parts.clear();
        textures.clear();
    }
};

/// What the height targets were last rendered from: when a frame asks for the same, the height
/// pass is skipped (a camera move or a pose change that moves no driving joint).
struct HeightKey {
    int width = 0, height = 0;
    std::uint64_t base = 0;             ///< content id of the base map (0 = none)
    std::vector<std::uint64_t> patterns; ///< content id per placement (0 = skipped)
    std::vector<double> params; ///< per placement: centre, scale, rotation, h, t, model, target, response
    bool operator==(const HeightKey&) const = default;
};

struct PatternTexture {
    GLuint tex = 0;
    std::uint64_t lastUse = 0; ///< frame counter, for evicting the least recently used
};

/// The content id of an image given without one: a hash of its size and pixels (FNV-1a over
/// 64-bit words), with the top bit set so that it never equals a PatternImage counter id.
std::uint64_t contentHash(const HeightImage& image) {
    std::uint64_t h = 1469598103934665603ull;
    auto mix = [&](std::uint64_t v) {
        h ^= v;
        h *= 1099511628211ull;
    };
    mix(static_cast<std::uint64_t>(image.width));
    mix(static_cast<std::uint64_t>(image.height));
    const std::size_t n = image.data.size();
    const float* d = image.data.data();
    std::size_t i = 0;
    for (; i + 1 < n; i += 2) {
        std::uint64_t v;
        std::memcpy(&v, d + i, sizeof v);
        mix(v);
    }
    if (i < n) {
        std::uint32_t v;
        std::memcpy(&v, d + i, sizeof v);
        mix(v);
    }
    return h | (1ull << 63);
}

/// The height maps as one RG32F texture (red: bump, green: displacement) — one target for the
/// height pass and one fetch for both maps in the skin pass — and its framebuffer.
struct HeightTargets {
    GLuint fbo = 0, maps = 0;
    int width = 0, height = 0;
    std::vector<float> staging; ///< interleaving buffer for CPU maps

    void destroy() {
        glDeleteFramebuffers(1, &fbo);
        glDeleteTextures(1, &maps);
        fbo = maps = 0;
        width = height = 0;
    }
};

/// Multisampled colour + depth, and the single-sampled resolve target.
struct FrameTargets {
    GLuint fbo = 0, color = 0, depth = 0, resolveFbo = 0, resolveColor = 0, pbo = 0;
    int width = 0, height = 0, samples = 0;
    std::size_t pboSize = 0;

    void destroy() {
        glDeleteFramebuffers(1, &fbo);
        glDeleteFramebuffers(1, &resolveFbo);
        glDeleteRenderbuffers(1, &color);
        glDeleteRenderbuffers(1, &depth);
        glDeleteRenderbuffers(1, &resolveColor);
        glDeleteBuffers(1, &pbo);
        *this = FrameTargets{};
    }
};

} // namespace

struct Renderer::Impl {
    // --- job queue (any thread) ----------------------------------------------------------------
    std::thread thread;
    std::mutex mutex;
    std::condition_variable cv;
    std::deque<std::function<void()>> jobs;
    bool stopping = false;

    template <class F>
    auto run(F&& f) -> decltype(f()) {
        using R = decltype(f());
        auto task = std::make_shared<std::packaged_task<R()>>(std::forward<F>(f));
        std::future<R> fut = task->get_future();
        {
            std::lock_guard<std::mutex> lock(mutex);
            jobs.push_back([task] { (*task)(); });
        }
        cv.notify_one();
        return fut.get();
    }

    void loop() {
        for (;;) {
            std::function<void()> job;
            {
                std::unique_lock<std::mutex> lock(mutex);
                cv.wait(lock, [&] { return stopping || !jobs.empty(); });
                if (jobs.empty()) return; // stopping and drained
                job = std::move(jobs.front());
                jobs.pop_front();
            }
            job();
        }
    }

    // --- render-thread state ----------------------------------------------------------------------
    std::unique_ptr<GlContext> context;
    RendererInfo info;
    GLuint heightProgram = 0, heightBaseProgram = 0, skinProgram = 0, skinTessProgram = 0,
           captureProgram = 0;
    GLuint emptyVao = 0, heightUbo = 0, frameUbo = 0, partUbo = 0, paletteSsbo = 0,
           feedbackBuffer = 0;
    GLuint flatTexture = 0;  ///< 1×1 zero heights (RG32F), for frames without height maps
    GLuint whiteTexture = 0; ///< 1×1 white, for parts without a base-colour texture
    GLint uboAlignment = 256;
    GLint maxRenderbufferSize = 0;

    /// Bytes between consecutive blocks of `size` in one uniform buffer bound by range.
    std::size_t uboStride(std::size_t size) const {
        const auto a = static_cast<std::size_t>(uboAlignment);
        return (size + a - 1) / a * a;
    }
    HeightTargets heights;
    FrameTargets frame;
    std::map<const Model*, GpuModel> models;
    std::map<std::uint64_t, PatternTexture> patterns; ///< by content id
    std::uint64_t useCounter = 0;
    GLuint baseTexture = 0;
    std::uint64_t baseId = 0; ///< content id of what baseTexture holds
    std::optional<HeightKey> lastHeights; ///< what `heights` holds now, if from a height pass
    std::size_t heightPasses = 0, heightPassesSkipped = 0;

    Status init(GlBackend backend);
    void shutdown();
    Status checkGl(const char* what);

    Result<GpuModel*> modelFor(const std::shared_ptr<const Model>& model);
    Result<GLuint> patternTexture(std::uint64_t id, const HeightImage& image, const std::string& field);
    Status ensureHeightTargets(int w, int h);
    Status heightPass(const HeightPassInput& in);
    Status readHeightTargets(HeightMaps& maps);
    Status uploadHeightMaps(const HeightMaps& maps);
    Status ensureFrameTargets(int w, int h, int samples);
    void uploadPalette(const Model& model, const GpuModel& gm, const std::vector<glm::mat4>& world);
    Result<FrameResult> renderFrame(const FrameRequest& req);
    Result<std::vector<SkinnedPart>> skinOnGpu(const std::shared_ptr<const Model>& model,
                                               const std::vector<glm::mat4>& world);
    Result<BlockLayout> blockLayout(const std::string& block);
};

Status Renderer::Impl::checkGl(const char* what) {
    GLenum err = glGetError();
    if (err == GL_NO_ERROR) return Ok{};
    while (glGetError() != GL_NO_ERROR) {
    }
    char buf[16];
    std::snprintf(buf, sizeof buf, "0x%04X", err);
    return makeError(ErrorCode::Internal, kWhere, "", std::string(what) + ": GL error " + buf);
}

Status Renderer::Impl::init(GlBackend backend) {
    auto ctx = GlContext::create(backend, info.tried);
    if (!ctx) return ctx.error();
    context = std::move(*ctx);
    info.backend = std::string(toString(context->backend()));
    info.device = context->device();
    auto str = [](GLenum e) {
        const GLubyte* s = glGetString(e);
        return s ? std::string(reinterpret_cast<const char*>(s)) : std::string();
    };
    info.vendor = str(GL_VENDOR);
    info.renderer = str(GL_RENDERER);
    info.version = str(GL_VERSION);
    info.glslVersion = str(GL_SHADING_LANGUAGE_VERSION);
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &info.maxTextureSize);
    glGetIntegerv(GL_MAX_SAMPLES, &info.maxSamples);
    glGetIntegerv(GL_UNIFORM_BUFFER_OFFSET_ALIGNMENT, &uboAlignment);
    glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &maxRenderbufferSize);
    uboAlignment = std::max(uboAlignment, 16);

    struct Build {
        GLuint* out;
        ProgramDesc desc;
    };
    std::vector<Build> builds = {
        {&heightProgram, {{{GL_VERTEX_SHADER, "heightpass.vert"}, {GL_FRAGMENT_SHADER, "heightpass.frag"}}, {}, {}}},
        {&heightBaseProgram, {{{GL_VERTEX_SHADER, "fullscreen.vert"}, {GL_FRAGMENT_SHADER, "heightbase.frag"}}, {}, {}}},
        {&skinProgram, {{{GL_VERTEX_SHADER, "skin.vert"}, {GL_FRAGMENT_SHADER, "skin.frag"}}, {}, {}}},
        {&skinTessProgram,
         {{{GL_VERTEX_SHADER, "skin.vert"}, {GL_TESS_CONTROL_SHADER, "skin.tesc"},
           {GL_TESS_EVALUATION_SHADER, "skin.tese"}, {GL_FRAGMENT_SHADER, "skin.frag"}},
          {"DERMIS_TESSELLATED"}, {}}},
        {&captureProgram,
         {{{GL_VERTEX_SHADER, "skin.vert"}}, {"DERMIS_CAPTURE"}, {"v_position", "v_normal"}}},
    };
    for (Build& b : builds) {
        auto p = buildProgram(b.desc);
        if (!p) return p.error();
        *b.out = *p;
    }
    glGenVertexArrays(1, &emptyVao);
    GLuint bufs[5];
    glGenBuffers(5, bufs);
    heightUbo = bufs[0];
    frameUbo = bufs[1];
    partUbo = bufs[2];
    paletteSsbo = bufs[3];
    feedbackBuffer = bufs[4];
    glBindBuffer(GL_UNIFORM_BUFFER, frameUbo);
    glBufferData(GL_UNIFORM_BUFFER, sizeof(FrameBlock), nullptr, GL_DYNAMIC_DRAW);
    const float zero[2] = {0.0f, 0.0f};
    flatTexture = makeFloatTexture(1, 1, zero, GL_NEAREST, 2);
    glGenTextures(1, &whiteTexture);
    glBindTexture(GL_TEXTURE_2D, whiteTexture);
    const std::uint8_t white[4] = {255, 255, 255, 255};
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_SRGB8_ALPHA8, 1, 1);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, white);
    return checkGl("initialising the renderer");
}

void Renderer::Impl::shutdown() {
    if (!context) return;
    for (auto& [k, m] : models)
        m.destroy();
    models.clear();
    for (auto& [k, p] : patterns)
        glDeleteTextures(1, &p.tex);
    patterns.clear();
    glDeleteTextures(1, &baseTexture);
    heights.destroy();
    frame.destroy();
    for (GLuint p : {heightProgram, heightBaseProgram, skinProgram, skinTessProgram, captureProgram})
        glDeleteProgram(p);
    GLuint bufs[5] = {heightUbo, frameUbo, partUbo, paletteSsbo, feedbackBuffer};
    glDeleteBuffers(5, bufs);
    glDeleteVertexArrays(1, &emptyVao);
    glDeleteTextures(1, &flatTexture);
    glDeleteTextures(1, &whiteTexture);
    glFinish();
    context.reset();
}

// --- models ---------------------------------------------------------------------------------

Result<GpuModel*> Renderer::Impl::modelFor(const std::shared_ptr<const Model>& model) {
    if (!model) return makeError(ErrorCode::InvalidArgument, kWhere, "model", "no model");
    // Drop models whose owner is gone (their address may be reused by a new model).
    for (auto it = models.begin(); it != models.end();) {
        if (it->second.owner.expired()) {
            it->second.destroy();
            it = models.erase(it);
        } else {
            ++it;
        }
    }
    auto found = models.find(model.get());
    if (found != models.end()) return &found->second;

    const Model& m = *model;
    GpuModel gm;
    gm.owner = model;
    gm.autoDisplacement = autoDisplacementScale(m);
    for (const Image8& img : m.images) {
        GLuint tex = 0;
        glGenTextures(1, &tex);
        glBindTexture(GL_TEXTURE_2D, tex);
        if (img.width > 0 && img.height > 0 &&
            img.rgba.size() == static_cast<std::size_t>(img.width) * img.height * 4) {
            const int levels =
                1 + static_cast<int>(std::floor(std::log2(std::max(img.width, img.height))));
            glTexStorage2D(GL_TEXTURE_2D, levels, GL_SRGB8_ALPHA8, img.width, img.height);
            glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
            glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, img.width, img.height, GL_RGBA,
                            GL_UNSIGNED_BYTE, img.rgba.data());
            glGenerateMipmap(GL_TEXTURE_2D);
            // Bilinear within the nearest mip level: half the fetches of trilinear.
            glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_NEAREST);
        } else {
            const std::uint8_t white[4] = {255, 255, 255, 255};
            glTexStorage2D(GL_TEXTURE_2D, 1, GL_SRGB8_ALPHA8, 1, 1);
            glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, white);
            glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        }
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        gm.textures.push_back(tex);
    }
    for (const MeshPart& part : m.parts) {
        GpuModel::Part gp;
        const std::size_t nv = part.positions.size();
        gp.vertexCount = static_cast<GLsizei>(nv);
        gp.paletteOffset = gm.paletteSize;
        gm.paletteSize += std::max<int>(1, static_cast<int>(part.influences.size()));
        gp.material = part.material;
        gp.hasUVs = part.uvs.size() == nv && nv > 0;

        // Attributes as the CPU skinning reads them: missing normals are computed, missing UVs
        // are zero, a vertex without joint data follows influence 0, out-of-range joints weigh 0.
        std::vector<glm::vec3> normals =
            part.normals.size() == nv ? part.normals : computeNormals(part.positions, part.indices);
        std::vector<glm::vec2> uvs = gp.hasUVs ? part.uvs : std::vector<glm::vec2>(nv, glm::vec2(0.0f));
        std::vector<glm::u16vec4> joints(nv, glm::u16vec4(0));
        std::vector<glm::vec4> weights(nv, glm::vec4(1.0f, 0.0f, 0.0f, 0.0f));
        if (part.joints.size() == nv && part.weights.size() == nv) {
            const std::size_t ni = part.influences.size();
            for (std::size_t v = 0; v < nv; ++v)
                for (int c = 0; c < 4; ++c) {
                    const bool ok = part.joints[v][c] < ni;
                    joints[v][c] = ok ? part.joints[v][c] : 0;
                    weights[v][c] = ok ? part.weights[v][c] : 0.0f;
                }
        }
        std::vector<std::uint32_t> indices;
        indices.reserve(part.indices.size());
        for (std::size_t i = 0; i + 2 < part.indices.size(); i += 3)
            if (part.indices[i] < nv && part.indices[i + 1] < nv && part.indices[i + 2] < nv)
                indices.insert(indices.end(), part.indices.begin() + static_cast<long>(i),
                               part.indices.begin() + static_cast<long>(i) + 3);
        gp.indexCount = static_cast<GLsizei>(indices.size());

        glGenVertexArrays(1, &gp.vao);
        glBindVertexArray(gp.vao);
        glGenBuffers(6, gp.buffers);
        auto attrib = [&](int slot, const void* data, std::size_t bytes, GLint comps, GLenum type,
                          bool integer) {
            glBindBuffer(GL_ARRAY_BUFFER, gp.buffers[slot]);
            glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(bytes), bytes ? data : nullptr,
                         GL_STATIC_DRAW);
            glEnableVertexAttribArray(static_cast<GLuint>(slot));
            if (integer)
                glVertexAttribIPointer(static_cast<GLuint>(slot), comps, type, 0, nullptr);
            else
                glVertexAttribPointer(static_cast<GLuint>(slot), comps, type, GL_FALSE, 0, nullptr);
        };
        attrib(0, part.positions.data(), nv * sizeof(glm::vec3), 3, GL_FLOAT, false);
        attrib(1, normals.data(), nv * sizeof(glm::vec3), 3, GL_FLOAT, false);
        attrib(2, uvs.data(), nv * sizeof(glm::vec2), 2, GL_FLOAT, false);
        attrib(3, joints.data(), nv * sizeof(glm::u16vec4), 4, GL_UNSIGNED_SHORT, true);
        attrib(4, weights.data(), nv * sizeof(glm::vec4), 4, GL_FLOAT, false);
        glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, gp.buffers[5]);
        glBufferData(GL_ELEMENT_ARRAY_BUFFER,
                     static_cast<GLsizeiptr>(indices.size() * sizeof(std::uint32_t)),
                     indices.empty() ? nullptr : indices.data(), GL_STATIC_DRAW);
        glBindVertexArray(0);
        gm.parts.push_back(gp);
    }
    if (auto s = checkGl("uploading a model"); !s) {
        gm.destroy();
        return s.error();
    }
    auto [it, inserted] = models.emplace(model.get(), std::move(gm));
    return &it->second;
}

void Renderer::Impl::uploadPalette(const Model& model, const GpuModel& gm,
                                   const std::vector<glm::mat4>& world) {
    std::vector<glm::mat4> palette(static_cast<std::size_t>(std::max(gm.paletteSize, 1)),
                                   glm::mat4(1.0f));
    for (std::size_t pi = 0; pi < model.parts.size() && pi < gm.parts.size(); ++pi) {
        const MeshPart& part = model.parts[pi];
        const std::size_t base = static_cast<std::size_t>(gm.parts[pi].paletteOffset);
        for (std::size_t k = 0; k < part.influences.size(); ++k) {
            const Influence& inf = part.influences[k];
            const bool valid = inf.node >= 0 && static_cast<std::size_t>(inf.node) < world.size();
            palette[base + k] =
                (valid ? world[static_cast<std::size_t>(inf.node)] : glm::mat4(1.0f)) * inf.inverseBind;
        }
    }
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, paletteSsbo);
    glBufferData(GL_SHADER_STORAGE_BUFFER,
                 static_cast<GLsizeiptr>(palette.size() * sizeof(glm::mat4)), palette.data(),
                 GL_STREAM_DRAW);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kPaletteBinding, paletteSsbo);
}

// --- height pass -----------------------------------------------------------------------------

Result<GLuint> Renderer::Impl::patternTexture(std::uint64_t id, const HeightImage& image,
                                              const std::string& field) {
    ++useCounter;
    if (auto it = patterns.find(id); it != patterns.end()) {
        it->second.lastUse = useCounter;
        return it->second.tex;
    }
    if (image.width > info.maxTextureSize || image.height > info.maxTextureSize)
        return makeError(ErrorCode::InvalidArgument, kWhere, field,
                         "pattern is larger than the GL's maximum texture size " +
                             std::to_string(info.maxTextureSize));
    // Bounded cache: drop the least recently used texture beyond kMaxPatternTextures.
    constexpr std::size_t kMaxPatternTextures = 256;
    if (patterns.size() >= kMaxPatternTextures) {
        auto oldest = std::min_element(patterns.begin(), patterns.end(), [](const auto& a, const auto& b) {
            return a.second.lastUse < b.second.lastUse;
        });
        glDeleteTextures(1, &oldest->second.tex);
        patterns.erase(oldest);
    }
    PatternTexture pt;
    pt.tex = makeFloatTexture(image.width, image.height, image.data.data(), GL_NEAREST);
    pt.lastUse = useCounter;
    patterns[id] = pt;
    return pt.tex;
}

Status Renderer::Impl::ensureHeightTargets(int w, int h) {
    if (heights.fbo && heights.width == w && heights.height == h) return Ok{};
    heights.destroy();
    lastHeights.reset();
    heights.width = w;
    heights.height = h;
    heights.maps = makeFloatTexture(w, h, nullptr, GL_LINEAR, 2);
    glGenFramebuffers(1, &heights.fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, heights.fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, heights.maps, 0);
    const GLenum buf = GL_COLOR_ATTACHMENT0;
    glDrawBuffers(1, &buf);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
        heights.destroy();
        return makeError(ErrorCode::Internal, kWhere, "/heightmap/size",
                         "the GL cannot render into an RG32F target of this size");
    }
    return checkGl("creating the height-map targets");
}

Status Renderer::Impl::heightPass(const HeightPassInput& in) {
    const int W = in.width, H = in.height;
    if (W <= 0 || H <= 0 || W > kMaxHeightmapSize || H > kMaxHeightmapSize ||
        W > info.maxTextureSize || H > info.maxTextureSize)
        return makeError(ErrorCode::InvalidArgument, kWhere, "/heightmap/size",
                         "each side must be in [1, " +
                             std::to_string(std::min(kMaxHeightmapSize, info.maxTextureSize)) + "]");
    // Resolve each placement's texture first, so that a bad input changes nothing.
    std::vector<GLuint> textures(in.placements.size(), 0);
    std::vector<std::uint64_t> ids(in.placements.size(), 0);
    for (std::size_t k = 0; k < in.placements.size(); ++k) {
        const BakePlacement& p = in.placements[k];
        const std::string field = "/placements/" + std::to_string(k);
        const HeightImage* img = p.pattern;
        if (!img || img->width <= 0 || img->height <= 0 ||
            img->data.size() != static_cast<std::size_t>(img->width) * img->height)
            return makeError(ErrorCode::InvalidArgument, kWhere, field + "/pattern", "no pattern image");
        if (!(p.footprint.scale.x > 0.0) || !(p.footprint.scale.y > 0.0))
            return makeError(ErrorCode::InvalidArgument, kWhere, field + "/scale", "must be > 0");
        if (p.t <= 0.0) continue; // contributes nothing (as on the CPU)
        ids[k] = p.patternId ? p.patternId : contentHash(*img);
        auto tex = patternTexture(ids[k], *img, field + "/pattern");
        if (!tex) return tex.error();
        textures[k] = *tex;
    }
    const HeightImage* base = in.base;
    std::uint64_t baseKey = 0;
    if (base) {
        if (base->width <= 0 || base->height <= 0 ||
            base->data.size() != static_cast<std::size_t>(base->width) * base->height ||
            base->width > info.maxTextureSize || base->height > info.maxTextureSize)
            return makeError(ErrorCode::InvalidArgument, kWhere, "/heightmap/base", "empty or oversized base map");
        baseKey = in.baseId ? in.baseId : contentHash(*base);
        if (baseKey != baseId || !baseTexture) {
            glDeleteTextures(1, &baseTexture);
            baseTexture = makeFloatTexture(base->width, base->height, base->data.data(), GL_NEAREST);
            baseId = baseKey;
        }
    }
    if (auto s = ensureHeightTargets(W, H); !s) return s;

    HeightKey key;
    key.width = W;
    key.height = H;
    key.base = baseKey;
    key.patterns = ids;
    for (std::size_t k = 0; k < in.placements.size(); ++k) {
        if (!textures[k]) continue;
        const BakePlacement& p = in.placements[k];
        key.params.insert(key.params.end(),
                          {p.footprint.center.x, p.footprint.center.y, p.footprint.scale.x,
                           p.footprint.scale.y, p.footprint.rotationDeg, p.h, p.t,
                           double(static_cast<int>(p.model)), double(static_cast<int>(p.target)),
                           double(static_cast<int>(p.response))});
    }
    if (lastHeights && *lastHeights == key) {
        ++heightPassesSkipped;
        return Ok{};
    }
    lastHeights.reset();

    // One block per placement in one buffer, bound by range per draw.
    const std::size_t stride = uboStride(sizeof(HeightPassBlock));
    const std::size_t count = in.placements.size() + 1;
    std::vector<std::uint8_t> blocks(stride * count, 0);
    const glm::vec4 mapSize(static_cast<float>(W), static_cast<float>(H), 0.0f, 0.0f);
    {
        HeightPassBlock b{};
        b.mapSize = mapSize;
        std::memcpy(blocks.data(), &b, sizeof b); // slot 0: the base draw
    }
    for (std::size_t k = 0; k < in.placements.size(); ++k) {
        const BakePlacement& p = in.placements[k];
        HeightPassBlock b{};
        const double a = glm::radians(p.footprint.rotationDeg);
        b.centerScale = glm::vec4(p.footprint.center.x, p.footprint.center.y, p.footprint.scale.x,
                                  p.footprint.scale.y);
        // The quad reaches 1.5 texels beyond the footprint on every side (in pattern units).
        const double texel = 1.5 * std::max(1.0 / W, 1.0 / H);
        b.rotation = glm::vec4(std::cos(a), std::sin(a), texel / p.footprint.scale.x,
                               texel / p.footprint.scale.y);
        b.drive = glm::vec4(static_cast<float>(p.h), static_cast<float>(p.t), 0.0f, 0.0f);
        b.mode = glm::ivec4(p.model == DeformModel::Scale ? 0 : 1,
                            p.target == Target::Bump ? 0 : 1, static_cast<int>(p.response), 0);
        b.mapSize = mapSize;
        if (p.pattern) {
            b.mapSize.z = static_cast<float>(p.pattern->width);
            b.mapSize.w = static_cast<float>(p.pattern->height);
        }
        std::memcpy(blocks.data() + stride * (k + 1), &b, sizeof b);
    }
    glBindBuffer(GL_UNIFORM_BUFFER, heightUbo);
    glBufferData(GL_UNIFORM_BUFFER, static_cast<GLsizeiptr>(blocks.size()), blocks.data(),
                 GL_STREAM_DRAW);

    glBindFramebuffer(GL_FRAMEBUFFER, heights.fbo);
    glViewport(0, 0, W, H);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    glDisable(GL_FRAMEBUFFER_SRGB);
    glDisable(GL_MULTISAMPLE);
    glDisable(GL_BLEND);
    glBindVertexArray(emptyVao);
    const float zero[4] = {0, 0, 0, 0};
    if (base) {
        glUseProgram(heightBaseProgram);
        glBindBufferRange(GL_UNIFORM_BUFFER, kHeightPassBinding, heightUbo, 0, sizeof(HeightPassBlock));
        glActiveTexture(GL_TEXTURE0);
        glBindTexture(GL_TEXTURE_2D, baseTexture);
        glDrawArrays(GL_TRIANGLES, 0, 3);
    } else {
        glClearBufferfv(GL_COLOR, 0, zero);
    }
    // Additive blending sums placements in document order, like the CPU reference.
    glEnable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    glBlendFunc(GL_ONE, GL_ONE);
    glUseProgram(heightProgram);
    glActiveTexture(GL_TEXTURE0);
    for (std::size_t k = 0; k < in.placements.size(); ++k) {
        if (!textures[k]) continue;
        glBindBufferRange(GL_UNIFORM_BUFFER, kHeightPassBinding, heightUbo,
                          static_cast<GLintptr>(stride * (k + 1)), sizeof(HeightPassBlock));
        glBindTexture(GL_TEXTURE_2D, textures[k]);
        glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
    }
    glDisable(GL_BLEND);
    if (auto st = checkGl("height pass"); !st) return st;
    lastHeights = std::move(key);
    ++heightPasses;
    return Ok{};
}

Status Renderer::Impl::readHeightTargets(HeightMaps& maps) {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, heights.fbo);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    for (auto [image, channel] : {std::pair{&maps.bump, GL_RED},
                                  std::pair{&maps.displacement, GL_GREEN}}) {
        *image = HeightImage(heights.width, heights.height);
        glReadPixels(0, 0, heights.width, heights.height, channel, GL_FLOAT, image->data.data());
    }
    return checkGl("reading the height maps back");
}

Status Renderer::Impl::uploadHeightMaps(const HeightMaps& maps) {
    const int W = maps.bump.width, H = maps.bump.height;
    if (W <= 0 || H <= 0 || maps.displacement.width != W || maps.displacement.height != H ||
        maps.bump.data.size() != static_cast<std::size_t>(W) * H ||
        maps.displacement.data.size() != static_cast<std::size_t>(W) * H)
        return makeError(ErrorCode::InvalidArgument, kWhere, "cpuMaps",
                         "bump and displacement maps must be non-empty and of one size");
    if (auto s = ensureHeightTargets(W, H); !s) return s;
    lastHeights.reset(); // the targets now hold CPU maps
    const std::size_t n = static_cast<std::size_t>(W) * H;
    heights.staging.resize(2 * n);
    const float* b = maps.bump.data.data();
    const float* d = maps.displacement.data.data();
    float* out = heights.staging.data();
    for (std::size_t i = 0; i < n; ++i) {
        out[2 * i] = b[i];
        out[2 * i + 1] = d[i];
    }
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glBindTexture(GL_TEXTURE_2D, heights.maps);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, W, H, GL_RG, GL_FLOAT, heights.staging.data());
    return checkGl("uploading height maps");
}

// --- skin pass -------------------------------------------------------------------------------

Status Renderer::Impl::ensureFrameTargets(int w, int h, int samples) {
    if (frame.fbo && frame.width == w && frame.height == h && frame.samples == samples) return Ok{};
    frame.destroy();
    frame.width = w;
    frame.height = h;
    frame.samples = samples;
    glGenFramebuffers(1, &frame.fbo);
    glGenRenderbuffers(1, &frame.color);
    glGenRenderbuffers(1, &frame.depth);
    glBindRenderbuffer(GL_RENDERBUFFER, frame.color);
    if (samples > 1)
        glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_SRGB8_ALPHA8, w, h);
    else
        glRenderbufferStorage(GL_RENDERBUFFER, GL_SRGB8_ALPHA8, w, h);
    glBindRenderbuffer(GL_RENDERBUFFER, frame.depth);
    if (samples > 1)
        glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_DEPTH_COMPONENT24, w, h);
    else
        glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, w, h);
    glBindFramebuffer(GL_FRAMEBUFFER, frame.fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, frame.color);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, frame.depth);
    bool complete = glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
    if (samples > 1) {
        glGenFramebuffers(1, &frame.resolveFbo);
        glGenRenderbuffers(1, &frame.resolveColor);
        glBindRenderbuffer(GL_RENDERBUFFER, frame.resolveColor);
        glRenderbufferStorage(GL_RENDERBUFFER, GL_SRGB8_ALPHA8, w, h);
        glBindFramebuffer(GL_FRAMEBUFFER, frame.resolveFbo);
        glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER,
                                  frame.resolveColor);
        complete = complete && glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
    }
    glGenBuffers(1, &frame.pbo);
    frame.pboSize = static_cast<std::size_t>(w) * h * 4;
    glBindBuffer(GL_PIXEL_PACK_BUFFER, frame.pbo);
    glBufferData(GL_PIXEL_PACK_BUFFER, static_cast<GLsizeiptr>(frame.pboSize), nullptr, GL_STREAM_READ);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    if (!complete) {
        frame.destroy();
        return makeError(ErrorCode::Internal, kWhere, "/render/size",
                         "the GL cannot create a " + std::to_string(w) + "x" + std::to_string(h) +
                             " frame with " + std::to_string(samples) + " samples");
    }
    return checkGl("creating the frame targets");
}

Result<FrameResult> Renderer::Impl::renderFrame(const FrameRequest& req) {
    const RenderSettings& rs = req.render;
    const int W = rs.size[0], H = rs.size[1];
    if (auto s = validateRenderSettings(rs, {}, kWhere); !s) return s.error();
    if (W > maxRenderbufferSize || H > maxRenderbufferSize)
        return makeError(ErrorCode::InvalidArgument, kWhere, "/render/size",
                         "each side must be at most the GL's renderbuffer limit " +
                             std::to_string(maxRenderbufferSize));
    if (!req.model) return makeError(ErrorCode::InvalidArgument, kWhere, "model", "no model");
    const Model& model = *req.model;

    FrameResult out;
    auto gm = modelFor(req.model);
    if (!gm) return gm.error();

    // Stage 1: the height maps this frame samples.
    auto t0 = std::chrono::steady_clock::now();
    GLuint heightTex = flatTexture;
    glm::vec2 hmSize(1.0f);
    if (req.heights) {
        if (auto s = heightPass(*req.heights); !s) return s.error();
        heightTex = heights.maps;
        hmSize = glm::vec2(heights.width, heights.height);
        if (req.readHeightMaps) {
            HeightMaps maps;
            if (auto s = readHeightTargets(maps); !s) return s.error();
            out.maps = std::move(maps);
        }
    } else if (req.cpuMaps) {
        if (auto s = uploadHeightMaps(*req.cpuMaps); !s) return s.error();
        heightTex = heights.maps;
        hmSize = glm::vec2(heights.width, heights.height);
    }
    if (req.profile) glFinish();
    out.timings.heightMs = msSince(t0);

    // Stage 2: skin, displace, shade.
    t0 = std::chrono::steady_clock::now();
    const int samples = std::min(rs.msaa, std::max(1, info.maxSamples));
    if (auto s = ensureFrameTargets(W, H, samples); !s) return s.error();
    uploadPalette(model, **gm, req.world);

    const double dispScale = rs.displacementScale ? *rs.displacementScale : (*gm)->autoDisplacement;
    const double bumpScale = 0.25 * (*gm)->autoDisplacement * rs.bumpStrength;

    // Orbit camera framed on the posed bounds (CPU skinning of the same pose: cheap at these
    // sizes), widened by the largest displacement a unit height can add.
    const auto [lo, hi] = boundsOf(skin(model, req.world));
    out.boundsMin = lo;
    out.boundsMax = hi;
    const glm::vec3 centre = 0.5f * (lo + hi);
    const float radius = std::max(0.5f * glm::length(hi - lo) + static_cast<float>(dispScale), 1e-4f);
    const float fovY = glm::radians(30.0f), aspect = static_cast<float>(W) / static_cast<float>(H);
    const float fovX = 2.0f * std::atan(std::tan(fovY * 0.5f) * aspect);
    const float distance = rs.camera.distance
                               ? static_cast<float>(*rs.camera.distance)
                               : radius / std::sin(0.5f * std::min(fovX, fovY)) * 1.02f;
    const float yaw = glm::radians(static_cast<float>(rs.camera.yaw));
    const float pitch = glm::radians(static_cast<float>(rs.camera.pitch));
    const glm::vec3 dir(std::sin(yaw) * std::cos(pitch), std::sin(pitch), std::cos(yaw) * std::cos(pitch));
    const glm::vec3 eye = centre + dir * distance;
    const glm::vec3 up = std::abs(dir.y) > 0.999f ? glm::vec3(0, 0, -dir.y) : glm::vec3(0, 1, 0);
    const glm::mat4 view = glm::lookAt(eye, centre, up);
    const float zNear = std::max({distance - radius * 1.5f, distance * 0.01f, 1e-4f});
    const float zFar = distance + radius * 1.5f;
    // Flip y so that GL's first row (bottom) holds the top of the picture: readback is row 0 first.
    const glm::mat4 proj = glm::scale(glm::mat4(1.0f), glm::vec3(1.0f, -1.0f, 1.0f)) *
                           glm::perspective(fovY, aspect, zNear, zFar);
    FrameBlock fb{};
    fb.viewProj = proj * view;
    fb.cameraPos = glm::vec4(eye, 0.0f);
    const glm::vec3 right = glm::normalize(glm::cross(-dir, up));
    const glm::vec3 camUp = glm::cross(right, -dir);
    fb.lightDir = glm::vec4(glm::normalize(-0.45f * right + 0.65f * camUp + 0.6f * dir), 0.3f);
    fb.heights = glm::vec4(static_cast<float>(dispScale), static_cast<float>(bumpScale), 0.0f, 0.0f);
    fb.heightmapSize = glm::vec4(hmSize, 1.0f / hmSize.x, 1.0f / hmSize.y);
    fb.viewport = glm::vec4(static_cast<float>(W), static_cast<float>(H), 6.0f, 16.0f);
    glBindBuffer(GL_UNIFORM_BUFFER, frameUbo);
    glBufferSubData(GL_UNIFORM_BUFFER, 0, sizeof fb, &fb);
    glBindBufferBase(GL_UNIFORM_BUFFER, kFrameBinding, frameUbo);

    const std::size_t stride = uboStride(sizeof(PartBlock));
    std::vector<std::uint8_t> partBlocks(stride * std::max<std::size_t>(1, (*gm)->parts.size()), 0);
    for (std::size_t pi = 0; pi < (*gm)->parts.size(); ++pi) {
        const GpuModel::Part& gp = (*gm)->parts[pi];
        PartBlock pb{};
        pb.baseColor = glm::vec4(0.80f, 0.62f, 0.54f, 1.0f); // skin tone when there is no material
        bool textured = false;
        if (gp.material >= 0 && static_cast<std::size_t>(gp.material) < model.materials.size()) {
            const Material& mat = model.materials[static_cast<std::size_t>(gp.material)];
            pb.baseColor = mat.baseColorFactor;
            textured = mat.baseColorTexture >= 0 &&
                       static_cast<std::size_t>(mat.baseColorTexture) < (*gm)->textures.size();
        }
        pb.part = glm::ivec4(gp.paletteOffset, textured ? 1 : 0, gp.hasUVs ? 1 : 0, 0);
        std::memcpy(partBlocks.data() + stride * pi, &pb, sizeof pb);
    }
    glBindBuffer(GL_UNIFORM_BUFFER, partUbo);
    glBufferData(GL_UNIFORM_BUFFER, static_cast<GLsizeiptr>(partBlocks.size()), partBlocks.data(),
                 GL_STREAM_DRAW);

    glBindFramebuffer(GL_FRAMEBUFFER, frame.fbo);
    glViewport(0, 0, W, H);
    glEnable(GL_FRAMEBUFFER_SRGB);
    if (samples > 1) glEnable(GL_MULTISAMPLE);
    else glDisable(GL_MULTISAMPLE);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDisable(GL_CULL_FACE);
    glDisable(GL_BLEND);
    const float background[4] = {0.046f, 0.054f, 0.066f, 1.0f}; // linear; a dark blue-grey
    const float one = 1.0f;
    glClearBufferfv(GL_COLOR, 0, background);
    glClearBufferfv(GL_DEPTH, 0, &one);
    const bool tess = rs.displacement == DisplacementMode::Tessellated;
    glUseProgram(tess ? skinTessProgram : skinProgram);
    if (tess) glPatchParameteri(GL_PATCH_VERTICES, 3);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, heightTex);
    for (std::size_t pi = 0; pi < (*gm)->parts.size(); ++pi) {
        const GpuModel::Part& gp = (*gm)->parts[pi];
        if (gp.indexCount == 0) continue;
        glBindBufferRange(GL_UNIFORM_BUFFER, kPartBinding, partUbo,
                          static_cast<GLintptr>(stride * pi), sizeof(PartBlock));
        glActiveTexture(GL_TEXTURE2);
        GLuint colorTex = whiteTexture;
        if (gp.material >= 0 && static_cast<std::size_t>(gp.material) < model.materials.size()) {
            const int ti = model.materials[static_cast<std::size_t>(gp.material)].baseColorTexture;
            if (ti >= 0 && static_cast<std::size_t>(ti) < (*gm)->textures.size())
                colorTex = (*gm)->textures[static_cast<std::size_t>(ti)];
        }
        glBindTexture(GL_TEXTURE_2D, colorTex);
        glBindVertexArray(gp.vao);
        glDrawElements(tess ? GL_PATCHES : GL_TRIANGLES, gp.indexCount, GL_UNSIGNED_INT, nullptr);
    }
    glBindVertexArray(0);
    GLuint readFbo = frame.fbo;
    if (samples > 1) {
        glBindFramebuffer(GL_READ_FRAMEBUFFER, frame.fbo);
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, frame.resolveFbo);
        glBlitFramebuffer(0, 0, W, H, 0, 0, W, H, GL_COLOR_BUFFER_BIT, GL_NEAREST);
        readFbo = frame.resolveFbo;
    }
    glDisable(GL_FRAMEBUFFER_SRGB);
    if (auto s = checkGl("skin pass"); !s) return s.error();
    if (req.profile) glFinish();
    out.timings.skinMs = msSince(t0);

    // Readback through the pixel-pack buffer.
    t0 = std::chrono::steady_clock::now();
    glBindFramebuffer(GL_READ_FRAMEBUFFER, readFbo);
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, frame.pbo);
    glReadPixels(0, 0, W, H, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
    out.image.width = W;
    out.image.height = H;
    out.image.rgba.resize(frame.pboSize);
    const void* mapped = glMapBufferRange(GL_PIXEL_PACK_BUFFER, 0,
                                          static_cast<GLsizeiptr>(frame.pboSize), GL_MAP_READ_BIT);
    if (!mapped) {
        glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
        return makeError(ErrorCode::Internal, kWhere, "", "cannot map the pixel-pack buffer");
    }
    std::memcpy(out.image.rgba.data(), mapped, frame.pboSize);
    glUnmapBuffer(GL_PIXEL_PACK_BUFFER);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    out.timings.readbackMs = msSince(t0);
    if (auto s = checkGl("frame readback"); !s) return s.error();
    return out;
}

Result<std::vector<SkinnedPart>> Renderer::Impl::skinOnGpu(const std::shared_ptr<const Model>& model,
                                                           const std::vector<glm::mat4>& world) {
    auto gm = modelFor(model);
    if (!gm) return gm.error();
    uploadPalette(*model, **gm, world);
    glUseProgram(captureProgram);
    glEnable(GL_RASTERIZER_DISCARD);
    std::vector<SkinnedPart> out((*gm)->parts.size());
    PartBlock pb{};
    glBindBuffer(GL_UNIFORM_BUFFER, partUbo);
    for (std::size_t pi = 0; pi < (*gm)->parts.size(); ++pi) {
        const GpuModel::Part& gp = (*gm)->parts[pi];
        const std::size_t nv = static_cast<std::size_t>(gp.vertexCount);
        if (nv == 0) continue;
        pb.part = glm::ivec4(gp.paletteOffset, 0, 0, 0);
        glBindBuffer(GL_UNIFORM_BUFFER, partUbo);
        glBufferData(GL_UNIFORM_BUFFER, sizeof pb, &pb, GL_STREAM_DRAW);
        glBindBufferBase(GL_UNIFORM_BUFFER, kPartBinding, partUbo);
        const std::size_t bytes = nv * 6 * sizeof(float);
        glBindBuffer(GL_TRANSFORM_FEEDBACK_BUFFER, feedbackBuffer);
        glBufferData(GL_TRANSFORM_FEEDBACK_BUFFER, static_cast<GLsizeiptr>(bytes), nullptr, GL_STREAM_READ);
        glBindBufferBase(GL_TRANSFORM_FEEDBACK_BUFFER, 0, feedbackBuffer);
        glBindVertexArray(gp.vao);
        glBeginTransformFeedback(GL_POINTS);
        glDrawArrays(GL_POINTS, 0, gp.vertexCount);
        glEndTransformFeedback();
        glBindVertexArray(0);
        std::vector<float> data(nv * 6);
        glGetBufferSubData(GL_TRANSFORM_FEEDBACK_BUFFER, 0, static_cast<GLsizeiptr>(bytes), data.data());
        out[pi].positions.resize(nv);
        out[pi].normals.resize(nv);
        for (std::size_t v = 0; v < nv; ++v) {
            out[pi].positions[v] = glm::vec3(data[v * 6], data[v * 6 + 1], data[v * 6 + 2]);
            out[pi].normals[v] = glm::vec3(data[v * 6 + 3], data[v * 6 + 4], data[v * 6 + 5]);
        }
    }
    glDisable(GL_RASTERIZER_DISCARD);
    if (auto s = checkGl("transform feedback skinning"); !s) return s.error();
    return out;
}

Result<Renderer::BlockLayout> Renderer::Impl::blockLayout(const std::string& block) {
    GLuint program = block == "HeightPassBlock" ? heightProgram : skinTessProgram;
    const GLuint index = glGetUniformBlockIndex(program, block.c_str());
    if (index == GL_INVALID_INDEX)
        return makeError(ErrorCode::NotFound, kWhere, block, "no such uniform block");
    BlockLayout layout;
    glGetActiveUniformBlockiv(program, index, GL_UNIFORM_BLOCK_DATA_SIZE, &layout.size);
    GLint n = 0;
    glGetActiveUniformBlockiv(program, index, GL_UNIFORM_BLOCK_ACTIVE_UNIFORMS, &n);
    std::vector<GLint> indices(static_cast<std::size_t>(n));
    glGetActiveUniformBlockiv(program, index, GL_UNIFORM_BLOCK_ACTIVE_UNIFORM_INDICES, indices.data());
    for (GLint ui : indices) {
        const GLuint u = static_cast<GLuint>(ui);
        char name[128] = {};
        GLsizei len = 0;
        glGetActiveUniformName(program, u, sizeof name, &len, name);
        GLint offset = -1;
        glGetActiveUniformsiv(program, 1, &u, GL_UNIFORM_OFFSET, &offset);
        layout.offsets.emplace_back(name, offset);
    }
    return layout;
}

FrameRequest frameRequest(const FramePlan& plan, std::shared_ptr<const Model> model) {
    FrameRequest req;
    req.model = std::move(model);
    req.world = plan.world;
    req.render = plan.render;
    req.heights = plan.heights;
    return req;
}

// --- public façade: every call runs on the render thread ----------------------------------------

Renderer::Renderer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

Result<std::unique_ptr<Renderer>> Renderer::create(GlBackend backend) {
    auto impl = std::make_unique<Impl>();
    std::promise<Status> started;
    std::future<Status> startedFuture = started.get_future();
    Impl* raw = impl.get();
    raw->thread = std::thread([raw, backend, started = std::move(started)]() mutable {
        Status s = raw->init(backend);
        const bool ok = static_cast<bool>(s);
        if (!ok) raw->shutdown();
        started.set_value(std::move(s));
        if (!ok) return;
        raw->loop();
        raw->shutdown();
    });
    Status s = startedFuture.get();
    if (!s) {
        raw->thread.join();
        return s.error();
    }
    return std::unique_ptr<Renderer>(new Renderer(std::move(impl)));
}

Renderer::~Renderer() {
    {
        std::lock_guard<std::mutex> lock(impl_->mutex);
        impl_->stopping = true;
    }
    impl_->cv.notify_all();
    if (impl_->thread.joinable()) impl_->thread.join();
}

const RendererInfo& Renderer::info() const { return impl_->info; }

Result<HeightMaps> Renderer::bakeHeightMaps(const HeightPassInput& in) {
    return impl_->run([&]() -> Result<HeightMaps> {
        if (auto s = impl_->heightPass(in); !s) return s.error();
        HeightMaps maps;
        if (auto s = impl_->readHeightTargets(maps); !s) return s.error();
        return maps;
    });
}

Result<FrameResult> Renderer::renderFrame(const FrameRequest& request) {
    return impl_->run([&] { return impl_->renderFrame(request); });
}

Result<std::vector<SkinnedPart>> Renderer::skinOnGpu(const std::shared_ptr<const Model>& model,
                                                     const std::vector<glm::mat4>& world) {
    return impl_->run([&] { return impl_->skinOnGpu(model, world); });
}

void Renderer::forgetPatterns() {
    impl_->run([&] {
        for (auto& [k, p] : impl_->patterns)
            glDeleteTextures(1, &p.tex);
        impl_->patterns.clear();
        glDeleteTextures(1, &impl_->baseTexture);
        impl_->baseTexture = 0;
        impl_->baseId = 0;
        impl_->lastHeights.reset();
        return 0;
    });
}

Renderer::Stats Renderer::stats() {
    return impl_->run([&] { return Stats{impl_->heightPasses, impl_->heightPassesSkipped}; });
}

Result<Renderer::BlockLayout> Renderer::blockLayout(const std::string& block) {
    return impl_->run([&] { return impl_->blockLayout(block); });
}

} // namespace dermis
