// glTF → Model for the loader of gltf_loader.hpp: the Converter reads the tinygltf model (nodes
// with rest TRS and parents, skins, metallic-roughness materials, the triangle primitives
// of the default scene's meshes, skin weights or rigid influences; animations and morph
// targets through gltf_animations.cpp and gltf_morph.cpp), validating
// everything it reads; accessors go through readAccessor (gltf_accessors.cpp).
#include "gltf_internal.hpp"

#include "core/rig.hpp"
#include "core/tangents.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <optional>

namespace dermis::gltf_detail {
namespace {

/// Most influences a skin may have (MeshPart::joints holds 16-bit indices).
constexpr std::size_t kMaxSkinJoints = 65536;

/// TRS of an affine column-major matrix without shear (glTF 2.0 §3.5.2 requires node matrices
/// to be decomposable so): T from column 3, S from the column lengths, R from the normalised
/// columns. A mirrored matrix (negative determinant) gets a negative x scale; a matrix with a
/// zero scale gets the identity rotation. False for projective matrices and for values outside
/// float range. (Written out rather than with glm::decompose, an experimental GLM extension that
/// divides by the column lengths and so returns NaN for a zero scale.)
bool decomposeTRS(const glm::dmat4& m, glm::vec3& t, glm::quat& r, glm::vec3& s) {
    if (std::abs(m[0][3]) > 1e-6 || std::abs(m[1][3]) > 1e-6 || std::abs(m[2][3]) > 1e-6 ||
        std::abs(m[3][3] - 1.0) > 1e-6)
        return false; // projective: not a TRS
    glm::dvec3 cols[3] = {glm::dvec3(m[0]), glm::dvec3(m[1]), glm::dvec3(m[2])};
    glm::dvec3 scale(glm::length(cols[0]), glm::length(cols[1]), glm::length(cols[2]));
    if (glm::dot(cols[0], glm::cross(cols[1], cols[2])) < 0.0) scale.x = -scale.x;
    glm::dmat3 rot(1.0);
    if (scale.x != 0.0 && scale.y != 0.0 && scale.z != 0.0)
        rot = glm::dmat3(cols[0] / scale.x, cols[1] / scale.y, cols[2] / scale.z);
    const glm::dquat q = glm::normalize(glm::quat_cast(rot));
    const glm::dvec3 translation(m[3]);
    for (int k = 0; k < 3; ++k)
        if (!fitsFloat(translation[k]) || !fitsFloat(scale[k])) return false;
    for (int k = 0; k < 4; ++k)
        if (!std::isfinite(q[k])) return false;
    t = glm::vec3(translation);
    r = glm::quat(q);
    s = glm::vec3(scale);
    return true;
}

/// glTF → Model, validating everything it reads.
class Converter {
  public:
    Converter(const tg::Model& g, Captured& captured) : g_(g), captured_(captured) {}

    Result<ParsedGltf> run() {
        if (auto s = nodes(); !s) return s.error();
        if (auto s = skins(); !s) return s.error();
        if (auto s = materials(); !s) return s.error();
        if (auto s = meshes(); !s) return s.error();
        if (auto s = convertAnimations(g_, m_, morphSlots_); !s) return s.error();
        ParsedGltf out;
        out.model = std::move(m_);
        out.images = std::move(pending_);
        return out;
    }

  private:
    const tg::Model& g_;
    Captured& captured_;
    Model m_;
    PendingImages pending_;
    std::vector<std::vector<Influence>> skinInfluences_;
    std::vector<glm::mat4> restWorld_;
    MorphSlots morphSlots_;

