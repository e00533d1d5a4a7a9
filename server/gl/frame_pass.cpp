// Stage 2 of the renderer: frame targets, the skin pass (skinning, displacement, bump mapping,
// shading under the camera of core/camera.hpp), readback, and transform-feedback skinning
// (see renderer_impl.hpp).
#include "renderer_impl.hpp"

#include "uniform_blocks.hpp"

#include "core/camera.hpp"
#include "core/edge_aa.hpp"
#include "core/render_settings.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace dermis {

using namespace gl;

static_assert(static_cast<std::size_t>(kOutlineSlots) == kMaxFrameOutlines);

namespace {

/// Colour or depth storage of a frame target, multisampled when samples > 1.
void renderbufferStorage(GLuint rb, int samples, GLenum format, int w, int h) {
    glBindRenderbuffer(GL_RENDERBUFFER, rb);
    if (samples > 1)
        glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, format, w, h);
    else
        glRenderbufferStorage(GL_RENDERBUFFER, format, w, h);
}

} // namespace

void FrameTargets::destroy() {
    glDeleteFramebuffers(1, &fbo);
    glDeleteFramebuffers(1, &resolveFbo);
    glDeleteRenderbuffers(1, &color);
    glDeleteRenderbuffers(1, &depth);
    glDeleteRenderbuffers(1, &resolveColor);
    *this = FrameTargets{};
}

Status Renderer::Impl::ensureFrameTargets(int w, int h, int samples) {
    if (frame.fbo && frame.width == w && frame.height == h && frame.samples == samples) return Ok{};
    frame.destroy();
    frame.width = w;
    frame.height = h;
    frame.samples = samples;
    glGenFramebuffers(1, &frame.fbo);
    glGenRenderbuffers(1, &frame.color);
    glGenRenderbuffers(1, &frame.depth);
    renderbufferStorage(frame.color, samples, GL_SRGB8_ALPHA8, w, h);
    renderbufferStorage(frame.depth, samples, GL_DEPTH_COMPONENT24, w, h);
    glBindFramebuffer(GL_FRAMEBUFFER, frame.fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, frame.color);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, frame.depth);
    bool complete = glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
    if (samples > 1) {
        glGenFramebuffers(1, &frame.resolveFbo);
        glGenRenderbuffers(1, &frame.resolveColor);
        renderbufferStorage(frame.resolveColor, 1, GL_SRGB8_ALPHA8, w, h);
        glBindFramebuffer(GL_FRAMEBUFFER, frame.resolveFbo);
        glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER,
                                  frame.resolveColor);
        complete = complete && glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
    }
    if (!complete) {
        frame.destroy();
        return makeError(ErrorCode::Internal, kWhere, "/render/size",
                         "the GL cannot create a " + std::to_string(w) + "x" + std::to_string(h) +
                             " frame with " + std::to_string(samples) + " samples");
    }
    return checkGl("creating the frame targets");
}

// --- one frame ----------------------------------------------------------------------------------

/// Render settings by the core's one check (validateRenderSettings), then the GL's renderbuffer
/// limit; a model must be given, and a view that FrameView names.
Status Renderer::Impl::checkFrameRequest(const FrameRequest& req) const {
    const RenderSettings& rs = req.render;
    if (auto s = validateRenderSettings(rs, {}, kWhere); !s) return s;
    if (rs.size[0] > maxRenderbufferSize || rs.size[1] > maxRenderbufferSize)
        return makeError(ErrorCode::InvalidArgument, kWhere, "/render/size",
                         "each side must be at most the GL's renderbuffer limit " +
                             std::to_string(maxRenderbufferSize));
    if (!req.model) return makeError(ErrorCode::InvalidArgument, kWhere, "model", "no model");
    if (static_cast<int>(req.view) < static_cast<int>(FrameView::Shaded) ||
        static_cast<int>(req.view) > static_cast<int>(FrameView::Lighting))
        return makeError(ErrorCode::InvalidArgument, kWhere, "view", "not a FrameView");
    if (req.outlines.size() > kMaxFrameOutlines)
        return makeError(ErrorCode::InvalidArgument, kWhere, "outlines",
                         "at most " + std::to_string(kMaxFrameOutlines) + " outlines");
    for (const FrameOutline& o : req.outlines)
        if (!(std::isfinite(o.center.x) && std::isfinite(o.center.y) && o.scale.x > 0.0f &&
              o.scale.y > 0.0f && std::isfinite(o.scale.x) && std::isfinite(o.scale.y) &&
              std::isfinite(o.rotation)) ||
            o.kind < FrameOutline::Selected || o.kind > FrameOutline::Brush)
            return makeError(ErrorCode::InvalidArgument, kWhere, "outlines",
                             "an outline needs a finite centre and rotation, a size > 0 and a kind");
    return Ok{};
}

