// Dermis core — MikkTSpace tangent frames (tangents.hpp).
#include "core/tangents.hpp"

#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <map>
#include <unordered_map>

namespace dermis {

namespace {

/// What one triangle contributes: its unit tangent and bitangent (already multiplied by the
/// orientation sign, as mikktspace stores them) and whether its UV mapping is usable.
struct Face {
    glm::dvec3 os{0.0}, ot{0.0};
    bool orientPreserving = false;
    bool usable = false;
};

/// Key of a welded vertex: the bits of position, normal and UV (mikktspace's vertex identity).
struct WeldKey {
    float f[8];
    bool operator==(const WeldKey& o) const { return std::memcmp(f, o.f, sizeof f) == 0; }
};
struct WeldHash {
    std::size_t operator()(const WeldKey& k) const {
        std::uint64_t h = 1469598103934665603ull; // FNV-1a over the bytes
        const auto* b = reinterpret_cast<const unsigned char*>(k.f);
        for (std::size_t i = 0; i < sizeof k.f; ++i) h = (h ^ b[i]) * 1099511628211ull;
        return static_cast<std::size_t>(h);
    }
};

glm::dvec3 projectOnPlane(const glm::dvec3& v, const glm::dvec3& n) {
    return v - n * glm::dot(n, v);
}

glm::dvec3 normalizedOrZero(const glm::dvec3& v) {
    const double len = glm::length(v);
    return len > 1e-20 && std::isfinite(len) ? v / len : glm::dvec3(0.0);
}

/// A unit vector perpendicular to `n` (any; for vertices without a usable UV mapping).
glm::dvec3 anyPerpendicular(const glm::dvec3& n) {
    const glm::dvec3 axis = std::abs(n.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
    const glm::dvec3 t = normalizedOrZero(projectOnPlane(axis, n));
    return glm::length(t) > 0.0 ? t : glm::dvec3(1, 0, 0);
}

Error argumentError(const char* field, const std::string& what) {
    return makeError(ErrorCode::InvalidArgument, "dermis::cornerTangents", field, what);
}

} // namespace

Result<std::vector<glm::vec4>> cornerTangents(const std::vector<glm::vec3>& positions,
                                              const std::vector<glm::vec3>& normals,
                                              const std::vector<glm::vec2>& uvs,
                                              const std::vector<std::uint32_t>& indices) {
    const std::size_t nv = positions.size();
    if (normals.size() != nv) return argumentError("normals", "one per vertex expected");
    if (uvs.size() != nv) return argumentError("uvs", "one per vertex expected");
    if (indices.size() % 3 != 0) return argumentError("indices", "not a multiple of 3");
    for (std::uint32_t i : indices)
        if (i >= nv) return argumentError("indices", "index " + std::to_string(i) + " out of range");

    // Weld vertices equal in position, normal and UV.
    std::vector<std::uint32_t> weld(nv);
    {
        std::unordered_map<WeldKey, std::uint32_t, WeldHash> first;
        first.reserve(nv);
        for (std::size_t v = 0; v < nv; ++v) {
            WeldKey k;
            std::memcpy(k.f, glm::value_ptr(positions[v]), 12);
            std::memcpy(k.f + 3, glm::value_ptr(normals[v]), 12);
            std::memcpy(k.f + 6, glm::value_ptr(uvs[v]), 8);
            weld[v] = first.emplace(k, static_cast<std::uint32_t>(v)).first->second;
        }
    }

    // Per triangle: tangent along +u, bitangent along +v (image up: glTF's v flipped).
    const std::size_t nf = indices.size() / 3;
    std::vector<Face> faces(nf);
    for (std::size_t f = 0; f < nf; ++f) {
        const std::uint32_t* c = &indices[3 * f];
        const glm::dvec3 p0(positions[c[0]]), p1(positions[c[1]]), p2(positions[c[2]]);
        const glm::dvec2 t0(uvs[c[0]].x, -double(uvs[c[0]].y)), t1(uvs[c[1]].x, -double(uvs[c[1]].y)),
            t2(uvs[c[2]].x, -double(uvs[c[2]].y));
        const glm::dvec3 d1 = p1 - p0, d2 = p2 - p0;
        const glm::dvec2 t21 = t1 - t0, t31 = t2 - t0;
        const double area = t21.x * t31.y - t21.y * t31.x; // signed, ×2
        Face& face = faces[f];
        face.orientPreserving = area > 0.0;
        const double sign = face.orientPreserving ? 1.0 : -1.0;
        const glm::dvec3 os = t31.y * d1 - t21.y * d2, ot = -t31.x * d1 + t21.x * d2;
        face.os = sign * normalizedOrZero(os);
        face.ot = sign * normalizedOrZero(ot);
        face.usable = std::abs(area) > 1e-30 && std::isfinite(area) && glm::length(face.os) > 0.0 &&
                      glm::length(glm::cross(d1, d2)) > 0.0;
    }

    // Per (welded vertex, orientation): Σ angle · projected tangent over its usable corners.
    struct Sum {
        glm::dvec3 os{0.0};
        bool any = false;
    };
    std::map<std::pair<std::uint32_t, bool>, Sum> sums;
    for (std::size_t f = 0; f < nf; ++f) {
        const Face& face = faces[f];
        if (!face.usable) continue;
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t v = indices[3 * f + k];
            const glm::dvec3 n = normalizedOrZero(glm::dvec3(normals[v]));
            const glm::dvec3 os = normalizedOrZero(projectOnPlane(face.os, n));
            const glm::dvec3 p(positions[v]);
            const glm::dvec3 e1 = normalizedOrZero(
                projectOnPlane(glm::dvec3(positions[indices[3 * f + (k + 2) % 3]]) - p, n));
            const glm::dvec3 e2 = normalizedOrZero(
                projectOnPlane(glm::dvec3(positions[indices[3 * f + (k + 1) % 3]]) - p, n));
            const double angle = std::acos(std::clamp(glm::dot(e1, e2), -1.0, 1.0));
            Sum& s = sums[{weld[v], face.orientPreserving}];
            s.os += angle * os;
            s.any = true;
        }
    }

