// Stage 1 of the renderer: pattern and base textures cached by content id (in the byte budget of
// gpu_cache.cpp), the height targets, the height pass (one quad per placement, additive; a surface
// placement's quad covers the texels it may reach and reads the rest-surface map, SPEC §8, whose
// two RGB32F textures are cached like patterns), readback and upload of maps (see
// renderer_impl.hpp). On a software rasterizer a pass covering many map
// areas is baked by the CPU and uploaded (RendererOptions::softwareCpuBakeCoverage).
#include "renderer_impl.hpp"

#include "uniform_blocks.hpp"

#include "core/texture_layout.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace dermis {

using namespace gl;

std::uint64_t gl::contentHash(const HeightImage& image) {
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

void HeightTargets::destroy() {
    glDeleteFramebuffers(1, &fbo);
    glDeleteTextures(1, &maps);
    fbo = maps = 0;
    width = height = 0;
}

namespace {

/// What the height targets will hold when `in` is rendered with these textures: equal keys
/// give equal maps, so the pass can be skipped.
HeightKey heightKey(const HeightPassInput& in, const ResolvedPatterns& resolved,
                    std::uint64_t baseKey) {
    HeightKey key;
    key.width = in.width;
    key.height = in.height;
    key.base = baseKey;
    key.patterns = resolved.ids;
    key.rest = resolved.restId;
    for (std::size_t k = 0; k < in.placements.size(); ++k) {
        if (!resolved.textures[k]) continue;
        const BakePlacement& p = in.placements[k];
        key.params.insert(key.params.end(),
                          {p.footprint.center.x, p.footprint.center.y, p.footprint.scale.x,
                           p.footprint.scale.y, p.footprint.rotationDeg, p.h, p.t,
                           double(static_cast<int>(p.model)), double(static_cast<int>(p.target)),
                           double(static_cast<int>(p.response)), p.surface ? 1.0 : 0.0});
        if (p.surface)
            key.params.insert(key.params.end(),
                              {p.anchorPosition.x, p.anchorPosition.y, p.anchorPosition.z,
                               p.anchorNormal.x, p.anchorNormal.y, p.anchorNormal.z,
                               p.anchorTangent.x, p.anchorTangent.y, p.anchorTangent.z, p.size.x,
                               p.size.y, p.depth});
    }
    return key;
}

/// The uniform block of placement `p` drawn into a W×H map.
HeightPassBlock placementBlock(const BakePlacement& p, int W, int H) {
    HeightPassBlock b{};
    const double a = glm::radians(p.footprint.rotationDeg);
    b.centerScale = glm::vec4(p.footprint.center.x, p.footprint.center.y, p.footprint.scale.x,
                              p.footprint.scale.y);
    // The quad reaches 1.5 texels beyond the footprint on every side (in pattern units).
    const double texel = 1.5 * std::max(1.0 / W, 1.0 / H);
    b.rotation = glm::vec4(std::cos(a), std::sin(a), texel / p.footprint.scale.x,
                           texel / p.footprint.scale.y);
    // The deform constant once per placement, not per fragment (llvmpipe evaluates a log2 per
    // fragment otherwise): the same float as the CPU bake's.
    b.drive = glm::vec4(static_cast<float>(p.h), static_cast<float>(p.t),
                        deformConstant(p.model, p.response, p.t), 0.0f);
    b.mode = glm::ivec4(p.model == DeformModel::Scale ? 0 : 1, p.target == Target::Bump ? 0 : 1,
                        static_cast<int>(p.response), 0);
    b.mapSize = glm::vec4(static_cast<float>(W), static_cast<float>(H), 0.0f, 0.0f);
    if (p.pattern) {
        b.mapSize.z = static_cast<float>(p.pattern->width);
        b.mapSize.w = static_cast<float>(p.pattern->height);
    }
    return b;
}

/// The uniform block of surface placement `p` (SPEC §8) drawn over texel rectangle `rect` of a
/// W×H map: the constants of dermis::SurfaceFrame.
HeightPassBlock surfaceBlock(const BakePlacement& p, const TexelRect& rect, int W, int H) {
    HeightPassBlock b = placementBlock(p, W, H);
    const float w = static_cast<float>(W), h = static_cast<float>(H);
    b.centerScale = glm::vec4(static_cast<float>(rect.x0) / w, static_cast<float>(rect.y0) / h,
                              static_cast<float>(rect.x1) / w, static_cast<float>(rect.y1) / h);
    b.mode.w = 1;
    const SurfaceFrame f(p);
    b.anchor = glm::vec4(glm::vec3(f.c), static_cast<float>(f.depth));
    b.anchorNormal = glm::vec4(glm::vec3(f.n), static_cast<float>(f.invW));
    b.anchorTangent = glm::vec4(glm::vec3(f.t), static_cast<float>(f.invH));
    b.anchorBinormal = glm::vec4(glm::vec3(f.b), 0.0f);
    return b;
}

/// Whether this height pass is baked by the CPU (RendererOptions::softwareCpuBakeCoverage): a
/// software rasterizer (RendererInfo::software) and footprints covering more than `coverage` map
/// areas.
bool bakeOnCpu(const HeightPassInput& in, const std::vector<TexelRect>& rects, double coverage,
               bool software) {
    if (!(coverage > 0.0)) return false;
    if (!software) return false;
    double covered = 0.0;
    for (std::size_t k = 0; k < in.placements.size(); ++k) {
        const BakePlacement& p = in.placements[k];
        if (!(p.t > 0.0)) continue;
        if (!p.surface) {
            covered += p.footprint.scale.x * p.footprint.scale.y;
        } else if (k < rects.size()) { // the rectangle of texels its quad covers
            const TexelRect& r = rects[k];
            covered += static_cast<double>(r.x1 - r.x0) * (r.y1 - r.y0) /
                       (static_cast<double>(in.width) * in.height);
        }
    }
    return covered > coverage;
}

} // namespace

Result<GLuint> Renderer::Impl::patternTexture(std::uint64_t id, const HeightImage& image,
                                              const std::string& field) {
    if (auto it = patterns.find(id); it != patterns.end()) {
        it->second.lastUse = useCounter;
        return it->second.tex;
    }
    if (image.width > info.maxTextureSize || image.height > info.maxTextureSize)
        return makeError(ErrorCode::InvalidArgument, kWhere, field,
                         "pattern is larger than the GL's maximum texture size " +
                             std::to_string(info.maxTextureSize));
    // Bounded cache: room within the byte budget, and at most kMaxPatternTextures textures.
    constexpr std::size_t kMaxPatternTextures = 256;
    PatternTexture pt;
    pt.bytes = static_cast<std::size_t>(image.width) * image.height * sizeof(float);
    makeRoom(pt.bytes);
    while (patterns.size() >= kMaxPatternTextures && evictOldest(useCounter, true)) {
    }
    pt.tex = makeFloatTexture(image.width, image.height, image.data.data(), GL_NEAREST);
    pt.lastUse = useCounter;
    patterns[id] = pt;
    patternBytes += pt.bytes;
    return pt.tex;
}

Result<ResolvedPatterns> Renderer::Impl::resolvePatterns(const HeightPassInput& in) {
    ResolvedPatterns r;
    r.textures.assign(in.placements.size(), 0);
    r.ids.assign(in.placements.size(), 0);
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
        r.ids[k] = p.patternId ? p.patternId : contentHash(*img);
        auto tex = patternTexture(r.ids[k], *img, field + "/pattern");
        if (!tex) return tex.error();
        r.textures[k] = *tex;
    }
    return r;
}

