// Stage 1 of the renderer: pattern and base textures cached by content id (in the byte budget of
// gpu_cache.cpp), the height targets, the height pass (one quad per placement, additive), readback
// and upload of maps (see renderer_impl.hpp). On a software rasterizer a pass covering many map
// areas is baked by the CPU and uploaded (RendererOptions::softwareCpuBakeCoverage).
#include "gl/renderer_impl.hpp"

#include "gl/uniform_blocks.hpp"

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
    for (std::size_t k = 0; k < in.placements.size(); ++k) {
        if (!resolved.textures[k]) continue;
        const BakePlacement& p = in.placements[k];
        key.params.insert(key.params.end(),
                          {p.footprint.center.x, p.footprint.center.y, p.footprint.scale.x,
                           p.footprint.scale.y, p.footprint.rotationDeg, p.h, p.t,
                           double(static_cast<int>(p.model)), double(static_cast<int>(p.target)),
                           double(static_cast<int>(p.response))});
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

/// Whether this height pass is baked by the CPU (RendererOptions::softwareCpuBakeCoverage): a
/// software rasterizer and footprints covering more than `coverage` map areas.
bool bakeOnCpu(const HeightPassInput& in, double coverage, const std::string& glRenderer) {
    if (!(coverage > 0.0)) return false;
    const bool software = glRenderer.find("llvmpipe") != std::string::npos ||
                          glRenderer.find("softpipe") != std::string::npos ||
                          glRenderer.find("swrast") != std::string::npos;
    if (!software) return false;
    double covered = 0.0;
    for (const BakePlacement& p : in.placements)
        if (p.t > 0.0) covered += p.footprint.scale.x * p.footprint.scale.y;
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
    auto baseKey = resolveBase(in);
    if (!baseKey) return baseKey.error();
    if (auto s = ensureHeightTargets(W, H); !s) return s;

    HeightKey key = heightKey(in, *resolved, *baseKey);
    if (lastHeights && *lastHeights == key) {
        ++heightPassesSkipped;
        return Ok{};
    }
    lastHeights.reset();
    if (bakeOnCpu(in, softwareCpuBakeCoverage, info.renderer)) {
        BakeSettings settings;
        settings.width = W;
        settings.height = H;
        settings.base = in.base;
        if (auto s = dermis::bakeHeightMapsInto(in.placements, settings, cpuBake); !s) return s;
        if (auto s = uploadHeightMaps(cpuBake); !s) return s;
        lastHeights = std::move(key);
        ++heightPasses;
        ++heightPassesOnCpu;
        return Ok{};
    }
    const std::size_t stride = uploadHeightBlocks(in);
    drawHeightPass(in, resolved->textures, stride);
    if (auto st = checkGl("height pass"); !st) return st;
    lastHeights = std::move(key);
    ++heightPasses;
    return Ok{};
}

/// One block per placement in one buffer, bound by range per draw; slot 0 is the base draw's.
/// Returns the stride between blocks.
std::size_t Renderer::Impl::uploadHeightBlocks(const HeightPassInput& in) {
    const std::size_t stride = uboStride(sizeof(HeightPassBlock));
    const std::size_t count = in.placements.size() + 1;
    std::vector<std::uint8_t> blocks(stride * count, 0);
    HeightPassBlock baseBlock{};
    baseBlock.mapSize =
        glm::vec4(static_cast<float>(in.width), static_cast<float>(in.height), 0.0f, 0.0f);
    std::memcpy(blocks.data(), &baseBlock, sizeof baseBlock);
    for (std::size_t k = 0; k < in.placements.size(); ++k) {
        const HeightPassBlock b = placementBlock(in.placements[k], in.width, in.height);
        std::memcpy(blocks.data() + stride * (k + 1), &b, sizeof b);
    }
    glBindBuffer(GL_UNIFORM_BUFFER, heightUbo);
    glBufferData(GL_UNIFORM_BUFFER, static_cast<GLsizeiptr>(blocks.size()), blocks.data(),
                 GL_STREAM_DRAW);
    return stride;
}

/// The base map (or zeros), then every placement with a texture, summed by additive blending in
/// document order like the CPU reference.
void Renderer::Impl::drawHeightPass(const HeightPassInput& in, const std::vector<GLuint>& textures,
                                    std::size_t stride) {
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
        glDrawArrays(GL_TRIANGLES, 0, 3);
    } else {
        glClearBufferfv(GL_COLOR, 0, zero);
    }
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