    std::vector<glm::vec4> out(indices.size());
    for (std::size_t f = 0; f < nf; ++f) {
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t v = indices[3 * f + k];
            const glm::dvec3 n = normalizedOrZero(glm::dvec3(normals[v]));
            // A degenerate triangle takes the frame of its vertex's other triangles (either
            // orientation, the preserving one first), as mikktspace's degenerate pass does.
            const Face& face = faces[f];
            const Sum* s = nullptr;
            auto find = [&](bool orient) -> const Sum* {
                auto it = sums.find({weld[v], orient});
                return it != sums.end() && it->second.any ? &it->second : nullptr;
            };
            bool orient = face.orientPreserving;
            if (face.usable) s = find(orient);
            else if ((s = find(true))) orient = true;
            else if ((s = find(false))) orient = false;
            glm::dvec3 t = s ? normalizedOrZero(projectOnPlane(s->os, n)) : glm::dvec3(0.0);
            if (glm::length(t) == 0.0) {
                t = anyPerpendicular(glm::length(n) > 0.0 ? n : glm::dvec3(0, 0, 1));
                orient = true;
            }
            out[3 * f + k] = glm::vec4(glm::vec3(t), orient ? 1.0f : -1.0f);
        }
    }
    return out;
}

Status generateTangents(MeshPart& part, int uvSet) {
    const char* kWhere = "dermis::generateTangents";
    const std::vector<glm::vec2>& uvs = uvSet == 1 ? part.uvs1 : part.uvs;
    if (part.normals.size() != part.positions.size())
        return makeError(ErrorCode::InvalidArgument, kWhere, "normals", "one per vertex expected");
    if (uvs.size() != part.positions.size())
        return makeError(ErrorCode::InvalidArgument, kWhere, uvSet == 1 ? "uvs1" : "uvs",
                         "one per vertex expected");
    auto corners = cornerTangents(part.positions, part.normals, uvs, part.indices);
    if (!corners) return corners.error();

    // The first tangent seen per vertex stays on it; a corner that disagrees moves to a copy of
    // the vertex made for that tangent (one copy per distinct tangent).
    const std::size_t nv = part.positions.size();
    std::vector<glm::vec4> tangents(nv);
    std::vector<bool> set(nv, false);
    std::map<std::pair<std::uint32_t, std::array<float, 4>>, std::uint32_t> copies;
    std::vector<std::uint32_t> source; // per appended vertex: the vertex it copies
    for (std::size_t c = 0; c < part.indices.size(); ++c) {
        const std::uint32_t v = part.indices[c];
        const glm::vec4 t = (*corners)[c];
        if (!set[v]) {
            tangents[v] = t;
            set[v] = true;
            continue;
        }
        if (tangents[v] == t) continue;
        const std::array<float, 4> key{t.x, t.y, t.z, t.w};
        auto [it, inserted] =
            copies.emplace(std::pair{v, key}, static_cast<std::uint32_t>(nv + source.size()));
        if (inserted) {
            source.push_back(v);
            tangents.push_back(t);
        }
        part.indices[c] = it->second;
    }
    for (std::size_t v = 0; v < nv; ++v)
        if (!set[v]) tangents[v] = glm::vec4(glm::vec3(anyPerpendicular(glm::dvec3(part.normals[v]))), 1.0f);

    auto append = [&source](auto& array) {
        if (array.empty()) return;
        array.reserve(array.size() + source.size());
        for (std::uint32_t v : source) array.push_back(array[v]);
    };
    append(part.positions);
    append(part.normals);
    append(part.uvs);
    append(part.uvs1);
    append(part.colors);
    append(part.joints);
    append(part.weights);
    for (MorphTarget& m : part.morphs) {
        append(m.positions);
        append(m.normals);
        m.tangents.clear();
    }
    part.tangents = std::move(tangents);
    return Ok{};
}

} // namespace dermis
