// Limits of gltf_loader.hpp (GltfLimits), checked from the sizes a file declares before anything
// is allocated for them: step 1 on the parsed JSON (tinygltf has resolved buffers but read no
// accessor), step 2 on the header bytes of the captured images (nothing decoded yet). See
// gltf_internal.hpp for the two checks.
//
// Why declared sizes: an accessor without a buffer view is `count` zeros (glTF 2.0 §3.6.2.1), so
// a 440-byte file can declare millions of vertices, and the converter reads a mesh's accessors
// again for every node that instances it; a PNG of a flat colour declares 16384² pixels in a few
// hundred kilobytes. Counting after reading would come after the allocation.
#include "gltf_internal.hpp"

#include <algorithm>
#include <set>

namespace dermis {

std::size_t GltfLimits::maxElements() const {
    const std::size_t perTriangles = maxTriangles > std::numeric_limits<std::size_t>::max() / 3
                                         ? std::numeric_limits<std::size_t>::max()
                                         : 3 * maxTriangles;
    return std::max<std::size_t>(perTriangles, 65536);
}

std::size_t GltfLimits::maxValues() const {
    const std::size_t e = maxElements();
    return e > std::numeric_limits<std::size_t>::max() / 24
               ? std::numeric_limits<std::size_t>::max()
               : 24 * e;
}

namespace gltf_detail {

Error tooLarge(const std::string& field, const std::string& what, const char* where) {
    return makeError(ErrorCode::TooLarge, where, field, what);
}

namespace {

/// Sums that cannot overflow: declared counts go up to 2^64, times instances.
using Big = long double;

std::string num(Big v) {
    if (v < 1e15L) return std::to_string(static_cast<unsigned long long>(v));
    return std::to_string(static_cast<double>(v));
}

class DeclaredSizes {
  public:
    DeclaredSizes(const tg::Model& g, const GltfLimits& limits) : g_(g), limits_(limits) {}

    Status run() {
        if (auto s = instances(); !s) return s.error();
        if (auto s = meshes(); !s) return s.error();
        if (auto s = skins(); !s) return s.error();
        if (auto s = animations(); !s) return s.error();
        return Ok{};
    }

  private:
    const tg::Model& g_;
    const GltfLimits& limits_;
    std::vector<std::size_t> meshInstances_;    ///< nodes of the default scene per mesh
    std::vector<std::size_t> skinnedInstances_; ///< of those, per skin: nodes with mesh and skin
    std::vector<std::vector<int>> skinsOfMesh_; ///< skins instancing each mesh, per instance
    Big values_ = 0;                            ///< accessor values read, each use counted

    const tg::Accessor* accessor(int index) const {
        if (index < 0 || static_cast<std::size_t>(index) >= g_.accessors.size()) return nullptr;
        return &g_.accessors[static_cast<std::size_t>(index)];
    }

    /// One use of accessor `index` (referenced at `field`): its count within maxElements, its
    /// values added to the total.
    Status use(int index, const std::string& field, Big times = 1) {
        const tg::Accessor* a = accessor(index);
        if (!a) return Ok{};
        if (a->count > limits_.maxElements())
            return tooLarge(field, "accessor " + str(index) + " declares " + str(a->count) +
                                       " elements, more than the limit " +
                                       str(limits_.maxElements()) + " (from max_triangles)");
        const int comps = tg::GetNumComponentsInType(static_cast<std::uint32_t>(a->type));
        values_ += Big(a->count) * Big(comps > 0 ? comps : 1) * times;
        if (values_ > Big(limits_.maxValues()))
            return tooLarge(field, "the accessors read come to " + num(values_) +
                                       " values, more than the limit " + str(limits_.maxValues()) +
                                       " (from max_triangles)");
        return Ok{};
    }

