// The renderer's model uploads: buffers and textures once per Model object, the joint palette
// per job (see renderer_impl.hpp).
#include "renderer_impl.hpp"

#include "uniform_blocks.hpp"

#include "core/camera.hpp"

#include <algorithm>
#include <cmath>

namespace dermis {

using namespace gl;

GLuint GpuModel::baseColorTexture(const Model& model, const Part& part) const {
    if (part.material < 0 || static_cast<std::size_t>(part.material) >= model.materials.size())
        return 0;
    const int ti = model.materials[static_cast<std::size_t>(part.material)].baseColorTexture;
    return ti >= 0 && static_cast<std::size_t>(ti) < textures.size()
               ? textures[static_cast<std::size_t>(ti)]
               : 0;
}

namespace {

void destroyParts(std::vector<GpuModel::Part>& parts) {
    for (GpuModel::Part& p : parts) {
        glDeleteVertexArrays(1, &p.vao);
        glDeleteBuffers(static_cast<GLsizei>(std::size(p.buffers)), p.buffers);
    }
    parts.clear();
}

} // namespace

void GpuModel::destroy() {
    destroyParts(parts);
    for (auto& [key, lp] : layouts) destroyParts(lp.parts);
    layouts.clear();
    if (!textures.empty()) glDeleteTextures(static_cast<GLsizei>(textures.size()), textures.data());
    textures.clear();
    for (GLuint& t : dataTextures)
        if (t) glDeleteTextures(1, &t);
    dataTextures.clear();
}

namespace {

/// sRGB code → linear light, and linear light (as a 16-bit index) → nearest sRGB code.
struct SrgbTables {
    float toLinear[256];
    std::uint8_t toSrgb[65536];
    SrgbTables() {
        for (int c = 0; c < 256; ++c) {
            const double v = c / 255.0;
            toLinear[c] = static_cast<float>(v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4));
        }
        for (int i = 0; i < 65536; ++i) {
            const double l = (i + 0.5) / 65536.0;
            const double v = l <= 0.0031308 ? 12.92 * l : 1.055 * std::pow(l, 1.0 / 2.4) - 0.055;
            toSrgb[i] = static_cast<std::uint8_t>(std::clamp(std::lround(v * 255.0), 0L, 255L));
        }
    }
};

/// The next mip level of an sRGB RGBA8 image: each texel the mean of its 2×2 (or 2×1, 1×2)
/// source texels, colour averaged in linear light, alpha as stored. What glGenerateMipmap does
/// for sRGB textures, on the CPU: llvmpipe's blit-based glGenerateMipmap took 150–300 ms for a
/// 1024² texture (the JIT of its blit shaders, on every process start), this takes ~5 ms.
Image8 halveSrgb(const Image8& src, const SrgbTables& t, bool linear = false) {
    Image8 dst;
    dst.width = std::max(1, src.width / 2);
    dst.height = std::max(1, src.height / 2);
    dst.rgba.resize(static_cast<std::size_t>(dst.width) * dst.height * 4);
    const int sx = src.width > 1 ? 2 : 1, sy = src.height > 1 ? 2 : 1;
    const float inv = 1.0f / static_cast<float>(sx * sy);
    for (int y = 0; y < dst.height; ++y)
        for (int x = 0; x < dst.width; ++x) {
            float acc[4] = {0, 0, 0, 0};
            for (int j = 0; j < sy; ++j)
                for (int i = 0; i < sx; ++i) {
                    const std::uint8_t* p =
                        &src.rgba[(static_cast<std::size_t>(y * sy + j) * src.width + x * sx + i) * 4];
                    for (int c = 0; c < 3; ++c)
                        acc[c] += linear ? p[c] / 255.0f : t.toLinear[p[c]];
                    acc[3] += p[3];
                }
            std::uint8_t* d = &dst.rgba[(static_cast<std::size_t>(y) * dst.width + x) * 4];
            for (int c = 0; c < 3; ++c)
                d[c] = linear ? static_cast<std::uint8_t>(std::lround(acc[c] * inv * 255.0f))
                              : t.toSrgb[std::min(65535, static_cast<int>(acc[c] * inv * 65536.0f))];
            d[3] = static_cast<std::uint8_t>(std::lround(acc[3] * inv));
        }
    return dst;
}

/// An sRGB texture of `img` with mipmaps (`linear`: RGBA8, for data such as normal maps, mips
/// averaged as stored); a 1×1 white one when `img` is empty or malformed. Wraps (glTF's default
/// sampler).
GLuint uploadImage(const Image8& img, bool linear = false) {
    const GLenum format = linear ? GL_RGBA8 : GL_SRGB8_ALPHA8;
    GLuint tex = 0;
    glGenTextures(1, &tex);
    glBindTexture(GL_TEXTURE_2D, tex);
    if (img.width > 0 && img.height > 0 &&
        img.rgba.size() == static_cast<std::size_t>(img.width) * img.height * 4) {
        const int levels =
            1 + static_cast<int>(std::floor(std::log2(std::max(img.width, img.height))));
        glTexStorage2D(GL_TEXTURE_2D, levels, format, img.width, img.height);
        glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
        glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, img.width, img.height, GL_RGBA, GL_UNSIGNED_BYTE,
                        img.rgba.data());
        static const SrgbTables tables;
        Image8 level;
        const Image8* prev = &img;
        for (int k = 1; k < levels; ++k) {
            level = halveSrgb(*prev, tables, linear);
            glTexSubImage2D(GL_TEXTURE_2D, k, 0, 0, level.width, level.height, GL_RGBA,
                            GL_UNSIGNED_BYTE, level.rgba.data());
            prev = &level;
        }
        // Bilinear within the nearest mip level: half the fetches of trilinear.
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_NEAREST);
    } else {
        const std::uint8_t white[4] = {255, 255, 255, 255};
        glTexStorage2D(GL_TEXTURE_2D, 1, format, 1, 1);
        glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, white);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    }
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    return tex;
}