Result<FrameResult> Renderer::Impl::renderFrame(const FrameRequest& req) {
    if (auto s = checkFrameRequest(req); !s) return s.error();
    const RenderSettings& rs = req.render;
    const int W = rs.size[0], H = rs.size[1];
    const Model& model = *req.model;

    FrameResult out;
    auto gm = modelFor(req.model);
    if (!gm) return gm.error();
    // The vertex arrays for the maps' layout (SPEC §8; the model's own UVs when none is given).
    const std::shared_ptr<const TextureLayout> layout =
        req.layout ? req.layout : (req.heights ? req.heights->layout : nullptr);
    auto parts = partsFor(model, **gm, layout);
    if (!parts) return parts.error();

    // Stage 1: the height maps this frame samples.
    auto t0 = std::chrono::steady_clock::now();
    auto heightSource = heightStage(req, out);
    if (!heightSource) return heightSource.error();
    if (req.profile) glFinish();
    out.timings.heightMs = msSince(t0);

    // Stage 2: skin, displace, shade.
    t0 = std::chrono::steady_clock::now();
    // MSAA draws `samples` per pixel and resolves; post-process AA draws one and runs the edge
    // pass on the read-back frame below (core/edge_aa.hpp).
    const ResolvedAntiAliasing aa = resolveAntiAliasing(rs, info.software, info.maxSamples);
    const int samples = aa.samples;
    out.antiAliasing = aa.label();
    if (auto s = ensureFrameTargets(W, H, samples); !s) return s.error();
    uploadPalette(model, **gm, req.world, req.morphWeights);
    const double dispScale = rs.displacementScale ? *rs.displacementScale : (*gm)->autoDisplacement;
    const double bumpScale = 0.25 * (*gm)->autoDisplacement * rs.bumpStrength;
    // Framed on the posed bounds (CPU skinning of the same pose: cheap at these sizes).
    const std::vector<SkinnedPart> posed = skin(model, req.world, req.morphWeights);
    const Bounds bounds = framingBounds(posed);
    out.boundsMin = bounds.min;
    out.boundsMax = bounds.max;
    const FrameCamera camera = frameCamera(bounds.min, bounds.max, dispScale, rs.camera, W, H);
    out.cameraTarget = camera.target;
    out.cameraDistance = camera.distance;
    uploadFrameBlock(camera, dispScale, bumpScale, heightSource->size);
    uploadOutlineBlock(req.outlines);
    // The pbr program draws the pbr shading and its views (BaseColor and Lighting always; Normal
    // with the model's normal map when the shading is pbr).
    // Skin shading draws its shaded view with its own program, and every other view as pbr.
    const bool pbr = req.view == FrameView::BaseColor || req.view == FrameView::Lighting ||
                     (rs.shading != Shading::Legacy && (req.view == FrameView::Shaded || req.view == FrameView::Normal));
    const bool skinShading = rs.shading == Shading::Skin && req.view == FrameView::Shaded;
    if (pbr) {
        auto light = environmentLight(req.environment);
        if (!light) return light.error();
        uploadEnvironmentBlock(**light, rs);
    }
    const std::size_t partStride = uploadPartBlocks(model, **gm, **parts, req.view, pbr);
    // The key light (render.key_light) lights the pbr programs' shaded and lighting views; its
    // shadow map is drawn before the frame (shadow_pass.cpp).
    const bool keyLight = pbr && rs.keyLight &&
                          (req.view == FrameView::Shaded || req.view == FrameView::Lighting);
    if (keyLight)
        if (auto s = keyLightStage(req, layout, **gm, **parts, bounds, dispScale, *heightSource, partStride);
            !s)
            return s.error();
    const auto program = skinProgram(rs.displacement == DisplacementMode::Tessellated, req.view, pbr,
                                     skinShading, keyLight, pbr && needsMaterialMaps(model, **gm, **parts),
                                     !req.outlines.empty());
    if (!program) return program.error();
    std::vector<std::size_t> order(parts.value()->size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    if (pbr) order = pbrDrawOrder(model, **parts, posed, camera.eye);
    const GLuint readFbo = drawSkinPass(model, **gm, **parts, rs, *program, heightSource->texture,
                                        partStride, samples, pbr ? &order : nullptr);
    if (auto s = checkGl("skin pass"); !s) return s.error();
    if (req.profile) glFinish();
    out.timings.skinMs = msSince(t0);

    t0 = std::chrono::steady_clock::now();
    if (auto s = readFrame(readFbo, out.image); !s) return s.error();
    out.timings.readbackMs = msSince(t0);
    if (auto s = checkGl("frame readback"); !s) return s.error();
    if (aa.mode == AntiAliasing::Post) {
        t0 = std::chrono::steady_clock::now();
        antiAliasEdges(out.image);
        out.timings.postAaMs = msSince(t0);
    }
    return out;
}

/// The GPU height pass on req.heights (and its maps into `out` when asked), else the CPU maps
/// uploaded, else the flat 1×1 texture.
Result<HeightSource> Renderer::Impl::heightStage(const FrameRequest& req, FrameResult& out) {
    HeightSource src{flatTexture, glm::vec2(1.0f)};
    if (req.heights) {
        if (auto s = heightPass(*req.heights); !s) return s.error();
        src = {heights.maps, glm::vec2(heights.width, heights.height)};
        if (req.readHeightMaps) {
            HeightMaps maps;
            if (auto s = readHeightTargets(maps); !s) return s.error();
            out.maps = std::move(maps);
        }
    } else if (req.cpuMaps) {
        if (auto s = uploadHeightMaps(*req.cpuMaps); !s) return s.error();
        src = {heights.maps, glm::vec2(heights.width, heights.height)};
    }
    return src;
}

void Renderer::Impl::uploadFrameBlock(const FrameCamera& camera, double dispScale,
                                      double bumpScale, glm::vec2 heightmapSize) {
    FrameBlock fb{};
    fb.viewProj = camera.viewProj;
    fb.cameraPos = glm::vec4(camera.eye, 0.0f);
    fb.lightDir = glm::vec4(camera.lightDir, 0.3f); // w: ambient level
    fb.heights = glm::vec4(static_cast<float>(dispScale), static_cast<float>(bumpScale), 0.0f, 0.0f);
    fb.heightmapSize = glm::vec4(heightmapSize, 1.0f / heightmapSize.x, 1.0f / heightmapSize.y);
    // Tessellation: about one vertex every 6 pixels, at most level 16.
    fb.viewport = glm::vec4(static_cast<float>(camera.width), static_cast<float>(camera.height),
                            6.0f, 16.0f);
    glBindBuffer(GL_UNIFORM_BUFFER, frameUbo);
    glBufferSubData(GL_UNIFORM_BUFFER, 0, sizeof fb, &fb);
    glBindBufferBase(GL_UNIFORM_BUFFER, kFrameBinding, frameUbo);
}

/// The frame's outlines into outlineUbo (count 0 when there are none: the shader draws nothing).
void Renderer::Impl::uploadOutlineBlock(const std::vector<FrameOutline>& outlines) {
    OutlineBlock ob{};
    const std::size_t n = std::min(outlines.size(), static_cast<std::size_t>(kOutlineSlots));
    ob.count = glm::ivec4(static_cast<int>(n), 0, 0, 0);
    for (std::size_t i = 0; i < n; ++i) {
        const FrameOutline& o = outlines[i];
        const float a = glm::radians(o.rotation);
        ob.rect[i] = glm::vec4(o.center, o.scale);
        ob.style[i] = glm::vec4(std::cos(a), std::sin(a), static_cast<float>(o.kind), static_cast<float>(o.shape));
        if (o.shape != FrameOutline::UvRect) {
            const glm::vec3 nrm = glm::normalize(o.normal), t = glm::normalize(o.tangent);
            const glm::vec2 size = o.shape == FrameOutline::SurfaceCircle ? glm::vec2(o.size.x) : o.size;
            ob.anchor[i] = glm::vec4(o.anchor, o.depth);
            ob.axisU[i] = glm::vec4(t / size.x, 0.0f);
            ob.axisV[i] = glm::vec4(glm::cross(nrm, t) / size.y, 0.0f);
        }
    }
    glBindBuffer(GL_UNIFORM_BUFFER, outlineUbo);
    glBufferSubData(GL_UNIFORM_BUFFER, 0, sizeof ob, &ob);
    glBindBufferBase(GL_UNIFORM_BUFFER, kOutlineBinding, outlineUbo);
}

/// One PartBlock per part in partUbo (bound by range per draw), each with the frame's view in
/// part.w (the legacy programs draw their DERMIS_VIEW variant; the pbr program chooses its view
/// by it) and, with `pbr`, the material (fillMaterialBlock); returns the stride.
std::size_t Renderer::Impl::uploadPartBlocks(const Model& model, const GpuModel& gm,
                                             const std::vector<GpuModel::Part>& parts, FrameView view,
                                             bool pbr) {
    const std::size_t stride = uboStride(sizeof(PartBlock));
    std::vector<std::uint8_t> partBlocks(stride * std::max<std::size_t>(1, parts.size()), 0);
    for (std::size_t pi = 0; pi < parts.size(); ++pi) {
        const GpuModel::Part& gp = parts[pi];
        PartBlock pb{};
        pb.baseColor = glm::vec4(0.80f, 0.62f, 0.54f, 1.0f); // skin tone when there is no material
        if (gp.material >= 0 && static_cast<std::size_t>(gp.material) < model.materials.size())
            pb.baseColor = model.materials[static_cast<std::size_t>(gp.material)].baseColorFactor;
        const bool textured = gm.baseColorTexture(model, gp) != 0 && gp.hasUVs;
        pb.part = glm::ivec4(gp.paletteOffset, textured ? 1 : 0, gp.hasMapUVs ? 1 : 0,
                             static_cast<int>(view));
        pb.morph = glm::ivec4(gp.morphTargets, gp.morphWeightOffset, gp.vertexCount, 0);
        if (pbr) fillMaterialBlock(pb, model, gm, gp);
        std::memcpy(partBlocks.data() + stride * pi, &pb, sizeof pb);
    }
    glBindBuffer(GL_UNIFORM_BUFFER, partUbo);
    glBufferData(GL_UNIFORM_BUFFER, static_cast<GLsizeiptr>(partBlocks.size()), partBlocks.data(),
                 GL_STREAM_DRAW);
    // The last draw's range may lie past the new, smaller store; every program declares PartBlock
    // (std140: always active) and Mesa reads each bound range on every draw.
    glBindBufferRange(GL_UNIFORM_BUFFER, kPartBinding, partUbo, 0, sizeof(PartBlock));
    return stride;
}

/// Draws every part into the frame targets and resolves MSAA; returns the framebuffer to read.
GLuint Renderer::Impl::drawSkinPass(const Model& model, const GpuModel& gm,
                                    const std::vector<GpuModel::Part>& parts,
                                    const RenderSettings& rs, GLuint skinProgram,
                                    GLuint heightTexture, std::size_t partStride, int samples,
                                    const std::vector<std::size_t>* pbrOrder) {
    const int W = frame.width, H = frame.height;
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
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, heightTexture);
    // glTF BLEND parts (pbr): over what is behind, without hiding what is drawn after them.
    auto blended = [&](const GpuModel::Part& gp) {
        const Material* mat = pbrOrder ? materialOf(model, gp) : nullptr;
        return mat && mat->alphaMode == AlphaMode::Blend;
    };
    auto bindPart = [&](std::size_t pi) {
        const GpuModel::Part& gp = parts[pi];
        glBindBufferRange(GL_UNIFORM_BUFFER, kPartBinding, partUbo,
                          static_cast<GLintptr>(partStride * pi), sizeof(PartBlock));
        if (pbrOrder) {
            bindMaterialTextures(model, gm, gp, whiteTexture);
        } else {
            glActiveTexture(GL_TEXTURE2);
            const GLuint colorTex = gm.baseColorTexture(model, gp);
            glBindTexture(GL_TEXTURE_2D, colorTex ? colorTex : whiteTexture);
        }
        bindMorphDeltas(gp);
        glBindVertexArray(gp.vao);
    };
    // Depth prepass (pbr and skin shading, one sample, vertex displacement): the opaque and
    // masked parts' depths first, by the depth-only program (a MASK part's cut-out fragments
    // write none), so that the shading pass below shades each pixel once — the fragments at
    // exactly those depths (GL_EQUAL; skin.vert's gl_Position is invariant) — instead of every
    // surface that is nearest when it is drawn (with the default scene's squat at 1024² that was
    // 1.9 fragments per covered pixel, and a software rasterizer pays the full shading for each).
    // Blended parts are not in it: they test against it and write no depth, as before. Where it
    // does not pay on llvmpipe it is not drawn: legacy's shading costs about what the prepass
    // does, and with MSAA the prepass tests every sample twice (docs/benchmarks.md).
    const bool prepass = !tess && pbrOrder && samples == 1;
    if (prepass) {
        glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
        glDepthMask(GL_TRUE);
        GLuint inUse = 0;
        for (std::size_t pi = 0; pi < parts.size(); ++pi) {
            if (parts[pi].indexCount == 0 || blended(parts[pi])) continue;
            const GLuint wanted = depthProgramFor(model, parts[pi]);
            if (wanted != inUse) glUseProgram(inUse = wanted);
            bindPart(pi);
            checkDrawBindings("depth prepass");
            glDrawElements(GL_TRIANGLES, parts[pi].indexCount, GL_UNSIGNED_INT, nullptr);
        }
        glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    }
    glUseProgram(skinProgram);
    if (tess) glPatchParameteri(GL_PATCH_VERTICES, 3);
    for (std::size_t k = 0; k < parts.size(); ++k) {
        const std::size_t pi = pbrOrder ? (*pbrOrder)[k] : k;
        const GpuModel::Part& gp = parts[pi];
        if (gp.indexCount == 0) continue;
        if (blended(gp)) {
            glEnable(GL_BLEND);
            glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
            glDepthFunc(GL_LESS);
            glDepthMask(GL_FALSE);
        } else {
            glDisable(GL_BLEND);
            glDepthFunc(prepass ? GL_EQUAL : GL_LESS);
            glDepthMask(prepass ? GL_FALSE : GL_TRUE);
        }
        bindPart(pi);
        checkDrawBindings("skin pass");
        glDrawElements(tess ? GL_PATCHES : GL_TRIANGLES, gp.indexCount, GL_UNSIGNED_INT, nullptr);
    }
    glDepthFunc(GL_LESS);
    glBindVertexArray(0);
    glDisable(GL_BLEND);
    glDepthMask(GL_TRUE);
    glActiveTexture(GL_TEXTURE0);
    GLuint readFbo = frame.fbo;
    if (samples > 1) {
        glBindFramebuffer(GL_READ_FRAMEBUFFER, frame.fbo);
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, frame.resolveFbo);
        glBlitFramebuffer(0, 0, W, H, 0, 0, W, H, GL_COLOR_BUFFER_BIT, GL_NEAREST);
        readFbo = frame.resolveFbo;
    }
    glDisable(GL_FRAMEBUFFER_SRGB);
    return readFbo;
}