    /// Nodes reached from the default scene (as the converter walks them: each node once).
    Status instances() {
        const std::size_t n = g_.nodes.size();
        meshInstances_.assign(g_.meshes.size(), 0);
        skinsOfMesh_.assign(g_.meshes.size(), {});
        std::vector<int> roots;
        if (!g_.scenes.empty()) {
            const int scene = g_.defaultScene < 0 ? 0 : g_.defaultScene;
            if (static_cast<std::size_t>(scene) >= g_.scenes.size()) return Ok{};
            roots = g_.scenes[static_cast<std::size_t>(scene)].nodes;
        } else {
            std::vector<char> child(n, 0);
            for (const tg::Node& node : g_.nodes)
                for (int c : node.children)
                    if (c >= 0 && static_cast<std::size_t>(c) < n)
                        child[static_cast<std::size_t>(c)] = 1;
            for (std::size_t i = 0; i < n; ++i)
                if (!child[i]) roots.push_back(static_cast<int>(i));
        }
        std::vector<char> seen(n, 0);
        std::vector<int> stack(roots.rbegin(), roots.rend());
        while (!stack.empty()) {
            const int i = stack.back();
            stack.pop_back();
            if (i < 0 || static_cast<std::size_t>(i) >= n || seen[static_cast<std::size_t>(i)])
                continue;
            seen[static_cast<std::size_t>(i)] = 1;
            const tg::Node& node = g_.nodes[static_cast<std::size_t>(i)];
            if (node.mesh >= 0 && static_cast<std::size_t>(node.mesh) < g_.meshes.size()) {
                ++meshInstances_[static_cast<std::size_t>(node.mesh)];
                skinsOfMesh_[static_cast<std::size_t>(node.mesh)].push_back(
                    node.skin >= 0 && static_cast<std::size_t>(node.skin) < g_.skins.size()
                        ? node.skin
                        : -1);
            }
            for (auto it = node.children.rbegin(); it != node.children.rend(); ++it)
                stack.push_back(*it);
        }
        return Ok{};
    }

    /// Triangles, vertices and parts after instancing; the accessors each instance reads.
    Status meshes() {
        Big triangles = 0, vertices = 0, parts = 0;
        for (std::size_t m = 0; m < g_.meshes.size(); ++m) {
            const std::size_t inst = meshInstances_[m];
            if (inst == 0) continue;
            const auto& prims = g_.meshes[m].primitives;
            for (std::size_t p = 0; p < prims.size(); ++p) {
                const tg::Primitive& prim = prims[p];
                const std::string field = "/meshes/" + str(m) + "/primitives/" + str(p);
                const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
                if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
                    mode != TINYGLTF_MODE_TRIANGLE_FAN)
                    continue; // skipped or refused by the converter
                auto pos = prim.attributes.find("POSITION");
                const tg::Accessor* position =
                    pos == prim.attributes.end() ? nullptr : accessor(pos->second);
                if (!position) continue; // the converter reports it
                const tg::Accessor* idx = accessor(prim.indices);
                const Big listed = Big(idx ? idx->count : position->count);
                const Big perInstance = mode == TINYGLTF_MODE_TRIANGLES
                                            ? Big(static_cast<unsigned long long>(listed) / 3)
                                            : (listed >= 3 ? listed - 2 : 0);
                const std::string triField =
                    idx ? field + "/indices" : field + "/attributes/POSITION";
                triangles += perInstance * Big(inst);
                if (triangles > Big(limits_.maxTriangles))
                    return tooLarge(triField, num(perInstance) + " triangles × " + str(inst) +
                                                  " instances: the model comes to " +
                                                  num(triangles) +
                                                  " triangles, more than max_triangles " +
                                                  str(limits_.maxTriangles));
                vertices += Big(position->count) * Big(inst);
                if (vertices > Big(limits_.maxElements()))
                    return tooLarge(field + "/attributes/POSITION",
                                    str(position->count) + " vertices × " + str(inst) +
                                        " instances: the model comes to " + num(vertices) +
                                        " vertices, more than the limit " +
                                        str(limits_.maxElements()) + " (from max_triangles)");
                parts += Big(inst);
                if (parts > Big(limits_.maxParts))
                    return tooLarge(field, "the model comes to " + num(parts) +
                                               " mesh parts (primitives × instances), more than " +
                                               str(limits_.maxParts));
                // What each instance reads (gltf_convert.cpp: primitive, skinWeights).
                for (const auto& [name, index] : prim.attributes) {
                    const bool read = name == "POSITION" || name == "NORMAL" ||
                                      name == "TEXCOORD_0" || name == "TEXCOORD_1" ||
                                      name == "TANGENT" || name == "COLOR_0" ||
                                      name.rfind("JOINTS_", 0) == 0 ||
                                      name.rfind("WEIGHTS_", 0) == 0;
                    if (read)
                        if (auto s = use(index, field + "/attributes/" + name, Big(inst)); !s)
                            return s;
                }
                // Morph targets (gltf_morph.cpp): their POSITION, NORMAL and TANGENT deltas.
                for (std::size_t t = 0; t < prim.targets.size(); ++t)
                    for (const auto& [name, index] : prim.targets[t])
                        if (name == "POSITION" || name == "NORMAL" || name == "TANGENT")
                            if (auto s = use(index, field + "/targets/" + str(t) + "/" + name,
                                             Big(inst));
                                !s)
                                return s;
                if (auto s = use(prim.indices, field + "/indices", Big(inst)); !s) return s;
                // A skinned part copies its skin's influences (node + inverse bind: 17 values).
                if (prim.attributes.count("JOINTS_0"))
                    for (int skin : skinsOfMesh_[m])
                        if (skin >= 0) {
                            values_ +=
                                Big(g_.skins[static_cast<std::size_t>(skin)].joints.size()) * 17;
                            if (values_ > Big(limits_.maxValues()))
                                return tooLarge(field, "the skinned parts come to " + num(values_) +
                                                           " values, more than the limit " +
                                                           str(limits_.maxValues()));
                        }
            }
        }
        return Ok{};
    }