    // --- nodes: names, rest TRS, parents -----------------------------------------------------
    Status nodes() {
        const std::size_t n = g_.nodes.size();
        m_.nodes.resize(n);
        for (std::size_t i = 0; i < n; ++i) {
            const tg::Node& src = g_.nodes[i];
            Node& dst = m_.nodes[i];
            const std::string field = "/nodes/" + str(i);
            dst.name = src.name;
            if (!src.matrix.empty()) {
                if (src.matrix.size() != 16 || !allFitFloat(src.matrix))
                    return parseError(field + "/matrix", "must be 16 finite float numbers");
                glm::dmat4 mat;
                for (int c = 0; c < 4; ++c)
                    for (int r = 0; r < 4; ++r)
                        mat[c][r] = src.matrix[static_cast<std::size_t>(c * 4 + r)];
                if (!decomposeTRS(mat, dst.translation, dst.rotation, dst.scale))
                    return parseError(field + "/matrix", "is not a translation·rotation·scale");
            } else {
                if (!src.translation.empty()) {
                    if (src.translation.size() != 3 || !allFitFloat(src.translation))
                        return parseError(field + "/translation", "must be 3 finite float numbers");
                    dst.translation = glm::vec3(
                        glm::dvec3(src.translation[0], src.translation[1], src.translation[2]));
                }
                if (!src.rotation.empty()) {
                    if (src.rotation.size() != 4 || !allFitFloat(src.rotation))
                        return parseError(field + "/rotation", "must be 4 finite float numbers");
                    const glm::dquat q(src.rotation[3], src.rotation[0], src.rotation[1],
                                       src.rotation[2]);
                    const double len = glm::length(q);
                    if (!(len > 1e-6) || !std::isfinite(len))
                        return parseError(field + "/rotation", "is not a unit quaternion");
                    dst.rotation = glm::quat(q / len);
                }
                if (!src.scale.empty()) {
                    if (src.scale.size() != 3 || !allFitFloat(src.scale))
                        return parseError(field + "/scale", "must be 3 finite float numbers");
                    dst.scale = glm::vec3(glm::dvec3(src.scale[0], src.scale[1], src.scale[2]));
                }
            }
        }
        // Parents from children: each node has at most one parent and is not its own ancestor
        // (glTF 2.0 §3.5.3: the node hierarchy is a set of disjoint strict trees).
        for (std::size_t i = 0; i < n; ++i) {
            const auto& children = g_.nodes[i].children;
            for (std::size_t k = 0; k < children.size(); ++k) {
                const int c = children[k];
                const std::string field = "/nodes/" + str(i) + "/children/" + str(k);
                if (c < 0 || static_cast<std::size_t>(c) >= n)
                    return parseError(field, "node " + str(c) + " does not exist");
                if (static_cast<std::size_t>(c) == i)
                    return parseError(field, "a node cannot be its own child");
                if (m_.nodes[c].parent != -1)
                    return parseError(field, "node " + str(c) + " has more than one parent");
                m_.nodes[c].parent = static_cast<int>(i);
            }
        }
        // Cycles, in linear time: walk up from each node until a node already known to lead to
        // a root (2); meeting a node of the current walk (1) closes a cycle.
        std::vector<unsigned char> state(n, 0);
        std::vector<std::size_t> walk;
        for (std::size_t i = 0; i < n; ++i) {
            walk.clear();
            std::size_t k = i;
            while (state[k] == 0) {
                state[k] = 1;
                walk.push_back(k);
                if (m_.nodes[k].parent < 0) break;
                k = static_cast<std::size_t>(m_.nodes[k].parent);
            }
            if (state[k] == 1 && m_.nodes[k].parent >= 0)
                return parseError("/nodes/" + str(k), "the node hierarchy has a cycle");
            for (std::size_t w : walk)
                state[w] = 2;
        }
        restWorld_ = worldMatrices(m_, restPose(m_));
        return Ok{};
    }

    // --- skins: joints and inverse bind matrices ----------------------------------------------
    Status skins() {
        for (std::size_t s = 0; s < g_.skins.size(); ++s) {
            const tg::Skin& skin = g_.skins[s];
            const std::string field = "/skins/" + str(s);
            if (skin.joints.empty()) return parseError(field + "/joints", "no joints");
            if (skin.joints.size() > kMaxSkinJoints)
                return makeError(ErrorCode::Unsupported, kWhere, field + "/joints",
                                 "more than " + str(kMaxSkinJoints) + " joints");
            std::vector<Influence> infl(skin.joints.size());
            for (std::size_t k = 0; k < skin.joints.size(); ++k) {
                const int j = skin.joints[k];
                if (j < 0 || static_cast<std::size_t>(j) >= m_.nodes.size())
                    return parseError(field + "/joints/" + str(k),
                                      "node " + str(j) + " does not exist");
                infl[k].node = j;
                if (std::find(m_.joints.begin(), m_.joints.end(), j) == m_.joints.end())
                    m_.joints.push_back(j);
            }
            if (skin.inverseBindMatrices >= 0) {
                const std::string f = field + "/inverseBindMatrices";
                auto ibm = readAccessor(g_, skin.inverseBindMatrices, TINYGLTF_TYPE_MAT4,
                                        Want::Float, {TINYGLTF_COMPONENT_TYPE_FLOAT}, f);
                if (!ibm) return ibm.error();
                if (ibm->count < infl.size()) return parseError(f, "fewer matrices than joints");
                if (!allFitFloat(ibm->values)) return parseError(f, "non-finite value");
                for (std::size_t k = 0; k < infl.size(); ++k)
                    for (int c = 0; c < 4; ++c)
                        for (int r = 0; r < 4; ++r)
                            infl[k].inverseBind[c][r] = static_cast<float>(ibm->at(k, c * 4 + r));
            }
            skinInfluences_.push_back(std::move(infl));
        }
        return Ok{};
    }

