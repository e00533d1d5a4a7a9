// The key light of pbr and skin frames (`render.key_light`; see renderer_impl.hpp): its block
// and its shadow map, a depth-only pass from the light (core/key_light.hpp shadowCamera) with the
// same vertex stage as the frame, so that the character casts what it shows.
#include "renderer_impl.hpp"

#include "programs.hpp"
#include "uniform_blocks.hpp"

#include "core/key_light.hpp"

namespace dermis {

using namespace gl;

namespace {

/// Texture unit of the shadow map (pbr.glsl u_shadowMap).
constexpr GLenum kUnitShadowMap = GL_TEXTURE9;

/// A depth texture compared on lookup (LEQUAL, bilinear: four comparisons filtered), clamped to
/// a border of depth 1, so that what lies outside the map is lit. Made on the shadow map's own
/// unit (left active), so that no texture a frame has bound elsewhere (the environment's on
/// units 7 and 8) is replaced.
GLuint makeShadowTexture(int size, const float* depth) {
    GLuint t = 0;
    glActiveTexture(kUnitShadowMap);
    glGenTextures(1, &t);
    glBindTexture(GL_TEXTURE_2D, t);
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_DEPTH_COMPONENT32F, size, size);
    if (depth) glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, size, size, GL_DEPTH_COMPONENT, GL_FLOAT, depth);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_BORDER);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_BORDER);
    const float border[4] = {1.0f, 1.0f, 1.0f, 1.0f};
    glTexParameterfv(GL_TEXTURE_2D, GL_TEXTURE_BORDER_COLOR, border);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
    return t;
}

} // namespace

bool ShadowInputs::sameAs(const ShadowInputs& o) const {
    const auto sameOwner = [](const auto& a, const auto& b) { return !a.owner_before(b) && !b.owner_before(a); };
    return sameOwner(model, o.model) && !model.expired() && sameOwner(layout, o.layout) && world == o.world &&
           morphWeights == o.morphWeights && viewProj == o.viewProj && dispScale == o.dispScale &&
           heightTexture == o.heightTexture && heightsWritten == o.heightsWritten;
}

void ShadowTarget::destroy() {
    glDeleteFramebuffers(1, &fbo);
    glDeleteTextures(1, &depth);
    *this = ShadowTarget{};
}

Status Renderer::Impl::ensureShadowTarget(int size) {
    if (shadowMap.fbo && shadowMap.size == size) return Ok{};
    shadowMap.destroy();
    lastShadow.reset();
    shadowMap.size = size;
    shadowMap.depth = makeShadowTexture(size, nullptr);
    glGenFramebuffers(1, &shadowMap.fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, shadowMap.fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, shadowMap.depth, 0);
    glDrawBuffer(GL_NONE);
    glReadBuffer(GL_NONE);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
        shadowMap.destroy();
        return makeError(ErrorCode::Internal, kWhere, "/render/key_light/shadow",
                         "the GL cannot draw a " + std::to_string(size) + "² shadow map");
    }
    return checkGl("creating the shadow map");
}

