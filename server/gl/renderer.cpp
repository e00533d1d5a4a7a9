// The GPU renderer's façade: the render thread and its job queue, GL start-up and shutdown,
// introspection. The stages live in gpu_model.cpp, height_pass.cpp and frame_pass.cpp.
#include "renderer_impl.hpp"

#include "core/frame_plan.hpp"

#include "programs.hpp"
#include "uniform_blocks.hpp"

#include <algorithm>
#include <cstdio>
#include <system_error>
#include <utility>

namespace dermis {

using namespace gl;

GLuint gl::makeFloatTexture(int w, int h, const float* data, GLint filter, int channels) {
    GLuint tex = 0;
    glGenTextures(1, &tex);
    glBindTexture(GL_TEXTURE_2D, tex);
    const GLenum internal = channels == 3 ? GL_RGB32F : channels == 2 ? GL_RG32F : GL_R32F;
    const GLenum format = channels == 3 ? GL_RGB : channels == 2 ? GL_RG : GL_RED;
    glTexStorage2D(GL_TEXTURE_2D, 1, internal, w, h);
    if (data) {
        glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
        glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, w, h, format, GL_FLOAT, data);
    }
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, filter);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, filter);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    return tex;
}

// --- job queue ------------------------------------------------------------------------------------

void Renderer::Impl::loop() {
    for (;;) {
        std::function<void()> job;
        {
            std::unique_lock<std::mutex> lock(mutex);
            cv.wait(lock, [&] { return stopping || !jobs.empty(); });
            if (jobs.empty()) return; // stopping and drained
            job = std::move(jobs.front());
            jobs.pop_front();
        }
        ++useCounter;
        job();
    }
}

void Renderer::Impl::checkDrawBindings(const char* draw) {
    if (!checkBindings || !bindingProblem.empty()) return;
    GLint current = 0;
    glGetIntegerv(GL_CURRENT_PROGRAM, &current);
    if (current == 0) {
        bindingProblem = std::string(draw) + ": no program in use";
        return;
    }
    const auto program = static_cast<GLuint>(current);
    GLint readBefore = 0;
    glGetIntegerv(GL_COPY_READ_BUFFER_BINDING, &readBefore);
    struct Kind {
        GLenum iface, binding, start, size;
        const char* name;
    };
    const Kind kinds[2] = {
        {GL_UNIFORM_BLOCK, GL_UNIFORM_BUFFER_BINDING, GL_UNIFORM_BUFFER_START,
         GL_UNIFORM_BUFFER_SIZE, "uniform block"},
        {GL_SHADER_STORAGE_BLOCK, GL_SHADER_STORAGE_BUFFER_BINDING, GL_SHADER_STORAGE_BUFFER_START,
         GL_SHADER_STORAGE_BUFFER_SIZE, "storage block"}};
    for (const Kind& kind : kinds) {
        GLint count = 0;
        glGetProgramInterfaceiv(program, kind.iface, GL_ACTIVE_RESOURCES, &count);
        for (GLint i = 0; i < count && bindingProblem.empty(); ++i) {
            const GLenum props[2] = {GL_BUFFER_BINDING, GL_BUFFER_DATA_SIZE};
            GLint value[2] = {0, 0};
            glGetProgramResourceiv(program, kind.iface, static_cast<GLuint>(i), 2, props, 2, nullptr,
                                   value);
            char name[64] = {};
            glGetProgramResourceName(program, kind.iface, static_cast<GLuint>(i), sizeof name,
                                     nullptr, name);
            const auto index = static_cast<GLuint>(value[0]);
            GLint buffer = 0;
            GLint64 start = 0, size = 0, store = 0;
            glGetIntegeri_v(kind.binding, index, &buffer);
            glGetInteger64i_v(kind.start, index, &start);
            glGetInteger64i_v(kind.size, index, &size);
            if (buffer != 0) {
                glBindBuffer(GL_COPY_READ_BUFFER, static_cast<GLuint>(buffer));
                glGetBufferParameteri64v(GL_COPY_READ_BUFFER, GL_BUFFER_SIZE, &store);
            }
            const GLint64 range = size != 0 ? size : store - start; // base binding: the whole store
            if (buffer == 0 || range < value[1] || start + range > store)
                bindingProblem = std::string(draw) + ": " + kind.name + " " + name + " (binding " +
                                 std::to_string(value[0]) + ", " + std::to_string(value[1]) +
                                 " bytes) has buffer " + std::to_string(buffer) + " range [" +
                                 std::to_string(start) + ", " + std::to_string(start + range) +
                                 ") of a " + std::to_string(store) + "-byte store";
        }
    }
    glBindBuffer(GL_COPY_READ_BUFFER, static_cast<GLuint>(readBefore));
}