    // --- materials: glTF metallic-roughness → Material, textures → compact Model::images -------
    std::map<int, int> imageSlot_; // glTF image → index in Model::images

    /// The Model::images index of glTF texture `tex` (its image captured for decoding on first
    /// use); −1 for a texture with no core `source` (e.g. only KHR_texture_basisu: untextured).
    Result<int> textureImage(int tex, const std::string& field) {
        if (static_cast<std::size_t>(tex) >= g_.textures.size())
            return parseError(field + "/index", "texture " + str(tex) + " does not exist");
        const int image = g_.textures[static_cast<std::size_t>(tex)].source;
        if (image < 0) return -1;
        if (static_cast<std::size_t>(image) >= g_.images.size())
            return parseError("/textures/" + str(tex) + "/source",
                              "image " + str(image) + " does not exist");
        auto [it, inserted] = imageSlot_.emplace(image, static_cast<int>(imageSlot_.size()));
        if (inserted) {
            auto cap = captured_.images.find(image);
            if (cap == captured_.images.end())
                return makeError(ErrorCode::NotFound, kWhere, "/images/" + str(image),
                                 "image data not available (external file missing "
                                 "or outside the model's folder)");
            PendingImages::Entry e = std::move(cap->second);
            e.imageIndex = it->second;
            pending_.entries.push_back(std::move(e));
        }
        return it->second;
    }

    /// A finite number (in float range) from the extension value `v` into `out`; false if not.
    static bool number(const tg::Value& v, float& out) {
        if (!v.IsNumber() || !fitsFloat(v.GetNumberAsDouble())) return false;
        out = static_cast<float>(v.GetNumberAsDouble());
        return true;
    }
    /// `n` finite numbers from the extension value `v` into `out`; false if not.
    static bool numbers(const tg::Value& v, int n, float* out) {
        if (!v.IsArray() || v.ArrayLen() != static_cast<std::size_t>(n)) return false;
        for (int k = 0; k < n; ++k)
            if (!number(v.Get(k), out[k])) return false;
        return true;
    }

    /// A textureInfo (index, texCoord, KHR_texture_transform) into `image` and `uv`. A texCoord
    /// other than 0 or 1 leaves the texture out (Dermis reads two UV sets).
    Status textureInfo(const tg::TextureInfo& info, const std::string& field, int& image,
                       TextureUv& uv) {
        return textureRef(info.index, info.texCoord, info.extensions, field, image, uv);
    }
    Status textureRef(int index, int texCoord, const tg::ExtensionMap& extensions,
                      const std::string& field, int& image, TextureUv& uv) {
        if (index < 0) return Ok{};
        uv.texCoord = texCoord;
        if (auto ext = extensions.find("KHR_texture_transform"); ext != extensions.end()) {
            const tg::Value& t = ext->second;
            const std::string f = field + "/extensions/KHR_texture_transform";
            if (t.Has("offset") && !numbers(t.Get("offset"), 2, &uv.offset.x))
                return parseError(f + "/offset", "must be 2 finite numbers");
            if (t.Has("scale") && !numbers(t.Get("scale"), 2, &uv.scale.x))
                return parseError(f + "/scale", "must be 2 finite numbers");
            if (t.Has("rotation") && !number(t.Get("rotation"), uv.rotation))
                return parseError(f + "/rotation", "must be a finite number");
            if (t.Has("texCoord")) {
                const tg::Value& tc = t.Get("texCoord");
                if (!tc.IsInt()) return parseError(f + "/texCoord", "must be an integer");
                uv.texCoord = tc.Get<int>();
            }
        }
        if (uv.texCoord < 0 || uv.texCoord > 1) return Ok{}; // TEXCOORD_2+: not read
        auto img = textureImage(index, field);
        if (!img) return img.error();
        image = *img;
        return Ok{};
    }

