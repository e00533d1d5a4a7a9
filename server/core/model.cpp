// Queries over a Model (model.hpp) and area-weighted vertex normals.
#include "model.hpp"

#include <cmath>

namespace dermis {

bool Model::hasUVs() const {
    if (parts.empty()) return false;
    for (const MeshPart& part : parts)
        if (part.uvs.empty() || part.uvs.size() != part.positions.size()) return false;
    return true;
}

std::size_t Model::triangleCount() const {
    std::size_t n = 0;
    for (const MeshPart& part : parts)
        n += part.indices.size() / 3;
    return n;
}

int Model::findJoint(const std::string& name) const {
    for (int j : joints)
        if (j >= 0 && static_cast<std::size_t>(j) < nodes.size() && nodes[j].name == name) return j;
    return -1;
}

int Model::findClip(const std::string& name) const {
    for (std::size_t c = 0; c < clips.size(); ++c)
        if (clips[c].name == name) return static_cast<int>(c);
    return -1;
}

glm::mat3 TextureUv::matrix() const {
    // glTF KHR_texture_transform: T · R · S with R = [[cos, sin], [−sin, cos]] (rows).
    const float c = std::cos(rotation), s = std::sin(rotation);
    glm::mat3 m(1.0f);
    m[0] = glm::vec3(c * scale.x, -s * scale.x, 0.0f);
    m[1] = glm::vec3(s * scale.y, c * scale.y, 0.0f);
    m[2] = glm::vec3(offset, 1.0f);
    return m;
}

int Model::dominantBaseColorImage() const {
    std::vector<std::size_t> covered(images.size(), 0);
    for (const MeshPart& part : parts) {
        if (part.material < 0 || static_cast<std::size_t>(part.material) >= materials.size()) continue;
        const int image = materials[static_cast<std::size_t>(part.material)].baseColorTexture;
        if (image < 0 || static_cast<std::size_t>(image) >= images.size()) continue;
        const Image8& img = images[static_cast<std::size_t>(image)];
        if (img.width <= 0 || img.height <= 0) continue;
        covered[static_cast<std::size_t>(image)] += part.indices.size() / 3;
    }
    int best = -1;
    for (std::size_t i = 0; i < covered.size(); ++i)
        if (covered[i] > 0 && (best < 0 || covered[i] > covered[static_cast<std::size_t>(best)]))
            best = static_cast<int>(i);
    return best;
}

int Model::parentJoint(int node) const {
    if (node < 0 || static_cast<std::size_t>(node) >= nodes.size()) return -1;
    int parent = nodes[static_cast<std::size_t>(node)].parent;
    // Bounded walk: a malformed hierarchy with a cycle cannot loop forever.
    for (std::size_t steps = 0; parent >= 0 && static_cast<std::size_t>(parent) < nodes.size() &&
                                steps < nodes.size();
         ++steps) {
        if (parent == node) return -1; // a cycle back to the start
        for (int j : joints)
            if (j == parent) return parent;
        parent = nodes[static_cast<std::size_t>(parent)].parent;
    }
    return -1;
}

std::vector<glm::vec3> computeNormals(const std::vector<glm::vec3>& positions,
                                      const std::vector<std::uint32_t>& indices) {
    // Each triangle adds its unnormalised face normal (length = 2·area) to its three corners, so
    // larger faces weigh more; accumulated in double so that big meshes do not lose small faces.
    std::vector<glm::dvec3> sum(positions.size(), glm::dvec3(0.0));
    const std::size_t n = positions.size();
    for (std::size_t t = 0; t + 2 < indices.size(); t += 3) {
        const std::uint32_t a = indices[t], b = indices[t + 1], c = indices[t + 2];
        if (a >= n || b >= n || c >= n) continue;
        const glm::dvec3 pa(positions[a]), pb(positions[b]), pc(positions[c]);
        const glm::dvec3 f = glm::cross(pb - pa, pc - pa);
        if (!std::isfinite(f.x) || !std::isfinite(f.y) || !std::isfinite(f.z)) continue;
        sum[a] += f;
        sum[b] += f;
        sum[c] += f;
    }
    std::vector<glm::vec3> out(n);
    for (std::size_t v = 0; v < n; ++v) {
        const double len = glm::length(sum[v]);
        out[v] = len > 0.0 ? glm::vec3(sum[v] / len) : glm::vec3(0.0f, 0.0f, 1.0f);
    }
    return out;
}

} // namespace dermis
