// The skin pass's `pbr` shading (render.shading; see renderer_impl.hpp): the image-based light
// (the default studio environment prefiltered on the CPU by core/environment, uploaded once), a
// part's glTF material into its PartBlock and texture units, and the draw order of alpha modes
// (opaque and masked parts first, blended ones after them, farthest first).
#include "renderer_impl.hpp"

#include "uniform_blocks.hpp"

#include "core/environment.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace dermis {

using namespace gl;

namespace {

/// Texture units of the material's textures (pbr.glsl's bindings; unit 2 is the base colour's,
/// shared with the legacy shading).
constexpr GLenum kUnitBaseColor = GL_TEXTURE2, kUnitMetallicRoughness = GL_TEXTURE3,
                 kUnitNormal = GL_TEXTURE4, kUnitOcclusion = GL_TEXTURE5,
                 kUnitEmissive = GL_TEXTURE6, kUnitEnvSpecular = GL_TEXTURE7,
                 kUnitBrdfLut = GL_TEXTURE8;

/// `img` resampled to w × h by direction (bilinear lookups of the equirectangular image): a
/// prefiltered level at the size its mip level needs.
EnvironmentImage resampled(const EnvironmentImage& img, int w, int h) {
    if (img.width == w && img.height == h) return img;
    EnvironmentImage out;
    out.width = w;
    out.height = h;
    out.texels.resize(static_cast<std::size_t>(w) * h);
    for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i) {
            const glm::vec2 uv((static_cast<float>(i) + 0.5f) / static_cast<float>(w),
                               1.0f - (static_cast<float>(j) + 0.5f) /
                                          static_cast<float>(h)); // (u, v_up)
            out.texels[static_cast<std::size_t>(j) * w + i] =
                sampleEquirect(img, equirectDirection(uv));
        }
    return out;
}

GLuint imageTexture(const std::vector<GLuint>& textures, int image) {
    return image >= 0 && static_cast<std::size_t>(image) < textures.size()
               ? textures[static_cast<std::size_t>(image)]
               : 0;
}

/// The default studio environment prefiltered, once per process (the first caller computes it,
/// ≈ 0.1 s; C++ statics make the others wait): every renderer of a process (a server's, a test
/// suite's many) shares the same deterministic result instead of prefiltering it again.
const PrefilteredEnvironment& studioPrefiltered() {
    static const PrefilteredEnvironment pre = prefilterEnvironment(studioEnvironment());
    return pre;
}

constexpr int kBrdfLutSize = 32;

/// The split-sum DFG table (core brdfLut), once per process like studioPrefiltered.
const std::vector<glm::vec2>& defaultBrdfLut() {
    static const std::vector<glm::vec2> lut = brdfLut(kBrdfLutSize);
    return lut;
}

} // namespace

void gl::warmStudioLighting() {
    defaultBrdfLut();
    studioPrefiltered();
}

const Material* gl::materialOf(const Model& model, const GpuModel::Part& gp) {
    if (gp.material < 0 || static_cast<std::size_t>(gp.material) >= model.materials.size())
        return nullptr;
    return &model.materials[static_cast<std::size_t>(gp.material)];
}