    Status materials() {
        for (std::size_t i = 0; i < g_.materials.size(); ++i) {
            const tg::Material& src = g_.materials[i];
            const std::string mfield = "/materials/" + str(i);
            const std::string field = mfield + "/pbrMetallicRoughness";
            const tg::PbrMetallicRoughness& pbr = src.pbrMetallicRoughness;
            Material dst;
            dst.name = src.name;
            const auto& f = pbr.baseColorFactor;
            if (!f.empty()) {
                if (f.size() != 4 || !allFitFloat(f))
                    return parseError(field + "/baseColorFactor", "must be 4 finite float numbers");
                dst.baseColorFactor = glm::vec4(glm::dvec4(f[0], f[1], f[2], f[3]));
            }
            if (!fitsFloat(pbr.metallicFactor))
                return parseError(field + "/metallicFactor", "must be a finite float number");
            if (!fitsFloat(pbr.roughnessFactor))
                return parseError(field + "/roughnessFactor", "must be a finite float number");
            dst.metallicFactor = static_cast<float>(pbr.metallicFactor);
            dst.roughnessFactor = static_cast<float>(pbr.roughnessFactor);
            if (auto s = textureInfo(pbr.baseColorTexture, field + "/baseColorTexture",
                                     dst.baseColorTexture, dst.baseColorUv);
                !s)
                return s;
            if (auto s = textureInfo(pbr.metallicRoughnessTexture,
                                     field + "/metallicRoughnessTexture",
                                     dst.metallicRoughnessTexture, dst.metallicRoughnessUv);
                !s)
                return s;
            const tg::NormalTextureInfo& nt = src.normalTexture;
            if (auto s = textureRef(nt.index, nt.texCoord, nt.extensions, mfield + "/normalTexture",
                                    dst.normalTexture, dst.normalUv);
                !s)
                return s;
            if (!fitsFloat(nt.scale))
                return parseError(mfield + "/normalTexture/scale", "must be a finite float number");
            dst.normalScale = static_cast<float>(nt.scale);
            const tg::OcclusionTextureInfo& ot = src.occlusionTexture;
            if (auto s = textureRef(ot.index, ot.texCoord, ot.extensions,
                                    mfield + "/occlusionTexture", dst.occlusionTexture,
                                    dst.occlusionUv);
                !s)
                return s;
            if (!fitsFloat(ot.strength))
                return parseError(mfield + "/occlusionTexture/strength",
                                  "must be a finite float number");
            dst.occlusionStrength = static_cast<float>(ot.strength);
            if (auto s = textureInfo(src.emissiveTexture, mfield + "/emissiveTexture",
                                     dst.emissiveTexture, dst.emissiveUv);
                !s)
                return s;
            if (!src.emissiveFactor.empty()) {
                const auto& e = src.emissiveFactor;
                if (e.size() != 3 || !allFitFloat(e))
                    return parseError(mfield + "/emissiveFactor", "must be 3 finite float numbers");
                dst.emissiveFactor = glm::vec3(glm::dvec3(e[0], e[1], e[2]));
            }
            if (auto ext = src.extensions.find("KHR_materials_emissive_strength");
                ext != src.extensions.end() && ext->second.Has("emissiveStrength")) {
                float strength = 1.0f;
                if (!number(ext->second.Get("emissiveStrength"), strength) || strength < 0.0f)
                    return parseError(mfield + "/extensions/KHR_materials_emissive_strength/"
                                               "emissiveStrength",
                                      "must be a finite number ≥ 0");
                dst.emissiveFactor *= strength;
            }
            if (src.alphaMode == "MASK") dst.alphaMode = AlphaMode::Mask;
            else if (src.alphaMode == "BLEND") dst.alphaMode = AlphaMode::Blend;
            else if (src.alphaMode != "OPAQUE" && !src.alphaMode.empty())
                return parseError(mfield + "/alphaMode",
                                  "must be OPAQUE, MASK or BLEND, not \"" + src.alphaMode + "\"");
            if (!fitsFloat(src.alphaCutoff))
                return parseError(mfield + "/alphaCutoff", "must be a finite float number");
            dst.alphaCutoff = static_cast<float>(src.alphaCutoff);
            dst.doubleSided = src.doubleSided;
            dst.unlit = src.extensions.count("KHR_materials_unlit") != 0;
            m_.materials.push_back(std::move(dst));
        }
        m_.images.resize(imageSlot_.size());
        return Ok{};
    }

    // --- meshes of the default scene --------------------------------------------------------
    Status meshes() {
        // Roots: the default scene, else scene 0, else every parentless node.
        std::vector<int> roots;
        if (!g_.scenes.empty()) {
            int scene = g_.defaultScene;
            if (scene < 0) scene = 0;
            if (static_cast<std::size_t>(scene) >= g_.scenes.size())
                return parseError("/scene", "scene " + str(scene) + " does not exist");
            const auto& list = g_.scenes[static_cast<std::size_t>(scene)].nodes;
            for (std::size_t k = 0; k < list.size(); ++k) {
                if (list[k] < 0 || static_cast<std::size_t>(list[k]) >= m_.nodes.size())
                    return parseError("/scenes/" + str(scene) + "/nodes/" + str(k),
                                      "node " + str(list[k]) + " does not exist");
                roots.push_back(list[k]);
            }
        } else {
            for (std::size_t i = 0; i < m_.nodes.size(); ++i)
                if (m_.nodes[i].parent < 0) roots.push_back(static_cast<int>(i));
        }
        // Depth-first, children in file order; each node once.
        std::vector<char> seen(m_.nodes.size(), 0);
        std::vector<int> stack(roots.rbegin(), roots.rend());
        while (!stack.empty()) {
            const int i = stack.back();
            stack.pop_back();
            if (seen[static_cast<std::size_t>(i)]) continue;
            seen[static_cast<std::size_t>(i)] = 1;
            if (auto s = meshNode(i); !s) return s.error();
            const auto& children = g_.nodes[static_cast<std::size_t>(i)].children;
            for (auto it = children.rbegin(); it != children.rend(); ++it)
                stack.push_back(*it);
        }
        return Ok{};
    }