// --- life cycle (render thread) ----------------------------------------------------------------

Status Renderer::Impl::checkGl(const char* what) {
    GLenum err = glGetError();
    if (err != GL_NO_ERROR)
        while (glGetError() != GL_NO_ERROR) {
        }
    if (!bindingProblem.empty()) {
        std::string problem = std::move(bindingProblem);
        bindingProblem.clear();
        return makeError(ErrorCode::Internal, kWhere, "", problem); // names the draw
    }
    if (err == GL_NO_ERROR) return Ok{};
    char buf[16];
    std::snprintf(buf, sizeof buf, "0x%04X", err);
    return makeError(ErrorCode::Internal, kWhere, "", std::string(what) + ": GL error " + buf);
}

Status Renderer::Impl::init(GlBackend backend) {
    auto t0 = std::chrono::steady_clock::now();
    auto ctx = GlContext::create(backend, info.tried);
    if (!ctx) return ctx.error();
    context = std::move(*ctx);
    readDriverInfo();
    info.contextMs = msSince(t0);
    t0 = std::chrono::steady_clock::now();
    if (auto s = buildPrograms(); !s) return s;
    createSharedObjects();
    info.programsMs = msSince(t0);
    return checkGl("initialising the renderer");
}

namespace {

/// Mesa's software rasterizers, by GL_RENDERER ("llvmpipe (LLVM 15.0.6, 256 bits)").
bool softwareRasterizer(const std::string& glRenderer) {
    return glRenderer.find("llvmpipe") != std::string::npos ||
           glRenderer.find("softpipe") != std::string::npos ||
           glRenderer.find("swrast") != std::string::npos;
}

} // namespace

void Renderer::Impl::readDriverInfo() {
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
    info.software = softwareRasterizer(info.renderer);
    glGetIntegerv(GL_UNIFORM_BUFFER_OFFSET_ALIGNMENT, &uboAlignment);
    glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &maxRenderbufferSize);
    uboAlignment = std::max(uboAlignment, 16);
}