/// Estimated GPU bytes of `m`'s upload: 56 per vertex (position, normal, uv, joints, weights),
/// 4 per index, 4 per texel of each image plus a third for its mipmaps.
std::size_t uploadBytes(const Model& m) {
    std::size_t bytes = 0;
    for (const MeshPart& part : m.parts)
        bytes += part.positions.size() * 56 + part.indices.size() * 4 +
                 (part.tangents.size() + part.colors.size()) * 16 + part.uvs1.size() * 8 +
                 part.morphs.size() * part.positions.size() * 48;
    for (const Image8& img : m.images)
        bytes += static_cast<std::size_t>(std::max(img.width, 1)) * std::max(img.height, 1) * 4 * 4 / 3;
    for (const Material& mat : m.materials) // the linear copies (counted per use: an upper bound)
        for (int t : {mat.metallicRoughnessTexture, mat.normalTexture, mat.occlusionTexture})
            if (t >= 0 && static_cast<std::size_t>(t) < m.images.size())
                bytes += static_cast<std::size_t>(std::max(m.images[static_cast<std::size_t>(t)].width, 1)) *
                         std::max(m.images[static_cast<std::size_t>(t)].height, 1) * 4 * 4 / 3;
    return bytes;
}

/// A part's vertex attributes as the CPU skinning reads them: missing normals are computed,
/// missing UVs are zero, a vertex without joint data follows influence 0, out-of-range joints
/// weigh 0; triangles with an out-of-range index are dropped.
struct PartAttributes {
    std::vector<glm::vec3> normals;
    std::vector<glm::vec2> uvs;
    std::vector<glm::vec4> tangents; ///< empty, or one per vertex (MeshPart::tangents)
    std::vector<glm::vec2> uvs1;     ///< empty, or one per vertex
    std::vector<glm::vec4> colors;   ///< empty, or one per vertex
    std::vector<glm::u16vec4> joints;
    std::vector<glm::vec4> weights;
    std::vector<std::uint32_t> indices;
};