    Status meshNode(int nodeIndex) {
        const tg::Node& node = g_.nodes[static_cast<std::size_t>(nodeIndex)];
        const std::string nodeField = "/nodes/" + str(nodeIndex);
        if (node.mesh < 0) return Ok{};
        if (static_cast<std::size_t>(node.mesh) >= g_.meshes.size())
            return parseError(nodeField + "/mesh", "mesh " + str(node.mesh) + " does not exist");
        if (node.skin >= 0 && static_cast<std::size_t>(node.skin) >= g_.skins.size())
            return parseError(nodeField + "/skin", "skin " + str(node.skin) + " does not exist");
        const tg::Mesh& mesh = g_.meshes[static_cast<std::size_t>(node.mesh)];
        if (auto s = addMorphWeights(g_, nodeIndex, m_, morphSlots_); !s) return s.error();
        const auto slots = morphSlots_.find(nodeIndex);
        const int firstWeight = slots != morphSlots_.end() ? slots->second.first : -1;
        for (std::size_t p = 0; p < mesh.primitives.size(); ++p) {
            const std::string field = "/meshes/" + str(node.mesh) + "/primitives/" + str(p);
            std::string name = !mesh.name.empty() ? mesh.name : node.name;
            if (mesh.primitives.size() > 1) name += "#" + str(p);
            if (auto s = primitive(nodeIndex, mesh.primitives[p], field, name, firstWeight); !s)
                return s.error();
        }
        return Ok{};
    }

    /// Reads the attribute `name` of `prim` (nullopt when absent), checking its vertex count.
    Result<std::optional<AccessorData>> attribute(const tg::Primitive& prim,
                                                  const std::string& name, int type, Want want,
                                                  std::initializer_list<int> allowed,
                                                  const std::string& primField,
                                                  std::size_t vertexCount) {
        auto it = prim.attributes.find(name);
        if (it == prim.attributes.end()) return std::optional<AccessorData>();
        const std::string field = primField + "/attributes/" + name;
        auto data = readAccessor(g_, it->second, type, want, allowed, field);
        if (!data) return data.error();
        if (vertexCount != 0 && data->count != vertexCount)
            return parseError(field,
                              str(data->count) + " elements, POSITION has " + str(vertexCount));
        if (!allFitFloat(data->values)) return parseError(field, "non-finite value");
        return std::optional<AccessorData>(std::move(*data));
    }

    Status primitive(int nodeIndex, const tg::Primitive& prim, const std::string& field,
                     const std::string& name, int firstWeight) {
        // Topology (glTF 2.0 §3.7.2.1): lists, strips and fans become lists; points and lines
        // are not surfaces and are skipped.
        const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
        if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
            mode != TINYGLTF_MODE_TRIANGLE_FAN) {
            if (mode >= TINYGLTF_MODE_POINTS && mode < TINYGLTF_MODE_TRIANGLES) return Ok{};
            return parseError(field + "/mode", "invalid mode " + str(mode));
        }
        if (prim.material >= 0 && static_cast<std::size_t>(prim.material) >= m_.materials.size())
            return parseError(field + "/material",
                              "material " + str(prim.material) + " does not exist");
        if (prim.material < -1)
            return parseError(field + "/material", "invalid index " + str(prim.material));

        MeshPart part;
        part.name = name;
        part.node = g_.nodes[static_cast<std::size_t>(nodeIndex)].name;
        part.material = prim.material;

        // POSITION
        auto pos = attribute(prim, "POSITION", TINYGLTF_TYPE_VEC3, Want::Float, {}, field, 0);
        if (!pos) return pos.error();
        if (!*pos) return parseError(field + "/attributes/POSITION", "missing");
        const std::size_t nv = (*pos)->count;
        if (nv == 0) return parseError(field + "/attributes/POSITION", "no vertices");
        part.positions.resize(nv);
        for (std::size_t v = 0; v < nv; ++v)
            part.positions[v] =
                glm::vec3(glm::dvec3((*pos)->at(v, 0), (*pos)->at(v, 1), (*pos)->at(v, 2)));
        for (const glm::vec3& p : part.positions)
            if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
                return parseError(field + "/attributes/POSITION", "value out of float range");