Status Renderer::Impl::resolveRest(const HeightPassInput& in, ResolvedPatterns& r) {
    r.surfaceRects.assign(in.placements.size(), TexelRect{});
    bool needed = false;
    for (std::size_t k = 0; k < in.placements.size(); ++k) {
        const BakePlacement& p = in.placements[k];
        if (!p.surface) continue;
        const std::string field = "/placements/" + std::to_string(k);
        const RestSurfaceMap* rest = in.rest.get();
        const std::size_t n = static_cast<std::size_t>(in.width) * in.height;
        if (!rest || rest->width != in.width || rest->height != in.height ||
            rest->position.size() != n || rest->normal.size() != n || rest->coverage.size() != n)
            return makeError(ErrorCode::InvalidArgument, kWhere, field + "/projection",
                             "a surface placement needs the rest-surface map of the layout in use "
                             "at the map size (" + std::to_string(in.width) + "x" +
                                 std::to_string(in.height) + ")");
        if (!(p.size.x > 0.0) || !(p.size.y > 0.0))
            return makeError(ErrorCode::InvalidArgument, kWhere, field + "/size", "must be > 0");
        if (!(p.depth > 0.0))
            return makeError(ErrorCode::InvalidArgument, kWhere, field + "/depth", "must be > 0");
        if (!r.textures[k]) continue; // contributes nothing
        r.surfaceRects[k] = surfacePlacementTexels(p, *rest);
        const TexelRect& rect = r.surfaceRects[k];
        if (rect.x0 >= rect.x1 || rect.y0 >= rect.y1) {
            r.textures[k] = 0; // reaches no texel
            r.ids[k] = 0;
            continue;
        }
        needed = true;
    }
    if (!needed) return Ok{};
    const RestSurfaceMap& rest = *in.rest;
    // By content id, like the patterns (RestSurfaceMap ids never equal theirs).
    const std::uint64_t id = rest.contentId ? rest.contentId : (std::uint64_t{3} << 62);
    if (auto it = patterns.find(id); it != patterns.end() && rest.contentId) {
        it->second.lastUse = useCounter;
        r.restPosition = it->second.tex;
        r.restNormal = it->second.tex2;
        r.restId = id;
        return Ok{};
    }
    if (auto it = patterns.find(id); it != patterns.end()) erasePattern(it); // no id: upload anew
    PatternTexture pt;
    pt.bytes = static_cast<std::size_t>(rest.width) * rest.height * 24;
    makeRoom(pt.bytes);
    pt.tex = makeFloatTexture(rest.width, rest.height, &rest.position[0].x, GL_NEAREST, 3);
    pt.tex2 = makeFloatTexture(rest.width, rest.height, &rest.normal[0].x, GL_NEAREST, 3);
    pt.lastUse = useCounter;
    patterns[id] = pt;
    patternBytes += pt.bytes;
    r.restPosition = pt.tex;
    r.restNormal = pt.tex2;
    r.restId = rest.contentId;
    return checkGl("uploading a rest-surface map");
}

