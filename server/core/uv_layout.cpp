#include "uv_layout.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <utility>

namespace dermis {

namespace {

void addEdges(const std::vector<std::uint32_t>& indices, const std::vector<glm::vec2>& uvs,
              std::vector<UvEdge>& out) {
    std::set<std::pair<std::uint32_t, std::uint32_t>> seen;
    for (std::size_t t = 0; t + 2 < indices.size(); t += 3)
        for (std::size_t k = 0; k < 3; ++k) {
            std::uint32_t a = indices[t + k], b = indices[t + (k + 1) % 3];
            if (a > b) std::swap(a, b);
            if (b >= uvs.size() || !seen.insert({a, b}).second) continue;
            out.push_back({uvs[a], uvs[b]});
        }
}

} // namespace

std::vector<UvEdge> uvEdges(const Model& model) {
    std::vector<UvEdge> out;
    for (const MeshPart& p : model.parts) addEdges(p.indices, p.uvs, out);
    return out;
}

std::vector<UvEdge> uvEdges(const TextureLayout& layout) {
    std::vector<UvEdge> out;
    for (const PartLayout& p : layout.parts) addEdges(p.indices, p.uvs, out);
    return out;
}

Image8 rasterizeUvEdges(const std::vector<UvEdge>& edges, int size) {
    Image8 img;
    img.width = img.height = size;
    img.rgba.assign(static_cast<std::size_t>(size) * size * 4, 0);
    for (const UvEdge& e : edges) {
        const double x0 = double(e.a.x) * size, y0 = double(e.a.y) * size;
        const double x1 = double(e.b.x) * size, y1 = double(e.b.y) * size;
        if (!std::isfinite(x0) || !std::isfinite(y0) || !std::isfinite(x1) || !std::isfinite(y1)) continue;
        const double span = std::max(std::abs(x1 - x0), std::abs(y1 - y0));
        if (span > 4.0 * size) continue; // far outside the unit square: nothing to see, no long loop
        const int steps = static_cast<int>(std::ceil(span)) + 1;
        for (int s = 0; s <= steps; ++s) {
            const double f = static_cast<double>(s) / steps;
            const int x = static_cast<int>(x0 + (x1 - x0) * f), y = static_cast<int>(y0 + (y1 - y0) * f);
            if (x < 0 || y < 0 || x >= size || y >= size) continue;
            std::uint8_t* px = &img.rgba[(static_cast<std::size_t>(y) * size + x) * 4];
            px[0] = px[1] = px[2] = px[3] = 255;
        }
    }
    return img;
}

} // namespace dermis