PartAttributes partAttributes(const MeshPart& part, bool hasUVs) {
    const std::size_t nv = part.positions.size();
    PartAttributes a;
    a.normals = part.normals.size() == nv ? part.normals : computeNormals(part.positions, part.indices);
    a.uvs = hasUVs ? part.uvs : std::vector<glm::vec2>(nv, glm::vec2(0.0f));
    if (part.tangents.size() == nv) a.tangents = part.tangents;
    if (part.uvs1.size() == nv) a.uvs1 = part.uvs1;
    if (part.colors.size() == nv) a.colors = part.colors;
    a.joints.assign(nv, glm::u16vec4(0));
    a.weights.assign(nv, glm::vec4(1.0f, 0.0f, 0.0f, 0.0f));
    if (part.joints.size() == nv && part.weights.size() == nv) {
        const std::size_t ni = part.influences.size();
        for (std::size_t v = 0; v < nv; ++v)
            for (int c = 0; c < 4; ++c) {
                const bool ok = part.joints[v][c] < ni;
                a.joints[v][c] = ok ? part.joints[v][c] : 0;
                a.weights[v][c] = ok ? part.weights[v][c] : 0.0f;
            }
    }
    a.indices.reserve(part.indices.size());
    for (std::size_t i = 0; i + 2 < part.indices.size(); i += 3)
        if (part.indices[i] < nv && part.indices[i + 1] < nv && part.indices[i + 2] < nv)
            a.indices.insert(a.indices.end(), part.indices.begin() + static_cast<long>(i),
                             part.indices.begin() + static_cast<long>(i) + 3);
    return a;
}

/// Vertex attribute `slot` of the bound vertex array from `buffer`, filled with `bytes` of
/// `data` (`data` null: the buffer is already filled).
void attribute(GLuint buffer, int slot, const void* data, std::size_t bytes, GLint comps,
               GLenum type, bool integer) {
    glBindBuffer(GL_ARRAY_BUFFER, buffer);
    if (data || bytes == 0)
        glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(bytes), bytes ? data : nullptr,
                     GL_STATIC_DRAW);
    glEnableVertexAttribArray(static_cast<GLuint>(slot));
    if (integer)
        glVertexAttribIPointer(static_cast<GLuint>(slot), comps, type, 0, nullptr);
    else
        glVertexAttribPointer(static_cast<GLuint>(slot), comps, type, GL_FALSE, 0, nullptr);
}

/// Attribute slots 0–5 (shaders/skin.vert) and the indices of one part into a new vertex array
/// of `gp`. `mapUvs` null: slot 5 reads the uv buffer (the maps use the model's UVs).
void uploadArrays(GpuModel::Part& gp, const std::vector<glm::vec3>& positions,
                  const PartAttributes& a, const std::vector<glm::vec2>* mapUvs) {
    const std::size_t nv = positions.size();
    gp.indexCount = static_cast<GLsizei>(a.indices.size());
    gp.vertexCount = static_cast<GLsizei>(nv);
    glGenVertexArrays(1, &gp.vao);
    glBindVertexArray(gp.vao);
    glGenBuffers(mapUvs ? 7 : 6, gp.buffers);
    // Slots 6–8 only where the part has them (the shader reads them only when PartBlock says so).
    const std::vector<glm::vec4>* extras4[2] = {&a.tangents, &a.colors};
    const int extraSlots4[2] = {6, 8};
    const int extraBuffers4[2] = {7, 9};
    for (int k = 0; k < 2; ++k) {
        if (extras4[k]->size() != nv || nv == 0) continue;
        glGenBuffers(1, &gp.buffers[extraBuffers4[k]]);
        attribute(gp.buffers[extraBuffers4[k]], extraSlots4[k], extras4[k]->data(),
                  nv * sizeof(glm::vec4), 4, GL_FLOAT, false);
    }
    if (a.uvs1.size() == nv && nv > 0) {
        glGenBuffers(1, &gp.buffers[8]);
        attribute(gp.buffers[8], 7, a.uvs1.data(), nv * sizeof(glm::vec2), 2, GL_FLOAT, false);
    }
    gp.hasTangents = a.tangents.size() == nv && nv > 0;
    gp.hasColors = a.colors.size() == nv && nv > 0;
    gp.hasUVs1 = a.uvs1.size() == nv && nv > 0;
    attribute(gp.buffers[0], 0, positions.data(), nv * sizeof(glm::vec3), 3, GL_FLOAT, false);
    attribute(gp.buffers[1], 1, a.normals.data(), nv * sizeof(glm::vec3), 3, GL_FLOAT, false);
    attribute(gp.buffers[2], 2, a.uvs.data(), nv * sizeof(glm::vec2), 2, GL_FLOAT, false);
    attribute(gp.buffers[3], 3, a.joints.data(), nv * sizeof(glm::u16vec4), 4, GL_UNSIGNED_SHORT, true);
    attribute(gp.buffers[4], 4, a.weights.data(), nv * sizeof(glm::vec4), 4, GL_FLOAT, false);
    if (mapUvs)
        attribute(gp.buffers[6], 5, mapUvs->data(), nv * sizeof(glm::vec2), 2, GL_FLOAT, false);
    else
        attribute(gp.buffers[2], 5, nullptr, nv * sizeof(glm::vec2), 2, GL_FLOAT, false);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, gp.buffers[5]);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER,
                 static_cast<GLsizeiptr>(a.indices.size() * sizeof(std::uint32_t)),
                 a.indices.empty() ? nullptr : a.indices.data(), GL_STATIC_DRAW);
    glBindVertexArray(0);
}