Status Renderer::Impl::buildPrograms() {
    struct Build {
        GLuint* out;
        ProgramDesc desc;
    };
    std::vector<Build> builds = {
        {&heightProgram, {{{GL_VERTEX_SHADER, "heightpass.vert"}, {GL_FRAGMENT_SHADER, "heightpass.frag"}}, {}, {}, {}}},
        {&heightSurfaceProgram,
         {{{GL_VERTEX_SHADER, "heightpass.vert"}, {GL_FRAGMENT_SHADER, "heightpass.frag"}}, {"DERMIS_SURFACE"}, {}, {}}},
        {&heightBaseProgram, {{{GL_VERTEX_SHADER, "fullscreen.vert"}, {GL_FRAGMENT_SHADER, "heightbase.frag"}}, {}, {}, {}}},
        {&captureProgram,
         {{{GL_VERTEX_SHADER, "skin.vert"}}, {"DERMIS_CAPTURE"}, {"v_position", "v_normal"}, {}}},
        {&depthProgram,
         {{{GL_VERTEX_SHADER, "skin.vert"}, {GL_FRAGMENT_SHADER, "shadow.frag"}}, {"DERMIS_PBR"}, {},
          {{GL_FRAGMENT_SHADER, "pbr.glsl"}}}},
        {&depthMaskProgram,
         {{{GL_VERTEX_SHADER, "skin.vert"}, {GL_FRAGMENT_SHADER, "shadow.frag"}}, {"DERMIS_PBR", "DERMIS_MASK"}, {},
          {{GL_FRAGMENT_SHADER, "pbr.glsl"}}}},
    };
    for (Build& b : builds) {
        auto p = buildProgram(b.desc);
        if (!p) return p.error();
        *b.out = *p;
    }
    for (bool tess : {false, true}) {
        for (FrameView view : {FrameView::Shaded, FrameView::Bump, FrameView::Displacement, FrameView::Normal})
            if (auto p = buildSkinProgram(tess, view); !p) return p.error();
            else skinPrograms[tess ? 1 : 0][static_cast<int>(view)] = *p;
        if (auto p = skinProgram(tess, FrameView::Shaded, true); !p) return p.error();
    }
    return Ok{};
}

Result<GLuint> Renderer::Impl::skinProgram(bool tess, FrameView view, bool pbr, bool skinShading,
                                           bool keyLight, bool maps, bool outlines) {
    if (!pbr) return skinPrograms[tess ? 1 : 0][static_cast<int>(view)];
    // The skin shading's program draws its shaded view only; its other views are pbr's.
    const unsigned variant = (tess ? kPbrTess : 0u) | (skinShading ? kPbrSkin : 0u) |
                             (keyLight ? kPbrKeyLight : 0u) | (maps ? kPbrMaps : 0u) |
                             (view != FrameView::Shaded ? kPbrViews : 0u) |
                             (outlines ? kPbrOutlines : 0u);
    GLuint& p = pbrPrograms[variant];
    if (!p) {
        auto built = buildSkinProgram(tess, FrameView::Shaded, true, variant);
        if (!built) return built.error();
        p = *built;
    }
    return p;
}

Result<GLuint> Renderer::Impl::buildSkinProgram(bool tess, FrameView view, bool pbr, unsigned variant) {
    ProgramDesc desc;
    desc.stages = {{GL_VERTEX_SHADER, "skin.vert"}};
    if (tess) {
        desc.stages.push_back({GL_TESS_CONTROL_SHADER, "skin.tesc"});
        desc.stages.push_back({GL_TESS_EVALUATION_SHADER, "skin.tese"});
        desc.defines.push_back("DERMIS_TESSELLATED");
    }
    desc.stages.push_back({GL_FRAGMENT_SHADER, "skin.frag"});
    desc.defines.push_back("DERMIS_VIEW " + std::to_string(static_cast<int>(view)));
    if (!pbr || (variant & kPbrOutlines)) desc.defines.push_back("DERMIS_OUTLINES");
    if (!pbr) return buildProgram(desc);
    desc.defines.push_back("DERMIS_PBR");
    desc.includes.push_back({GL_FRAGMENT_SHADER, "pbr.glsl"});
    if (variant & kPbrSkin) {
        auto vec3 = [](const double (&v)[3]) {
            return "vec3(" + std::to_string(v[0]) + ", " + std::to_string(v[1]) + ", " + std::to_string(v[2]) + ")";
        };
        desc.defines.push_back("DERMIS_SKIN");
        desc.defines.push_back("DERMIS_SKIN_SCATTER " + vec3(kSkinScatterWidth));
        desc.defines.push_back("DERMIS_SKIN_NORMAL_BLEND " + vec3(kSkinNormalBlend));
        desc.defines.push_back("DERMIS_SKIN_LOBE_ROUGHNESS " + std::to_string(kSkinSecondLobeRoughness));
        desc.defines.push_back("DERMIS_SKIN_LOBE_WEIGHT " + std::to_string(kSkinSecondLobeWeight));
    }
    if (variant & kPbrKeyLight) desc.defines.push_back("DERMIS_KEY_LIGHT");
    if (variant & kPbrMaps) desc.defines.push_back("DERMIS_PBR_MAPS");
    if (variant & kPbrViews) desc.defines.push_back("DERMIS_PBR_VIEWS");
    return buildProgram(desc);
}