        // Indices → triangle list.
        std::vector<std::uint32_t> raw;
        if (prim.indices >= 0) {
            const std::string f = field + "/indices";
            auto idx = readAccessor(g_, prim.indices, TINYGLTF_TYPE_SCALAR, Want::Integer,
                                    {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                                     TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
                                     TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT},
                                    f);
            if (!idx) return idx.error();
            raw.resize(idx->count);
            for (std::size_t k = 0; k < idx->count; ++k) {
                const double v = idx->values[k];
                if (v >= static_cast<double>(nv))
                    return parseError(f, "index " + str(static_cast<std::size_t>(v)) +
                                             " out of range (" + str(nv) + " vertices)");
                raw[k] = static_cast<std::uint32_t>(v);
            }
        } else {
            raw.resize(nv);
            for (std::size_t k = 0; k < nv; ++k)
                raw[k] = static_cast<std::uint32_t>(k);
        }
        if (mode == TINYGLTF_MODE_TRIANGLES) {
            if (raw.size() % 3 != 0)
                return parseError(prim.indices >= 0 ? field + "/indices"
                                                    : field + "/attributes/POSITION",
                                  str(raw.size()) + " vertices is not a whole number of "
                                                    "triangles");
            part.indices = std::move(raw);
        } else if (raw.size() >= 3) {
            part.indices.reserve((raw.size() - 2) * 3);
            for (std::size_t i = 0; i + 2 < raw.size(); ++i) {
                if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
                    // {v_i, v_{i+(1+i%2)}, v_{i+(2−i%2)}}: every other triangle flips.
                    part.indices.insert(part.indices.end(),
                                        {raw[i], raw[i + 1 + i % 2], raw[i + 2 - i % 2]});
                } else {
                    part.indices.insert(part.indices.end(), {raw[i + 1], raw[i + 2], raw[0]});
                }
            }
        }

        // NORMAL (unit; computed where missing or zero)
        auto nrm = attribute(prim, "NORMAL", TINYGLTF_TYPE_VEC3, Want::Float, {}, field, nv);
        if (!nrm) return nrm.error();
        {
            std::vector<glm::vec3> computed;
            part.normals.resize(nv);
            for (std::size_t v = 0; v < nv; ++v) {
                glm::dvec3 n(0.0);
                if (*nrm) n = glm::dvec3((*nrm)->at(v, 0), (*nrm)->at(v, 1), (*nrm)->at(v, 2));
                const double len = glm::length(n);
                if (len > 1e-12) {
                    part.normals[v] = glm::vec3(n / len);
                } else {
                    if (computed.empty()) computed = computeNormals(part.positions, part.indices);
                    part.normals[v] = computed[v];
                }
            }
        }

        // TEXCOORD_0
        auto uv = attribute(prim, "TEXCOORD_0", TINYGLTF_TYPE_VEC2, Want::Float, {}, field, nv);
        if (!uv) return uv.error();
        if (*uv) {
            part.uvs.resize(nv);
            for (std::size_t v = 0; v < nv; ++v)
                part.uvs[v] = glm::vec2(glm::dvec2((*uv)->at(v, 0), (*uv)->at(v, 1)));
        }

        // TEXCOORD_1 (a texture's texCoord may name it)
        auto uv1 = attribute(prim, "TEXCOORD_1", TINYGLTF_TYPE_VEC2, Want::Float, {}, field, nv);
        if (!uv1) return uv1.error();
        if (*uv1) {
            part.uvs1.resize(nv);
            for (std::size_t v = 0; v < nv; ++v)
                part.uvs1[v] = glm::vec2(glm::dvec2((*uv1)->at(v, 0), (*uv1)->at(v, 1)));
        }

        // TANGENT (xyz unit, w ±1): kept only when every tangent is usable; else the shading
        // builds the frame per pixel.
        auto tan = attribute(prim, "TANGENT", TINYGLTF_TYPE_VEC4, Want::Float,
                             {TINYGLTF_COMPONENT_TYPE_FLOAT}, field, nv);
        if (!tan) return tan.error();
        if (*tan) {
            part.tangents.resize(nv);
            for (std::size_t v = 0; v < nv && !part.tangents.empty(); ++v) {
                const glm::dvec3 t((*tan)->at(v, 0), (*tan)->at(v, 1), (*tan)->at(v, 2));
                const double len = glm::length(t);
                if (!(len > 1e-6)) part.tangents.clear();
                else part.tangents[v] = glm::vec4(glm::vec3(t / len), (*tan)->at(v, 3) < 0.0 ? -1.0f : 1.0f);
            }
        }