Result<const Renderer::Impl::EnvironmentLight*>
Renderer::Impl::environmentLight(const std::shared_ptr<const EnvironmentImage>& env) {
    if (!brdfLutTexture) {
        const int lutSize = kBrdfLutSize;
        const std::vector<glm::vec2>& lut = defaultBrdfLut();
        glGenTextures(1, &brdfLutTexture);
        glBindTexture(GL_TEXTURE_2D, brdfLutTexture);
        glTexStorage2D(GL_TEXTURE_2D, 1, GL_RG16F, lutSize, lutSize);
        glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, lutSize, lutSize, GL_RG, GL_FLOAT, lut.data());
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    }
    EnvironmentLight* light = &studioLight;
    if (env) {
        if (customKey == env.get() && !customOwner.expired() && customLight.specular) return &customLight;
        if (auto s = validateEnvironment(*env); !s)
            return makeError(ErrorCode::InvalidArgument, kWhere, "environment", s.error().message);
        customLight.destroy();
        customOwner = env;
        customKey = env.get();
        light = &customLight;
    } else if (studioLight.specular) {
        return &studioLight;
    }
    PrefilteredEnvironment custom;
    if (env) custom = prefilterEnvironment(*env);
    const PrefilteredEnvironment& pre = env ? custom : studioPrefiltered();
    for (std::size_t k = 0; k < 9; ++k) light->block.irradianceSh[k] = glm::vec4(pre.irradianceSh[k], 0.0f);
    const int levels = static_cast<int>(pre.specular.size());
    light->block.params = glm::vec4(1.0f, 1.0f, 0.0f, static_cast<float>(std::max(levels - 1, 0)));
    glGenTextures(1, &light->specular);
    glBindTexture(GL_TEXTURE_2D, light->specular);
    const int w0 = pre.specular.empty() ? 1 : pre.specular[0].width;
    const int h0 = pre.specular.empty() ? 1 : pre.specular[0].height;
    glTexStorage2D(GL_TEXTURE_2D, std::max(levels, 1), GL_RGB16F, w0, h0);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    for (int k = 0; k < levels; ++k) {
        // Level k of the mip chain holds roughness k/(levels−1) at the chain's size.
        const EnvironmentImage level = resampled(pre.specular[static_cast<std::size_t>(k)],
                                                 std::max(1, w0 >> k), std::max(1, h0 >> k));
        glTexSubImage2D(GL_TEXTURE_2D, k, 0, 0, level.width, level.height, GL_RGB, GL_FLOAT,
                        level.texels.data());
    }
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    if (auto s = checkGl("uploading an environment"); !s) return s.error();
    return light;
}

void Renderer::Impl::uploadEnvironmentBlock(const EnvironmentLight& light, const RenderSettings& rs) {
    EnvironmentBlock eb = light.block;
    const double a = rs.environmentRotation * 3.14159265358979323846 / 180.0;
    eb.params.x = static_cast<float>(rs.exposure);
    eb.params.y = static_cast<float>(std::cos(a));
    eb.params.z = static_cast<float>(std::sin(a));
    eb.mode = glm::ivec4(rs.toneMapping == ToneMapping::Neutral ? 1
                         : rs.toneMapping == ToneMapping::Aces  ? 2
                                                                : 0,
                         0, 0, 0);
    glBindBuffer(GL_UNIFORM_BUFFER, environmentUbo);
    glBufferSubData(GL_UNIFORM_BUFFER, 0, sizeof eb, &eb);
    glBindBufferBase(GL_UNIFORM_BUFFER, kEnvironmentBinding, environmentUbo);
    glActiveTexture(kUnitEnvSpecular);
    glBindTexture(GL_TEXTURE_2D, light.specular);
    glActiveTexture(kUnitBrdfLut);
    glBindTexture(GL_TEXTURE_2D, brdfLutTexture);
}