/// The vertex array, buffers and 1×1 textures every job shares.
void Renderer::Impl::createSharedObjects() {
    glGenVertexArrays(1, &emptyVao);
    GLuint bufs[7];
    glGenBuffers(7, bufs);
    heightUbo = bufs[0];
    frameUbo = bufs[1];
    partUbo = bufs[2];
    paletteSsbo = bufs[3];
    feedbackBuffer = bufs[4];
    outlineUbo = bufs[5];
    morphWeightSsbo = bufs[6];
    glGenBuffers(1, &environmentUbo);
    // Every block common.glsl and skin.vert declare is active in every program (std140 / std430),
    // so each binding holds a zeroed buffer of at least the block's size from the start; the
    // passes re-bind a buffer at offset 0 whenever they re-allocate it (checkDrawBindings).
    const std::vector<std::uint8_t> zeros(sizeof(EnvironmentBlock) + sizeof(OutlineBlock) +
                                              sizeof(PartBlock) + sizeof(HeightPassBlock) +
                                              sizeof(FrameBlock),
                                          0);
    const struct {
        GLenum target;
        GLuint binding, buffer;
        std::size_t bytes;
    } initial[] = {
        {GL_UNIFORM_BUFFER, kHeightPassBinding, heightUbo, sizeof(HeightPassBlock)},
        {GL_UNIFORM_BUFFER, kFrameBinding, frameUbo, sizeof(FrameBlock)},
        {GL_UNIFORM_BUFFER, kPartBinding, partUbo, sizeof(PartBlock)},
        {GL_UNIFORM_BUFFER, kOutlineBinding, outlineUbo, sizeof(OutlineBlock)},
        {GL_UNIFORM_BUFFER, kEnvironmentBinding, environmentUbo, sizeof(EnvironmentBlock)},
        {GL_SHADER_STORAGE_BUFFER, kPaletteBinding, paletteSsbo, sizeof(glm::mat4)},
        {GL_SHADER_STORAGE_BUFFER, kMorphDeltaBinding, morphWeightSsbo, sizeof(glm::vec4)},
        {GL_SHADER_STORAGE_BUFFER, kMorphWeightBinding, morphWeightSsbo, sizeof(glm::vec4)},
    };
    for (const auto& b : initial) {
        glBindBuffer(b.target, b.buffer);
        glBufferData(b.target, static_cast<GLsizeiptr>(b.bytes), zeros.data(), GL_DYNAMIC_DRAW);
        glBindBufferBase(b.target, b.binding, b.buffer);
    }
    const float zero[2] = {0.0f, 0.0f};
    flatTexture = makeFloatTexture(1, 1, zero, GL_NEAREST, 2);
    glGenTextures(1, &whiteTexture);
    glBindTexture(GL_TEXTURE_2D, whiteTexture);
    const std::uint8_t white[4] = {255, 255, 255, 255};
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_SRGB8_ALPHA8, 1, 1);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, white);
}

void Renderer::Impl::dropPatternTextures() {
    while (!patterns.empty())
        erasePattern(patterns.begin());
    lastHeights.reset();
}