/// Reads the frame (RGBA8, GL row 0 first = the picture's top) straight into `image` (one copy:
/// through a pixel-pack buffer, mapped and copied out, llvmpipe's readback of a 1024² frame took
/// 1.1–1.3 ms instead of 0.8–0.9).
Status Renderer::Impl::readFrame(GLuint readFbo, Image8& image) {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, readFbo);
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    image.width = frame.width;
    image.height = frame.height;
    image.rgba.resize(static_cast<std::size_t>(frame.width) * static_cast<std::size_t>(frame.height) * 4);
    glReadPixels(0, 0, frame.width, frame.height, GL_RGBA, GL_UNSIGNED_BYTE, image.rgba.data());
    return Ok{};
}

// --- transform-feedback skinning ------------------------------------------------------------------

Result<std::vector<SkinnedPart>> Renderer::Impl::skinOnGpu(const std::shared_ptr<const Model>& model,
                                                           const std::vector<glm::mat4>& world,
                                                           const std::vector<float>& morphWeights) {
    auto gm = modelFor(model);
    if (!gm) return gm.error();
    uploadPalette(*model, **gm, world, morphWeights);
    // A draw needs a complete framebuffer even with rasterization discarded; a surfaceless
    // context has no default one (GL_INVALID_FRAMEBUFFER_OPERATION when no frame came first).
    if (frame.fbo == 0)
        if (auto s = ensureFrameTargets(16, 16, 1); !s) return s.error();
    glBindFramebuffer(GL_FRAMEBUFFER, frame.fbo);
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
        pb.morph = glm::ivec4(gp.morphTargets, gp.morphWeightOffset, gp.vertexCount, 0);
        bindMorphDeltas(gp);
        glBindBuffer(GL_UNIFORM_BUFFER, partUbo);
        glBufferData(GL_UNIFORM_BUFFER, sizeof pb, &pb, GL_STREAM_DRAW);
        glBindBufferBase(GL_UNIFORM_BUFFER, kPartBinding, partUbo);
        const std::size_t bytes = nv * 6 * sizeof(float);
        glBindBuffer(GL_TRANSFORM_FEEDBACK_BUFFER, feedbackBuffer);
        glBufferData(GL_TRANSFORM_FEEDBACK_BUFFER, static_cast<GLsizeiptr>(bytes), nullptr, GL_STREAM_READ);
        glBindBufferBase(GL_TRANSFORM_FEEDBACK_BUFFER, 0, feedbackBuffer);
        glBindVertexArray(gp.vao);
        glBeginTransformFeedback(GL_POINTS);
        checkDrawBindings("transform feedback skinning");
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

} // namespace dermis