namespace gl {

void fillMaterialBlock(PartBlock& pb, const Model& model, const GpuModel& gm,
                       const GpuModel::Part& gp) {
    const Material* mat = materialOf(model, gp);
    const Material fallback; // glTF's default material: white, metallic 1, roughness 1
    const Material& m = mat ? *mat : fallback;
    pb.emissive = glm::vec4(m.emissiveFactor, m.alphaCutoff);
    pb.material =
        glm::vec4(m.metallicFactor, m.roughnessFactor, m.normalScale, m.occlusionStrength);
    // The textures in pbr.glsl's order (materialUv's k): their UV sets and transforms.
    const TextureUv* uvs[5] = {&m.baseColorUv, &m.metallicRoughnessUv, &m.normalUv, &m.occlusionUv,
                               &m.emissiveUv};
    int uvSets = 0;
    for (int k = 0; k < 5; ++k) {
        if (uvs[k]->texCoord == 1) uvSets |= 1 << k;
        const glm::mat3 x = uvs[k]->matrix();
        pb.uvTransform[2 * k] = glm::vec4(x[0][0], x[1][0], x[2][0], 0.0f);
        pb.uvTransform[2 * k + 1] = glm::vec4(x[0][1], x[1][1], x[2][1], 0.0f);
    }
    const int alpha = m.alphaMode == AlphaMode::Mask ? 1 : m.alphaMode == AlphaMode::Blend ? 2 : 0;
    const int flags = (m.unlit ? kPartUnlit : 0) | (gp.hasTangents ? kPartTangents : 0) |
                      (gp.hasColors ? kPartColors : 0);
    pb.maps = glm::ivec4(materialMaps(model, gm, gp), alpha, flags, uvSets);
    if (!mat) pb.baseColor = glm::vec4(0.80f, 0.62f, 0.54f, 1.0f); // the legacy skin tone
    if (!mat) pb.material = glm::vec4(0.0f, 0.6f, 1.0f, 1.0f);     // a dielectric, not glTF's metal
}

int materialMaps(const Model& model, const GpuModel& gm, const GpuModel::Part& gp) {
    const Material* m = materialOf(model, gp);
    if (!m) return 0;
    const struct {
        int image;
        const TextureUv& uv;
        bool data;
        int bit;
    } maps[5] = {{m->baseColorTexture, m->baseColorUv, false, kMapBaseColor},
                 {m->metallicRoughnessTexture, m->metallicRoughnessUv, true, kMapMetallicRoughness},
                 {m->normalTexture, m->normalUv, true, kMapNormal},
                 {m->occlusionTexture, m->occlusionUv, true, kMapOcclusion},
                 {m->emissiveTexture, m->emissiveUv, false, kMapEmissive}};
    int present = 0;
    for (const auto& t : maps) {
        const bool uvOk = t.uv.texCoord == 1 ? gp.hasUVs1 : gp.hasUVs;
        if (imageTexture(t.data ? gm.dataTextures : gm.textures, t.image) && uvOk) present |= t.bit;
    }
    return present;
}

bool needsMaterialMaps(const Model& model, const GpuModel& gm, const std::vector<GpuModel::Part>& parts) {
    return std::any_of(parts.begin(), parts.end(), [&](const GpuModel::Part& gp) {
        return (materialMaps(model, gm, gp) & ~kMapBaseColor) != 0;
    });
}

void bindMaterialTextures(const Model& model, const GpuModel& gm, const GpuModel::Part& gp,
                          GLuint whiteTexture) {
    const Material* m = materialOf(model, gp);
    auto bind = [&](GLenum unit, const std::vector<GLuint>& textures, int image) {
        const GLuint t = m ? imageTexture(textures, image) : 0;
        glActiveTexture(unit);
        glBindTexture(GL_TEXTURE_2D, t ? t : whiteTexture);
    };
    bind(kUnitBaseColor, gm.textures, m ? m->baseColorTexture : -1);
    bind(kUnitMetallicRoughness, gm.dataTextures, m ? m->metallicRoughnessTexture : -1);
    bind(kUnitNormal, gm.dataTextures, m ? m->normalTexture : -1);
    bind(kUnitOcclusion, gm.dataTextures, m ? m->occlusionTexture : -1);
    bind(kUnitEmissive, gm.textures, m ? m->emissiveTexture : -1);
}

std::vector<std::size_t> pbrDrawOrder(const Model& model, const std::vector<GpuModel::Part>& parts,
                                      const std::vector<SkinnedPart>& posed, glm::vec3 eye) {
    std::vector<std::size_t> order(parts.size());
    std::iota(order.begin(), order.end(), std::size_t{0});
    auto blended = [&](std::size_t i) {
        const Material* m = materialOf(model, parts[i]);
        return m && m->alphaMode == AlphaMode::Blend;
    };
    auto distance = [&](std::size_t i) {
        if (i >= posed.size() || posed[i].positions.empty()) return 0.0f;
        glm::vec3 lo(posed[i].positions[0]), hi(lo);
        for (const glm::vec3& p : posed[i].positions) {
            lo = glm::min(lo, p);
            hi = glm::max(hi, p);
        }
        return glm::length(0.5f * (lo + hi) - eye);
    };
    std::vector<float> dist(parts.size());
    for (std::size_t i = 0; i < parts.size(); ++i)
        dist[i] = blended(i) ? distance(i) : 0.0f;
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        const bool ba = blended(a), bb = blended(b);
        if (ba != bb) return !ba;       // opaque and masked first
        return ba && dist[a] > dist[b]; // blended: farthest first
    });
    return order;
}

} // namespace gl
} // namespace dermis