/// The morph deltas of `part` into buffers[10] (skin.vert's MorphDeltas): per target k and
/// vertex v three vec4 at ((k·nv + v)·3), the position, normal and tangent deltas (zero where the
/// target has none). Vertex v reads source vertex (*source)[v] (null: v itself; layout parts).
/// Returns the bytes uploaded (0 without targets).
std::size_t uploadMorphs(const MeshPart& part, const std::vector<std::uint32_t>* source, GpuModel::Part& gp) {
    const std::size_t np = part.positions.size();
    const std::size_t nv = source ? source->size() : np;
    const std::size_t targets = part.morphs.size();
    if (targets == 0 || nv == 0) return 0;
    std::vector<glm::vec4> deltas(targets * nv * 3, glm::vec4(0.0f));
    for (std::size_t k = 0; k < targets; ++k) {
        const MorphTarget& t = part.morphs[k];
        const std::vector<glm::vec3>* arrays[3] = {&t.positions, &t.normals, &t.tangents};
        for (std::size_t v = 0; v < nv; ++v) {
            const std::size_t s = source ? (*source)[v] : v;
            for (int a = 0; a < 3; ++a)
                if (arrays[a]->size() == np && s < np)
                    deltas[(k * nv + v) * 3 + static_cast<std::size_t>(a)] = glm::vec4((*arrays[a])[s], 0.0f);
        }
    }
    glGenBuffers(1, &gp.buffers[10]);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, gp.buffers[10]);
    glBufferData(GL_SHADER_STORAGE_BUFFER, static_cast<GLsizeiptr>(deltas.size() * sizeof(glm::vec4)),
                 deltas.data(), GL_STATIC_DRAW);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, 0);
    return deltas.size() * sizeof(glm::vec4);
}

/// The vertex array and buffers of one part with the model's own UVs as the maps' UVs.
void uploadPart(const MeshPart& part, GpuModel::Part& gp) {
    gp.hasMapUVs = gp.hasUVs;
    uploadArrays(gp, part.positions, partAttributes(part, gp.hasUVs), nullptr);
    uploadMorphs(part, nullptr, gp);
}

/// Whether `pl` is part `part`'s own UVs (what modelTextureLayout makes of it): identity source,
/// the part's indices and UVs; or empty where the part has no UVs.
bool isModelLayout(const MeshPart& part, const PartLayout& pl, bool partHasUVs) {
    if (pl.indices.empty()) return !partHasUVs || part.indices.empty();
    if (!partHasUVs || pl.source.size() != part.positions.size() || pl.indices != part.indices ||
        pl.uvs.size() != pl.source.size())
        return false;
    for (std::uint32_t v = 0; v < pl.source.size(); ++v)
        if (pl.source[v] != v || pl.uvs[v] != part.uvs[v]) return false;
    return true;
}