Status Renderer::Impl::keyLightStage(const FrameRequest& req, const std::shared_ptr<const TextureLayout>& layout,
                                     const GpuModel& gm, const std::vector<GpuModel::Part>& parts,
                                     const Bounds& bounds, double dispScale, const HeightSource& heightSource,
                                     std::size_t partStride) {
    const Model& model = *req.model;
    const KeyLight& light = *req.render.keyLight;
    if (!keyLightUbo) {
        glGenBuffers(1, &keyLightUbo);
        glGenBuffers(1, &shadowFrameUbo);
        glBindBuffer(GL_UNIFORM_BUFFER, keyLightUbo);
        glBufferData(GL_UNIFORM_BUFFER, sizeof(KeyLightBlock), nullptr, GL_DYNAMIC_DRAW);
        glBindBuffer(GL_UNIFORM_BUFFER, shadowFrameUbo);
        glBufferData(GL_UNIFORM_BUFFER, sizeof(FrameBlock), nullptr, GL_DYNAMIC_DRAW);
        const float lit = 1.0f;
        noShadowTexture = makeShadowTexture(1, &lit);
    }
    const int size = kKeyLightShadowMapSize;
    const ShadowCamera sc = shadowCamera(bounds.min, bounds.max, dispScale, keyLightDirection(light), size);
    KeyLightBlock kb{};
    kb.shadowViewProj = sc.viewProj;
    kb.direction = glm::vec4(sc.towardsLight, light.shadow ? 1.0f : 0.0f);
    kb.radiance = glm::vec4(static_cast<float>(light.color[0] * light.intensity),
                            static_cast<float>(light.color[1] * light.intensity),
                            static_cast<float>(light.color[2] * light.intensity), 0.0f);
    // Lookups move 1.5 texels off the surface (more where the light grazes it) and compare one
    // texel's depth nearer: no acne on lit surfaces, shadows detached by about a texel (≈ 1 mm
    // on a 2 m character).
    kb.shadowParams = glm::vec4(1.5f * sc.texelWorld, sc.texelWorld / sc.depthRange, 1.0f / static_cast<float>(size), 0.0f);
    glBindBuffer(GL_UNIFORM_BUFFER, keyLightUbo);
    glBufferSubData(GL_UNIFORM_BUFFER, 0, sizeof kb, &kb);
    glBindBufferBase(GL_UNIFORM_BUFFER, kKeyLightBinding, keyLightUbo);
    if (!light.shadow) {
        glActiveTexture(kUnitShadowMap);
        glBindTexture(GL_TEXTURE_2D, noShadowTexture);
        glActiveTexture(GL_TEXTURE0);
        return checkGl("key light");
    }

    if (auto s = ensureShadowTarget(size); !s) {
        glActiveTexture(GL_TEXTURE0);
        return s;
    }
    ShadowInputs inputs{req.model, layout, req.world, req.morphWeights, sc.viewProj, dispScale,
                        heightSource.texture, heightsWritten};
    if (lastShadow && lastShadow->sameAs(inputs)) {
        glActiveTexture(kUnitShadowMap);
        glBindTexture(GL_TEXTURE_2D, shadowMap.depth);
        glActiveTexture(GL_TEXTURE0);
        return checkGl("key light");
    }
    lastShadow.reset(); // until drawn
    // The light's view in a FrameBlock of its own (skin.vert reads the displacement scale from it).
    FrameBlock fb{};
    fb.viewProj = sc.viewProj;
    fb.cameraPos = glm::vec4(0.5f * (bounds.min + bounds.max) + 2.0f * sc.radius * sc.towardsLight, 0.0f);
    fb.heights = glm::vec4(static_cast<float>(dispScale), 0.0f, 0.0f, 0.0f);
    fb.heightmapSize = glm::vec4(heightSource.size, 1.0f / heightSource.size.x, 1.0f / heightSource.size.y);
    fb.viewport = glm::vec4(static_cast<float>(size), static_cast<float>(size), 6.0f, 16.0f);
    glBindBuffer(GL_UNIFORM_BUFFER, shadowFrameUbo);
    glBufferSubData(GL_UNIFORM_BUFFER, 0, sizeof fb, &fb);
    glBindBufferBase(GL_UNIFORM_BUFFER, kFrameBinding, shadowFrameUbo);

    glBindFramebuffer(GL_FRAMEBUFFER, shadowMap.fbo);
    glViewport(0, 0, size, size);
    glDisable(GL_MULTISAMPLE);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(1.1f, 2.0f);
    const float one = 1.0f;
    glClearBufferfv(GL_DEPTH, 0, &one);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, heightSource.texture);
    GLuint program = 0;
    for (std::size_t pi = 0; pi < parts.size(); ++pi) {
        const GpuModel::Part& gp = parts[pi];
        if (gp.indexCount == 0) continue;
        const Material* m = materialOf(model, gp);
        if (m && m->alphaMode == AlphaMode::Blend) continue;
        const GLuint wanted = depthProgramFor(m);
        if (wanted != program) glUseProgram(program = wanted);
        glBindBufferRange(GL_UNIFORM_BUFFER, kPartBinding, partUbo,
                          static_cast<GLintptr>(partStride * pi), sizeof(PartBlock));
        bindMaterialTextures(model, gm, gp, whiteTexture);
        bindMorphDeltas(gp);
        glBindVertexArray(gp.vao);
        checkDrawBindings("shadow pass");
        glDrawElements(GL_TRIANGLES, gp.indexCount, GL_UNSIGNED_INT, nullptr);
    }
    glBindVertexArray(0);
    glDisable(GL_POLYGON_OFFSET_FILL);
    glBindBufferBase(GL_UNIFORM_BUFFER, kFrameBinding, frameUbo);
    glActiveTexture(kUnitShadowMap);
    glBindTexture(GL_TEXTURE_2D, shadowMap.depth);
    glActiveTexture(GL_TEXTURE0);
    if (auto s = checkGl("shadow pass"); !s) return s;
    lastShadow = std::move(inputs);
    return Ok{};
}

} // namespace dermis
