// glTF morph targets for the converter (gltf_convert.cpp): the weights a node instancing a mesh
// with targets adds to the model, each primitive's deltas, and a rigid part's deltas moved into
// its rest world space. glTF 2.0 §3.7.2.2 "Morph Targets".
#include "gltf_internal.hpp"

#include <cmath>

namespace dermis::gltf_detail {

Status addMorphWeights(const tg::Model& g, int nodeIndex, Model& m, MorphSlots& slots) {
    const tg::Node& node = g.nodes[static_cast<std::size_t>(nodeIndex)];
    const tg::Mesh& mesh = g.meshes[static_cast<std::size_t>(node.mesh)];
    const std::string meshField = "/meshes/" + str(node.mesh);
    std::size_t count = 0;
    for (std::size_t p = 0; p < mesh.primitives.size(); ++p) {
        const std::size_t n = mesh.primitives[p].targets.size();
        if (p > 0 && n != count)
            return parseError(meshField + "/primitives/" + str(p) + "/targets",
                              str(n) + " targets, primitive 0 has " + str(count) +
                                  " (every primitive of a mesh has the same number)");
        count = n;
    }
    if (count == 0) return Ok{};
    // Rest weights: the node's, else the mesh's, else zero.
    const bool own = !node.weights.empty();
    const std::vector<double>& rest = own ? node.weights : mesh.weights;
    const std::string restField = own ? "/nodes/" + str(nodeIndex) + "/weights" : meshField + "/weights";
    if (!rest.empty() && rest.size() != count)
        return parseError(restField, str(rest.size()) + " weights for " + str(count) + " morph targets");
    if (!allFitFloat(rest)) return parseError(restField, "non-finite value");
    // Names: the de facto convention mesh.extras.targetNames (Blender, three.js, Babylon).
    std::vector<std::string> names(count);
    if (mesh.extras.IsObject() && mesh.extras.Has("targetNames")) {
        const tg::Value& list = mesh.extras.Get("targetNames");
        if (list.IsArray())
            for (std::size_t k = 0; k < count && k < list.ArrayLen(); ++k)
                if (list.Get(static_cast<int>(k)).IsString())
                    names[k] = list.Get(static_cast<int>(k)).Get<std::string>();
    }
    const std::string base = !mesh.name.empty() ? mesh.name : !node.name.empty() ? node.name : "mesh" + str(node.mesh);
    const int first = static_cast<int>(m.morphWeights.size());
    for (std::size_t k = 0; k < count; ++k) {
        MorphWeight w;
        w.name = !names[k].empty() ? names[k] : base + "#" + str(k);
        w.node = nodeIndex;
        w.rest = rest.empty() ? 0.0f : static_cast<float>(rest[k]);
        m.morphWeights.push_back(std::move(w));
    }
    slots[nodeIndex] = {first, static_cast<int>(count)};
    return Ok{};
}

Status readMorphTargets(const tg::Model& g, const tg::Primitive& prim, const std::string& field,
                        int firstWeight, MeshPart& part) {
    const std::size_t nv = part.positions.size();
    for (std::size_t t = 0; t < prim.targets.size(); ++t) {
        MorphTarget target;
        target.weight = firstWeight + static_cast<int>(t);
        for (const auto& [name, index] : prim.targets[t]) {
            std::vector<glm::vec3>* dst = name == "POSITION" ? &target.positions
                                          : name == "NORMAL" ? &target.normals
                                          : name == "TANGENT" ? &target.tangents
                                                              : nullptr;
            if (!dst) continue; // TEXCOORD_n, COLOR_n deltas: not used
            const std::string f = field + "/targets/" + str(t) + "/" + name;
            // Deltas are VEC3 (a TANGENT delta has no w), float or normalised integers.
            auto data = readAccessor(g, index, TINYGLTF_TYPE_VEC3, Want::Float, {}, f);
            if (!data) return data.error();
            if (data->count != nv)
                return parseError(f, str(data->count) + " elements, POSITION has " + str(nv));
            if (!allFitFloat(data->values)) return parseError(f, "non-finite value");
            dst->resize(nv);
            for (std::size_t v = 0; v < nv; ++v)
                (*dst)[v] = glm::vec3(glm::dvec3(data->at(v, 0), data->at(v, 1), data->at(v, 2)));
        }
        // A normal or tangent delta needs the attribute it moves.
        if (part.tangents.empty()) target.tangents.clear();
        part.morphs.push_back(std::move(target));
    }
    return Ok{};
}

void transformMorphs(MeshPart& part, const glm::dmat4& world, const std::vector<double>& normalScale,
                     const std::vector<double>& tangentScale) {
    const glm::dmat3 linear(world);
    const glm::dmat3 normal = glm::transpose(glm::inverse(linear));
    for (MorphTarget& t : part.morphs) {
        for (glm::vec3& d : t.positions)
            d = glm::vec3(linear * glm::dvec3(d));
        for (std::size_t v = 0; v < t.normals.size(); ++v)
            t.normals[v] = glm::vec3(normal * glm::dvec3(t.normals[v]) *
                                     (v < normalScale.size() ? normalScale[v] : 1.0));
        for (std::size_t v = 0; v < t.tangents.size(); ++v)
            t.tangents[v] = glm::vec3(linear * glm::dvec3(t.tangents[v]) *
                                      (v < tangentScale.size() ? tangentScale[v] : 1.0));
    }
}

} // namespace dermis::gltf_detail