/// The vertex array and buffers of `part` split as layout part `pl` (SPEC §8): each layout
/// vertex copies its source vertex (position, normal, joints, weights, the model's UV for the
/// base colour), with the layout's UV as the map UV; the layout's triangles (any with an index
/// out of range dropped). Returns the bytes uploaded.
std::size_t uploadLayoutPart(const MeshPart& part, const PartLayout& pl, GpuModel::Part& gp) {
    const std::size_t nv = part.positions.size();
    const PartAttributes src = partAttributes(part, gp.hasUVs);
    const std::size_t lv = std::min(pl.source.size(), pl.uvs.size());
    std::vector<std::uint32_t> source(lv);
    for (std::size_t v = 0; v < lv; ++v) source[v] = pl.source[v] < nv ? pl.source[v] : 0;
    PartAttributes a;
    std::vector<glm::vec3> positions(lv);
    a.normals.resize(lv);
    a.uvs.resize(lv);
    a.joints.resize(lv);
    a.weights.resize(lv);
    if (!src.tangents.empty()) a.tangents.resize(lv);
    if (!src.uvs1.empty()) a.uvs1.resize(lv);
    if (!src.colors.empty()) a.colors.resize(lv);
    for (std::size_t v = 0; v < lv; ++v) {
        const std::uint32_t s = source[v];
        positions[v] = nv ? part.positions[s] : glm::vec3(0.0f);
        a.normals[v] = nv ? src.normals[s] : glm::vec3(0, 0, 1);
        a.uvs[v] = nv ? src.uvs[s] : glm::vec2(0.0f);
        a.joints[v] = nv ? src.joints[s] : glm::u16vec4(0);
        a.weights[v] = nv ? src.weights[s] : glm::vec4(1, 0, 0, 0);
        if (!a.tangents.empty()) a.tangents[v] = src.tangents[s];
        if (!a.uvs1.empty()) a.uvs1[v] = src.uvs1[s];
        if (!a.colors.empty()) a.colors[v] = src.colors[s];
    }
    std::vector<glm::vec2> mapUvs(pl.uvs.begin(), pl.uvs.begin() + static_cast<long>(lv));
    for (std::size_t i = 0; i + 2 < pl.indices.size(); i += 3)
        if (pl.indices[i] < lv && pl.indices[i + 1] < lv && pl.indices[i + 2] < lv &&
            pl.source[pl.indices[i]] < nv && pl.source[pl.indices[i + 1]] < nv &&
            pl.source[pl.indices[i + 2]] < nv)
            a.indices.insert(a.indices.end(), pl.indices.begin() + static_cast<long>(i),
                             pl.indices.begin() + static_cast<long>(i) + 3);
    gp.hasMapUVs = !a.indices.empty();
    uploadArrays(gp, positions, a, &mapUvs);
    const std::size_t morphBytes = uploadMorphs(part, &source, gp);
    return lv * 64 + a.indices.size() * 4 + morphBytes;
}

} // namespace

void Renderer::Impl::dropOrphanedModels() {
    // Their address may be reused by a new model.
    for (auto it = models.begin(); it != models.end();) {
        if (it->second.owner.expired()) {
            eraseModel(it++);
        } else {
            ++it;
        }
    }
}

Result<GpuModel*> Renderer::Impl::modelFor(const std::shared_ptr<const Model>& model) {
    if (!model) return makeError(ErrorCode::InvalidArgument, kWhere, "model", "no model");
    dropOrphanedModels();
    auto found = models.find(model.get());
    if (found != models.end()) {
        found->second.lastUse = useCounter;
        return &found->second;
    }

    const Model& m = *model;
    GpuModel gm;
    gm.owner = model;
    gm.autoDisplacement = autoDisplacementScale(m);
    gm.bytes = uploadBytes(m);
    gm.lastUse = useCounter;
    makeRoom(gm.bytes);
    // Images a material reads as data get a linear texture too (the sRGB one decodes colour).
    std::vector<char> asData(m.images.size(), 0);
    for (const Material& mat : m.materials)
        for (int t : {mat.metallicRoughnessTexture, mat.normalTexture, mat.occlusionTexture})
            if (t >= 0 && static_cast<std::size_t>(t) < asData.size()) asData[static_cast<std::size_t>(t)] = 1;
    for (std::size_t i = 0; i < m.images.size(); ++i) {
        gm.textures.push_back(uploadImage(m.images[i]));
        gm.dataTextures.push_back(asData[i] ? uploadImage(m.images[i], true) : 0);
    }
    for (const MeshPart& part : m.parts) {
        GpuModel::Part gp;
        const std::size_t nv = part.positions.size();
        gp.vertexCount = static_cast<GLsizei>(nv);
        gp.paletteOffset = gm.paletteSize;
        gm.paletteSize += std::max<int>(1, static_cast<int>(part.influences.size()));
        gp.morphTargets = static_cast<int>(part.morphs.size());
        gp.morphWeightOffset = gm.morphWeightCount;
        gm.morphWeightCount += gp.morphTargets;
        gp.material = part.material;
        gp.hasUVs = part.uvs.size() == nv && nv > 0;
        uploadPart(part, gp);
        gm.parts.push_back(gp);
    }
    if (auto s = checkGl("uploading a model"); !s) {
        gm.destroy();
        return s.error();
    }
    modelBytes += gm.bytes;
    auto [it, inserted] = models.emplace(model.get(), std::move(gm));
    return &it->second;
}