void Renderer::Impl::shutdown() {
    if (!context) return;
    while (!models.empty())
        eraseModel(models.begin());
    dropPatternTextures();
    heights.destroy();
    frame.destroy();
    for (GLuint p : {heightProgram, heightSurfaceProgram, heightBaseProgram, captureProgram})
        glDeleteProgram(p);
    for (auto& byView : skinPrograms)
        for (GLuint& p : byView) {
            glDeleteProgram(p);
            p = 0;
        }
    for (const auto& [variant, p] : pbrPrograms)
        glDeleteProgram(p);
    pbrPrograms.clear();
    glDeleteProgram(depthProgram);
    depthProgram = 0;
    glDeleteProgram(depthMaskProgram);
    depthMaskProgram = 0;
    shadowMap.destroy();
    glDeleteTextures(1, &noShadowTexture);
    noShadowTexture = 0;
    glDeleteBuffers(1, &keyLightUbo);
    glDeleteBuffers(1, &shadowFrameUbo);
    keyLightUbo = shadowFrameUbo = 0;
    studioLight.destroy();
    customLight.destroy();
    customKey = nullptr;
    glDeleteTextures(1, &brdfLutTexture);
    glDeleteBuffers(1, &environmentUbo);
    brdfLutTexture = environmentUbo = 0;
    GLuint bufs[7] = {heightUbo, frameUbo, partUbo, paletteSsbo, feedbackBuffer, outlineUbo, morphWeightSsbo};
    glDeleteBuffers(7, bufs);
    glDeleteVertexArrays(1, &emptyVao);
    glDeleteTextures(1, &flatTexture);
    glDeleteTextures(1, &whiteTexture);
    glFinish();
    context.reset();
}

Result<Renderer::BlockLayout> Renderer::Impl::blockLayout(const std::string& block) {
    // The tessellated PBR program with the material's maps, views and outlines uses every member
    // of the skin pass's blocks; its key light variant declares the KeyLightBlock.
    GLuint program = heightProgram;
    if (block != "HeightPassBlock") {
        auto p = skinProgram(true, FrameView::Lighting, true, false, block == "KeyLightBlock", true, true);
        if (!p) return p.error();
        program = *p;
    }
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
    req.morphWeights = plan.pose.morphWeights;
    req.render = plan.render;
    req.view = plan.view;
    req.heights = plan.heights;
    req.layout = plan.heights.layout;
    return req;
}

// --- public façade: every call runs on the render thread ----------------------------------------

Renderer::Renderer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

Result<std::unique_ptr<Renderer>> Renderer::create(GlBackend backend, const RendererOptions& options) {
    auto impl = std::make_unique<Impl>();
    impl->cacheBudget = options.cacheBudgetBytes;
    impl->softwareCpuBakeCoverage = options.softwareCpuBakeCoverage;
    impl->checkBindings = options.checkBindings;
    impl->publishCacheStats();
    // The default light's CPU tables beside the context's start (EGL, shaders): ≈ 0.1 s a first
    // pbr frame would otherwise wait for. Without a thread for it the first frame computes them.
    try {
        impl->lightingWarm = std::async(std::launch::async, gl::warmStudioLighting);
    } catch (const std::system_error&) {
    }
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
    HeightMaps maps;
    if (auto s = impl_->run([&] { return impl_->bakeHeightMaps(in, maps); }); !s) return s.error();
    return maps;
}

Result<FrameResult> Renderer::renderFrame(const FrameRequest& request) {
    return impl_->run([&] { return impl_->renderFrame(request); });
}

Result<std::vector<SkinnedPart>> Renderer::skinOnGpu(const std::shared_ptr<const Model>& model,
                                                     const std::vector<glm::mat4>& world,
                                                     const std::vector<float>& morphWeights) {
    return impl_->run([&] { return impl_->skinOnGpu(model, world, morphWeights); });
}

void Renderer::forgetPatterns() {
    impl_->run([&] {
        impl_->dropPatternTextures();
        return 0;
    });
}

Renderer::Stats Renderer::stats() {
    return impl_->run([&] {
        return Stats{impl_->heightPasses, impl_->heightPassesSkipped, impl_->heightPassesOnCpu};
    });
}

Result<Renderer::BlockLayout> Renderer::blockLayout(const std::string& block) {
    return impl_->run([&] { return impl_->blockLayout(block); });
}

} // namespace dermis
