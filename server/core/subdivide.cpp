// Midpoint subdivision of skinned meshes and synthetic joints. See subdivide.hpp.
#include "subdivide.hpp"

#include "rig.hpp"

#include <algorithm>
#include <array>
#include <string>
#include <unordered_map>
#include <utility>

namespace dermis {

namespace {

/// Up to four (influence, weight) pairs averaged from two vertices' skins.
std::pair<glm::u16vec4, glm::vec4> blendSkin(glm::u16vec4 ja, glm::vec4 wa, glm::u16vec4 jb,
                                             glm::vec4 wb) {
    std::array<std::pair<std::uint16_t, float>, 8> all{};
    int n = 0;
    auto add = [&](std::uint16_t j, float w) {
        if (w <= 0.0f) return;
        for (int k = 0; k < n; ++k)
            if (all[static_cast<std::size_t>(k)].first == j) {
                all[static_cast<std::size_t>(k)].second += w;
                return;
            }
        all[static_cast<std::size_t>(n++)] = {j, w};
    };
    for (int k = 0; k < 4; ++k) {
        add(ja[k], 0.5f * wa[k]);
        add(jb[k], 0.5f * wb[k]);
    }
    for (int a = 1; a < n; ++a) // insertion sort, largest weight first (n ≤ 8)
        for (int b = a; b > 0 && all[static_cast<std::size_t>(b - 1)].second <
                                     all[static_cast<std::size_t>(b)].second; --b)
            std::swap(all[static_cast<std::size_t>(b - 1)], all[static_cast<std::size_t>(b)]);
    glm::u16vec4 j(0);
    glm::vec4 w(0.0f);
    float sum = 0.0f;
    for (int k = 0; k < std::min(n, 4); ++k) {
        j[k] = all[static_cast<std::size_t>(k)].first;
        w[k] = all[static_cast<std::size_t>(k)].second;
        sum += w[k];
    }
    if (sum > 0.0f) w /= sum;
    else w = glm::vec4(1, 0, 0, 0);
    return {j, w};
}

} // namespace

Result<MeshPart> subdivideMidpoint(const MeshPart& part) {
    const std::size_t nv = part.positions.size();
    for (std::uint32_t i : part.indices)
        if (i >= nv)
            return makeError(ErrorCode::InvalidArgument, "dermis::subdivideMidpoint", "indices",
                             "index " + std::to_string(i) + " out of range");
    MeshPart out = part;
    out.indices.clear();
    out.indices.reserve(part.indices.size() * 4);
    const bool hasNormals = part.normals.size() == nv, hasUVs = part.uvs.size() == nv;
    const bool hasSkin = part.joints.size() == nv && part.weights.size() == nv;
    const bool hasUVs1 = part.uvs1.size() == nv, hasTangents = part.tangents.size() == nv,
               hasColors = part.colors.size() == nv;
    std::unordered_map<std::uint64_t, std::uint32_t> midpoints;
    midpoints.reserve(part.indices.size());
    auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
        const std::uint64_t key = (std::uint64_t{std::min(a, b)} << 32) | std::max(a, b);
        if (auto it = midpoints.find(key); it != midpoints.end()) return it->second;
        const auto m = static_cast<std::uint32_t>(out.positions.size());
        out.positions.push_back(0.5f * (out.positions[a] + out.positions[b]));
        if (hasNormals) {
            const glm::vec3 n = out.normals[a] + out.normals[b];
            const float len = glm::length(n);
            out.normals.push_back(len > 0.0f ? n / len : out.normals[a]);
        }
        if (hasUVs) out.uvs.push_back(0.5f * (out.uvs[a] + out.uvs[b]));
        if (hasUVs1) out.uvs1.push_back(0.5f * (out.uvs1[a] + out.uvs1[b]));
        if (hasColors) out.colors.push_back(0.5f * (out.colors[a] + out.colors[b]));
        if (hasTangents) {
            const glm::vec3 t = glm::vec3(out.tangents[a]) + glm::vec3(out.tangents[b]);
            const float len = glm::length(t);
            out.tangents.push_back(len > 0.0f ? glm::vec4(t / len, out.tangents[a].w)
                                              : out.tangents[a]);
        }
        for (MorphTarget& t : out.morphs) // deltas of a midpoint: the mean (a linear blend)
            for (std::vector<glm::vec3>* d : {&t.positions, &t.normals, &t.tangents})
                if (d->size() == m) d->push_back(0.5f * ((*d)[a] + (*d)[b]));
        if (hasSkin) {
            auto [j, w] = blendSkin(out.joints[a], out.weights[a], out.joints[b], out.weights[b]);
            out.joints.push_back(j);
            out.weights.push_back(w);
        }
        midpoints.emplace(key, m);
        return m;
    };
    for (std::size_t t = 0; t + 2 < part.indices.size(); t += 3) {
        const std::uint32_t a = part.indices[t], b = part.indices[t + 1], c = part.indices[t + 2];
        const std::uint32_t ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
        out.indices.insert(out.indices.end(), {a, ab, ca, ab, b, bc, ca, bc, c, ab, bc, ca});
    }
    return out;
}

Result<Model> subdivideModel(const Model& model, int levels) {
    if (levels < 0 || levels > 6)
        return makeError(ErrorCode::InvalidArgument, "dermis::subdivideModel", "levels",
                         "must be in [0, 6]");
    Model out = model;
    for (int l = 0; l < levels; ++l)
        for (MeshPart& part : out.parts) {
            auto next = subdivideMidpoint(part);
            if (!next) return next.error();
            part = std::move(*next);
        }
    return out;
}

Result<Model> withSyntheticJoints(const Model& model, int total) {
    const char* where = "dermis::withSyntheticJoints";
    if (model.joints.empty())
        return makeError(ErrorCode::InvalidArgument, where, "joints", "the model has no joints");
    if (total > 65535)
        return makeError(ErrorCode::InvalidArgument, where, "joints", "at most 65535 joints");
    Model out = model;
    const std::size_t existing = model.joints.size();
    for (int k = 0; static_cast<int>(out.joints.size()) < total; ++k) {
        Node n;
        n.name = "synthetic_joint_" + std::to_string(k);
        n.parent = model.joints[static_cast<std::size_t>(k) % existing];
        n.translation = glm::vec3(0.0f, 0.01f, 0.0f);
        out.nodes.push_back(n);
        out.joints.push_back(static_cast<int>(out.nodes.size()) - 1);
    }
    if (out.joints.size() == existing) return out;
    const std::vector<glm::mat4> rest = worldMatrices(out, restPose(out));
    for (MeshPart& part : out.parts) {
        if (part.joints.empty()) continue;
        for (std::size_t j = existing; j < out.joints.size(); ++j) {
            const int node = out.joints[j];
            part.influences.push_back({node, glm::inverse(rest[static_cast<std::size_t>(node)])});
        }
    }
    return out;
}

} // namespace dermis