Result<const std::vector<GpuModel::Part>*> Renderer::Impl::partsFor(
    const Model& model, GpuModel& gm, const std::shared_ptr<const TextureLayout>& layout) {
    // Layouts whose owner is gone: their address may be reused by a new one.
    for (auto it = gm.layouts.begin(); it != gm.layouts.end();) {
        if (it->second.owner.expired()) {
            destroyParts(it->second.parts);
            gm.bytes -= it->second.bytes;
            modelBytes -= it->second.bytes;
            it = gm.layouts.erase(it);
        } else {
            ++it;
        }
    }
    if (!layout) return &gm.parts;
    if (auto it = gm.layouts.find(layout.get()); it != gm.layouts.end())
        return it->second.identity ? &gm.parts : &it->second.parts;
    if (layout->parts.size() != model.parts.size())
        return makeError(ErrorCode::InvalidArgument, kWhere, "layout",
                         "the height-map layout has " + std::to_string(layout->parts.size()) +
                             " parts, the model " + std::to_string(model.parts.size()));
    GpuModel::LayoutParts lp;
    lp.owner = layout;
    lp.identity = true;
    for (std::size_t k = 0; k < model.parts.size() && lp.identity; ++k)
        lp.identity = isModelLayout(model.parts[k], layout->parts[k], gm.parts[k].hasUVs);
    if (!lp.identity) {
        for (std::size_t k = 0; k < model.parts.size(); ++k) {
            GpuModel::Part gp = gm.parts[k]; // palette offset, material, hasUVs
            for (GLuint& b : gp.buffers) b = 0;
            gp.vao = 0;
            lp.bytes += uploadLayoutPart(model.parts[k], layout->parts[k], gp);
            lp.parts.push_back(gp);
        }
        if (auto s = checkGl("uploading a height-map layout"); !s) {
            destroyParts(lp.parts);
            return s.error();
        }
    }
    gm.bytes += lp.bytes;
    modelBytes += lp.bytes;
    auto [it, inserted] = gm.layouts.emplace(layout.get(), std::move(lp));
    return it->second.identity ? &gm.parts : &it->second.parts;
}

void Renderer::Impl::uploadPalette(const Model& model, const GpuModel& gm,
                                   const std::vector<glm::mat4>& world,
                                   const std::vector<float>& morphWeights) {
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

    // Each part's target weights from its MorphWeight entries (core morphWeightOf).
    // At least one vec4: the buffer also stands in for the MorphDeltas of parts without targets.
    std::vector<float> weights(static_cast<std::size_t>(std::max(gm.morphWeightCount, 4)), 0.0f);
    for (std::size_t pi = 0; pi < model.parts.size() && pi < gm.parts.size(); ++pi) {
        const MeshPart& part = model.parts[pi];
        const auto base = static_cast<std::size_t>(gm.parts[pi].morphWeightOffset);
        for (std::size_t k = 0; k < part.morphs.size() && base + k < weights.size(); ++k)
            weights[base + k] = morphWeightOf(model, part.morphs[k], morphWeights);
    }
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, morphWeightSsbo);
    glBufferData(GL_SHADER_STORAGE_BUFFER, static_cast<GLsizeiptr>(weights.size() * sizeof(float)),
                 weights.data(), GL_STREAM_DRAW);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kMorphWeightBinding, morphWeightSsbo);
}

void Renderer::Impl::bindMorphDeltas(const GpuModel::Part& gp) const {
    // A part without targets never reads the buffer; any buffer keeps the binding valid.
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kMorphDeltaBinding,
                     gp.buffers[10] ? gp.buffers[10] : morphWeightSsbo);
}

} // namespace dermis