    /// Joints of every skin (the converter reads them all), and their inverse bind matrices.
    Status skins() {
        std::set<int> distinct;
        for (std::size_t s = 0; s < g_.skins.size(); ++s) {
            const tg::Skin& skin = g_.skins[s];
            const std::string field = "/skins/" + str(s);
            if (skin.joints.size() > limits_.maxJoints)
                return tooLarge(field + "/joints", str(skin.joints.size()) +
                                                       " joints, more than max_joints " +
                                                       str(limits_.maxJoints));
            distinct.insert(skin.joints.begin(), skin.joints.end());
            if (distinct.size() > limits_.maxJoints)
                return tooLarge(field + "/joints", "the skins come to " + str(distinct.size()) +
                                                       " distinct joints, more than max_joints " +
                                                       str(limits_.maxJoints));
            if (auto st = use(skin.inverseBindMatrices, field + "/inverseBindMatrices"); !st)
                return st;
        }
        return Ok{};
    }

    /// Every channel reads its sampler's input and output.
    Status animations() {
        for (std::size_t a = 0; a < g_.animations.size(); ++a) {
            const tg::Animation& anim = g_.animations[a];
            for (const tg::AnimationChannel& ch : anim.channels) {
                if (ch.sampler < 0 || static_cast<std::size_t>(ch.sampler) >= anim.samplers.size())
                    continue;
                const tg::AnimationSampler& smp =
                    anim.samplers[static_cast<std::size_t>(ch.sampler)];
                const std::string sfield = "/animations/" + str(a) + "/samplers/" + str(ch.sampler);
                if (auto s = use(smp.input, sfield + "/input"); !s) return s;
                if (auto s = use(smp.output, sfield + "/output"); !s) return s;
            }
        }
        return Ok{};
    }
};

} // namespace

Status checkDeclaredSizes(const tg::Model& g, const GltfLimits& limits) {
    return DeclaredSizes(g, limits).run();
}

Status checkDeclaredTextures(const PendingImages& images, const GltfLimits& limits,
                             const char* where, std::vector<ImageSize>& sizes) {
    sizes.clear();
    Big total = 0;
    for (const PendingImages::Entry& e : images.entries) {
        const std::string field = "/images/" + str(e.gltfImage);
        const auto size = encodedImageSize(e.bytes.data(), e.bytes.size());
        if (!size)
            return makeError(ErrorCode::Unsupported, where, field,
                             "not a PNG or JPEG image with a valid header (" +
                                 (e.mimeType.empty() ? std::string("no MIME type") : e.mimeType) +
                                 ")");
        const Big bytes = Big(size->width) * Big(size->height) * 4;
        total += bytes;
        if (total > Big(limits.maxTextureBytes))
            return tooLarge(field,
                            std::to_string(size->width) + "×" + std::to_string(size->height) +
                                " texture: decoding it needs " + num(bytes) +
                                " bytes, the textures come to " + num(total) +
                                ", more than the texture budget " + str(limits.maxTextureBytes) +
                                " bytes",
                            where);
        sizes.push_back(*size);
    }
    return Ok{};
}

} // namespace gltf_detail
} // namespace dermis