        // COLOR_0 (RGB or RGBA; float or normalised integers), linear
        if (auto it = prim.attributes.find("COLOR_0"); it != prim.attributes.end()) {
            const bool rgb = it->second >= 0 &&
                             static_cast<std::size_t>(it->second) < g_.accessors.size() &&
                             g_.accessors[static_cast<std::size_t>(it->second)].type ==
                                 TINYGLTF_TYPE_VEC3;
            auto col = attribute(prim, "COLOR_0", rgb ? TINYGLTF_TYPE_VEC3 : TINYGLTF_TYPE_VEC4,
                                 Want::Float,
                                 {TINYGLTF_COMPONENT_TYPE_FLOAT,
                                  TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                                  TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT},
                                 field, nv);
            if (!col) return col.error();
            if (isIntegerType((*col)->componentType) && !(*col)->normalized)
                return parseError(field + "/attributes/COLOR_0",
                                  "integer colours must be normalized");
            part.colors.resize(nv);
            for (std::size_t v = 0; v < nv; ++v)
                part.colors[v] = glm::vec4(glm::dvec4((*col)->at(v, 0), (*col)->at(v, 1),
                                                      (*col)->at(v, 2),
                                                      rgb ? 1.0 : (*col)->at(v, 3)));
        }

        if (!prim.targets.empty())
            if (auto s = readMorphTargets(g_, prim, field, firstWeight, part); !s) return s.error();

        // Skinned (node has a skin and the primitive has JOINTS_0), else rigid on the node.
        const tg::Node& node = g_.nodes[static_cast<std::size_t>(nodeIndex)];
        const bool skinned = node.skin >= 0 && prim.attributes.count("JOINTS_0") != 0;
        if (skinned)
            if (auto s = skinWeights(prim, field, static_cast<std::size_t>(node.skin), part); !s)
                return s.error();
        // glTF §3.7.2.1: a normal-mapped primitive without TANGENT gets MikkTSpace tangents over
        // the normal texture's UV set, in the mesh's own space (before a rigid part moves to rest
        // world space, which turns them as it turns tangents read from the file).
        if (part.tangents.empty() && part.material >= 0) {
            const Material& mat = m_.materials[static_cast<std::size_t>(part.material)];
            const int set = mat.normalUv.texCoord;
            if (mat.normalTexture >= 0 && !(set == 1 ? part.uvs1 : part.uvs).empty()) {
                if (auto s = generateTangents(part, set); !s)
                    return parseError(field + "/attributes/TANGENT", s.error().message);
                part.tangentsGenerated = true;
            }
        }
        if (!skinned)
            if (auto s = rigid(nodeIndex, part); !s) return s.error();
        m_.parts.push_back(std::move(part));
        return Ok{};
    }

    /// JOINTS_n / WEIGHTS_n → the 4 largest influences per vertex, weights normalised (an
    /// all-zero vertex gets weight 1 on influence 0).
    Status skinWeights(const tg::Primitive& prim, const std::string& field, std::size_t skin,
                       MeshPart& part) {
        const std::size_t nv = part.positions.size();
        part.influences = skinInfluences_[skin];
        std::vector<AccessorData> joints, weights;
        for (int set = 0;; ++set) {
            const std::string jn = "JOINTS_" + std::to_string(set);
            const std::string wn = "WEIGHTS_" + std::to_string(set);
            auto j = attribute(
                prim, jn, TINYGLTF_TYPE_VEC4, Want::Integer,
                {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT},
                field, nv);
            if (!j) return j.error();
            auto w =
                attribute(prim, wn, TINYGLTF_TYPE_VEC4, Want::Float,
                          {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                           TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT},
                          field, nv);
            if (!w) return w.error();
            if (!*j && !*w) break;
            if (!*j || !*w)
                return parseError(field + "/attributes/" + (*j ? wn : jn),
                                  "missing (JOINTS_n and WEIGHTS_n come in pairs)");
            if (isIntegerType((*w)->componentType) && !(*w)->normalized)
                return parseError(field + "/attributes/" + wn,
                                  "integer weights must be normalized");
            joints.push_back(std::move(**j));
            weights.push_back(std::move(**w));
        }
        const std::size_t sets = joints.size();
        const std::size_t influenceCount = part.influences.size();
        part.joints.resize(nv);
        part.weights.resize(nv);
        std::vector<std::pair<double, std::size_t>> cand; // (weight, joint)
        for (std::size_t v = 0; v < nv; ++v) {
            cand.clear();
            for (std::size_t s = 0; s < sets; ++s) {
                for (int c = 0; c < 4; ++c) {
                    const double w = weights[s].at(v, c);
                    if (!(w > 0.0)) continue; // zero (or negative) weights do not count
                    const double j = joints[s].at(v, c);
                    if (j >= static_cast<double>(influenceCount))
                        return parseError(
                            field + "/attributes/JOINTS_" + str(s),
                            "vertex " + str(v) + ": joint " + str(static_cast<std::size_t>(j)) +
                                " out of range (skin has " + str(influenceCount) + ")");
                    cand.emplace_back(w, static_cast<std::size_t>(j));
                }
            }
            if (cand.size() > 4) {
                std::partial_sort(cand.begin(), cand.begin() + 4, cand.end(),
                                  [](const auto& a, const auto& b) { return a.first > b.first; });
                cand.resize(4);
            }
            double sum = 0.0;
            for (const auto& c : cand)
                sum += c.first;
            glm::u16vec4 jv(0);
            glm::vec4 wv(0.0f);
            if (!(sum > 0.0)) {
                wv.x = 1.0f; // no weight at all: follow influence 0
            } else {
                for (std::size_t k = 0; k < cand.size(); ++k) {
                    jv[static_cast<int>(k)] = static_cast<std::uint16_t>(cand[k].second);
                    wv[static_cast<int>(k)] = static_cast<float>(cand[k].first / sum);
                }
            }
            part.joints[v] = jv;
            part.weights[v] = wv;
        }
        return Ok{};
    }