Result<std::uint64_t> Renderer::Impl::resolveBase(const HeightPassInput& in) {
    const HeightImage* base = in.base;
    if (!base) return std::uint64_t{0};
    if (base->width <= 0 || base->height <= 0 ||
        base->data.size() != static_cast<std::size_t>(base->width) * base->height ||
        base->width > info.maxTextureSize || base->height > info.maxTextureSize)
        return makeError(ErrorCode::InvalidArgument, kWhere, "/heightmap/base", "empty or oversized base map");
    const std::uint64_t key = in.baseId ? in.baseId : contentHash(*base);
    auto tex = patternTexture(key, *base, "/heightmap/base");
    if (!tex) return tex.error();
    baseTexture = *tex;
    return key;
}

Status Renderer::Impl::ensureHeightTargets(int w, int h) {
    if (heights.fbo && heights.width == w && heights.height == h) return Ok{};
    heights.destroy();
    lastHeights.reset();
    ++heightsWritten;
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
    auto resolved = resolvePatterns(in);
    if (!resolved) return resolved.error();
    if (auto s = resolveRest(in, *resolved); !s) return s;
    auto baseKey = resolveBase(in);
    if (!baseKey) return baseKey.error();
    if (auto s = ensureHeightTargets(W, H); !s) return s;

    HeightKey key = heightKey(in, *resolved, *baseKey);
    if (resolved->restPosition && in.rest && !in.rest->contentId)
        lastHeights.reset(); // a rest-surface map without an id: its pixels may have changed
    if (lastHeights && *lastHeights == key) {
        ++heightPassesSkipped;
        return Ok{};
    }
    lastHeights.reset();
    if (bakeOnCpu(in, resolved->surfaceRects, softwareCpuBakeCoverage, info.software)) {
        BakeSettings settings;
        settings.width = W;
        settings.height = H;
        settings.base = in.base;
        settings.rest = in.rest.get();
        if (auto s = dermis::bakeHeightMapsInto(in.placements, settings, cpuBake); !s) return s;
        if (auto s = uploadHeightMaps(cpuBake); !s) return s;
        lastHeights = std::move(key); // (uploadHeightMaps counted the write)
        ++heightPasses;
        ++heightPassesOnCpu;
        return Ok{};
    }
    const std::size_t stride = uploadHeightBlocks(in, *resolved);
    ++heightsWritten;
    drawHeightPass(in, *resolved, stride);
    // Mesa's llvmpipe (egl-surfaceless and OSMesa alike) was seen to let the skin pass sample
    // part of the previous content of the height targets when this pass follows an upload of CPU
    // maps (glTexSubImage2D) and only clears them: a frame without placements after a CPU-baked
    // one differed from the same frame rendered again (glFlush did not help). Waiting for the
    // pass makes frames depend on their inputs only; hardware GLs are not affected.
    if (info.software) glFinish();
    if (auto st = checkGl("height pass"); !st) return st;
    lastHeights = std::move(key);
    ++heightPasses;
    return Ok{};
}

