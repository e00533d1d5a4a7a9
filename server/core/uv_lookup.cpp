// UV → surface lookup. See uv_lookup.hpp.
#include "uv_lookup.hpp"

#include "disjoint_sets.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace dermis {

namespace {

/// Barycentric coordinates of p in triangle (a, b, c); nullopt for a degenerate triangle.
std::optional<glm::dvec3> barycentric(glm::dvec2 p, glm::dvec2 a, glm::dvec2 b, glm::dvec2 c) {
    const glm::dvec2 v0 = b - a, v1 = c - a, v2 = p - a;
    const double den = v0.x * v1.y - v1.x * v0.y;
    if (std::abs(den) < 1e-18) return std::nullopt;
    const double w1 = (v2.x * v1.y - v1.x * v2.y) / den;
    const double w2 = (v0.x * v2.y - v2.x * v0.y) / den;
    return glm::dvec3(1.0 - w1 - w2, w1, w2);
}

} // namespace

UvLookup::UvLookup(const Model& model, int cells) : model_(&model) {
    std::size_t triangles = 0;
    for (const MeshPart& p : model.parts)
        if (!p.uvs.empty()) triangles += p.indices.size() / 3;
    cells_ = cells > 0 ? cells
                       : std::clamp(static_cast<int>(std::sqrt(static_cast<double>(triangles))), 8, 512);
    grid_.assign(static_cast<std::size_t>(cells_) * cells_, {});
    for (std::size_t pi = 0; pi < model.parts.size(); ++pi) {
        const MeshPart& p = model.parts[pi];
        if (p.uvs.empty()) continue;
        DisjointSets comp(p.uvs.size());
        const std::size_t n = p.indices.size() / 3;
        auto valid = [&](std::size_t t) {
            for (int k = 0; k < 3; ++k)
                if (p.indices[3 * t + k] >= p.uvs.size()) return false;
            return true;
        };
        for (std::size_t t = 0; t < n; ++t)
            if (valid(t)) {
                comp.join(p.indices[3 * t], p.indices[3 * t + 1]);
                comp.join(p.indices[3 * t], p.indices[3 * t + 2]);
            }
        std::vector<int> chartOfRoot(p.uvs.size(), -1);
        for (std::size_t t = 0; t < n; ++t) {
            if (!valid(t)) continue;
            const auto r = static_cast<std::uint32_t>(comp.root(p.indices[3 * t]));
            if (chartOfRoot[r] < 0) chartOfRoot[r] = chartCount_++;
            const int id = static_cast<int>(tris_.size());
            tris_.push_back({static_cast<int>(pi), static_cast<int>(t), chartOfRoot[r]});
            glm::vec2 lo(1e30f), hi(-1e30f);
            for (int k = 0; k < 3; ++k) {
                lo = glm::min(lo, p.uvs[p.indices[3 * t + k]]);
                hi = glm::max(hi, p.uvs[p.indices[3 * t + k]]);
            }
            if (!(hi.x >= 0.0f && hi.y >= 0.0f && lo.x <= 1.0f && lo.y <= 1.0f)) continue;
            auto cell = [&](float x) {
                return std::clamp(static_cast<int>(std::floor(x * static_cast<float>(cells_))), 0, cells_ - 1);
            };
            for (int cy = cell(lo.y); cy <= cell(hi.y); ++cy)
                for (int cx = cell(lo.x); cx <= cell(hi.x); ++cx)
                    grid_[static_cast<std::size_t>(cy) * cells_ + cx].push_back(id);
        }
    }
}

template <class Visit>
void UvLookup::visit(glm::dvec2 uv, Visit&& onHit) const {
    if (!std::isfinite(uv.x) || !std::isfinite(uv.y) || uv.x < 0.0 || uv.y < 0.0 || uv.x > 1.0 ||
        uv.y > 1.0)
        return;
    const int cx = std::min(cells_ - 1, static_cast<int>(uv.x * cells_));
    const int cy = std::min(cells_ - 1, static_cast<int>(uv.y * cells_));
    constexpr double kEps = 1e-7;
    for (int id : grid_[static_cast<std::size_t>(cy) * cells_ + cx]) {
        const Tri& tri = tris_[static_cast<std::size_t>(id)];
        const MeshPart& p = model_->parts[static_cast<std::size_t>(tri.part)];
        const std::size_t base = 3 * static_cast<std::size_t>(tri.triangle);
        const auto b = barycentric(uv, glm::dvec2(p.uvs[p.indices[base]]),
                                   glm::dvec2(p.uvs[p.indices[base + 1]]),
                                   glm::dvec2(p.uvs[p.indices[base + 2]]));
        if (!b || b->x < -kEps || b->y < -kEps || b->z < -kEps) continue;
        if (!onHit(Hit{tri.part, tri.triangle, glm::vec3(*b), tri.chart})) return;
    }
}

std::optional<UvLookup::Hit> UvLookup::find(glm::dvec2 uv) const {
    std::optional<Hit> out;
    visit(uv, [&](const Hit& h) {
        out = h;
        return false;
    });
    return out;
}

std::vector<UvLookup::Hit> UvLookup::findAll(glm::dvec2 uv) const {
    std::vector<Hit> out;
    visit(uv, [&](const Hit& h) {
        out.push_back(h);
        return true;
    });
    return out;
}

glm::vec3 UvLookup::position(const Hit& h) const {
    const MeshPart& p = model_->parts[static_cast<std::size_t>(h.part)];
    const std::size_t base = 3 * static_cast<std::size_t>(h.triangle);
    glm::vec3 out(0.0f);
    for (int k = 0; k < 3; ++k) out += h.bary[k] * p.positions[p.indices[base + k]];
    return out;
}

float UvLookup::weightOf(const Hit& h, int node) const {
    const MeshPart& p = model_->parts[static_cast<std::size_t>(h.part)];
    const std::size_t base = 3 * static_cast<std::size_t>(h.triangle);
    float w = 0.0f;
    for (int k = 0; k < 3; ++k) {
        const std::uint32_t v = p.indices[base + k];
        if (v >= p.joints.size() || v >= p.weights.size()) {
            // No per-vertex skin: the part follows influence 0 entirely.
            if (!p.influences.empty() && p.influences[0].node == node) w += h.bary[k];
            continue;
        }
        for (int c = 0; c < 4; ++c) {
            const std::size_t inf = p.joints[v][c];
            if (inf < p.influences.size() && p.influences[inf].node == node)
                w += h.bary[k] * p.weights[v][c];
        }
    }
    return w;
}

} // namespace dermis