    /// A mesh on a plain node: positions and normals baked into rest world space, one influence
    /// {node, inverse(restWorld(node))} (see MeshPart). When the rest world matrix is singular
    /// (a node scaled to zero at rest) the part stays in the node's local space with an identity
    /// inverse bind: posed positions are the same, only the bind space differs.
    Status rigid(int nodeIndex, MeshPart& part) {
        const glm::mat4 world = restWorld_[static_cast<std::size_t>(nodeIndex)];
        const glm::dmat4 dworld(world);
        const double det = glm::determinant(glm::dmat3(dworld));
        Influence inf;
        inf.node = nodeIndex;
        if (det != 0.0 && std::isfinite(det)) {
            const glm::dmat4 inverse = glm::inverse(dworld);
            bool ok = true;
            for (int c = 0; c < 4; ++c)
                for (int r = 0; r < 4; ++r)
                    ok = ok && fitsFloat(inverse[c][r]);
            if (ok) {
                inf.inverseBind = glm::mat4(inverse);
                const glm::dmat3 nm = glm::transpose(glm::inverse(glm::dmat3(dworld)));
                // Per vertex 1/|M·v₀| of the normal and tangent, for their morph deltas.
                std::vector<double> normalScale(part.morphs.empty() ? 0 : part.positions.size(), 1.0);
                std::vector<double> tangentScale(normalScale.size(), 1.0);
                for (std::size_t v = 0; v < part.positions.size(); ++v) {
                    const glm::dvec3 p(dworld * glm::dvec4(glm::dvec3(part.positions[v]), 1.0));
                    if (!fitsFloat(p.x) || !fitsFloat(p.y) || !fitsFloat(p.z))
                        return parseError("/nodes/" + str(nodeIndex),
                                          "the rest transform takes the mesh out of float range");
                    part.positions[v] = glm::vec3(p);
                    const glm::dvec3 n = nm * glm::dvec3(part.normals[v]);
                    const double len = glm::length(n);
                    if (len > 0.0 && std::isfinite(len)) {
                        part.normals[v] = glm::vec3(n / len);
                        if (!normalScale.empty()) normalScale[v] = 1.0 / len;
                    }
                    if (!part.tangents.empty()) {
                        // Tangents move with the surface (the matrix, not its inverse
                        // transpose); a mirroring transform flips the bitangent's sign.
                        const glm::dvec3 t = glm::dmat3(dworld) * glm::dvec3(part.tangents[v]);
                        const double tl = glm::length(t);
                        if (tl > 0.0 && std::isfinite(tl)) {
                            part.tangents[v] = glm::vec4(glm::vec3(t / tl),
                                                         det < 0.0 ? -part.tangents[v].w
                                                                   : part.tangents[v].w);
                            if (!tangentScale.empty()) tangentScale[v] = 1.0 / tl;
                        }
                    }
                }
                if (!part.morphs.empty()) transformMorphs(part, dworld, normalScale, tangentScale);
            }
        }
        part.influences = {inf};
        part.joints.assign(part.positions.size(), glm::u16vec4(0));
        part.weights.assign(part.positions.size(), glm::vec4(1.0f, 0.0f, 0.0f, 0.0f));
        return Ok{};
    }
};

} // namespace

Result<ParsedGltf> convertGltf(const tg::Model& g, Captured& captured) {
    return Converter(g, captured).run();
}

} // namespace dermis::gltf_detail