/// One block per placement in one buffer, bound by range per draw; slot 0 is the base draw's.
/// Returns the stride between blocks.
std::size_t Renderer::Impl::uploadHeightBlocks(const HeightPassInput& in, const ResolvedPatterns& resolved) {
    const std::size_t stride = uboStride(sizeof(HeightPassBlock));
    const std::size_t count = in.placements.size() + 1;
    std::vector<std::uint8_t> blocks(stride * count, 0);
    HeightPassBlock baseBlock{};
    baseBlock.mapSize =
        glm::vec4(static_cast<float>(in.width), static_cast<float>(in.height), 0.0f, 0.0f);
    std::memcpy(blocks.data(), &baseBlock, sizeof baseBlock);
    for (std::size_t k = 0; k < in.placements.size(); ++k) {
        const BakePlacement& p = in.placements[k];
        const HeightPassBlock b = p.surface && k < resolved.surfaceRects.size()
                                      ? surfaceBlock(p, resolved.surfaceRects[k], in.width, in.height)
                                      : placementBlock(p, in.width, in.height);
        std::memcpy(blocks.data() + stride * (k + 1), &b, sizeof b);
    }
    glBindBuffer(GL_UNIFORM_BUFFER, heightUbo);
    glBufferData(GL_UNIFORM_BUFFER, static_cast<GLsizeiptr>(blocks.size()), blocks.data(),
                 GL_STREAM_DRAW);
    // The last placement's range may lie past the new, smaller store; every program declares
    // HeightPassBlock (std140: always active) and Mesa reads each bound range on every draw.
    glBindBufferRange(GL_UNIFORM_BUFFER, kHeightPassBinding, heightUbo, 0, sizeof(HeightPassBlock));
    return stride;
}

/// The base map (or zeros), then every placement with a texture, summed by additive blending in
/// document order like the CPU reference.
void Renderer::Impl::drawHeightPass(const HeightPassInput& in, const ResolvedPatterns& resolved,
                                    std::size_t stride) {
    const std::vector<GLuint>& textures = resolved.textures;
    glBindFramebuffer(GL_FRAMEBUFFER, heights.fbo);
    glViewport(0, 0, in.width, in.height);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    glDisable(GL_FRAMEBUFFER_SRGB);
    glDisable(GL_MULTISAMPLE);
    glDisable(GL_BLEND);
    glBindVertexArray(emptyVao);
    const float zero[4] = {0, 0, 0, 0};
    if (in.base) {
        glUseProgram(heightBaseProgram);
        glBindBufferRange(GL_UNIFORM_BUFFER, kHeightPassBinding, heightUbo, 0, sizeof(HeightPassBlock));
        glActiveTexture(GL_TEXTURE0);
        glBindTexture(GL_TEXTURE_2D, baseTexture);
        checkDrawBindings("height pass base map");
        glDrawArrays(GL_TRIANGLES, 0, 3);
    } else {
        glClearBufferfv(GL_COLOR, 0, zero);
    }
    glEnable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    glBlendFunc(GL_ONE, GL_ONE);
    if (resolved.restPosition) { // surface placements read the rest-surface map (SPEC §8)
        glActiveTexture(GL_TEXTURE1);
        glBindTexture(GL_TEXTURE_2D, resolved.restPosition);
        glActiveTexture(GL_TEXTURE2);
        glBindTexture(GL_TEXTURE_2D, resolved.restNormal);
    }
    GLuint program = 0;
    glActiveTexture(GL_TEXTURE0);
    for (std::size_t k = 0; k < in.placements.size(); ++k) {
        if (!textures[k]) continue;
        const GLuint wanted = in.placements[k].surface ? heightSurfaceProgram : heightProgram;
        if (wanted != program) glUseProgram(program = wanted);
        glBindBufferRange(GL_UNIFORM_BUFFER, kHeightPassBinding, heightUbo,
                          static_cast<GLintptr>(stride * (k + 1)), sizeof(HeightPassBlock));
        glBindTexture(GL_TEXTURE_2D, textures[k]);
        checkDrawBindings("height pass");
        glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
    }
    glDisable(GL_BLEND);
}

Status Renderer::Impl::bakeHeightMaps(const HeightPassInput& in, HeightMaps& maps) {
    if (auto s = heightPass(in); !s) return s;
    return readHeightTargets(maps);
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
    ++heightsWritten;
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

} // namespace dermis
