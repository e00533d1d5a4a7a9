// UV-space normal maps of height maps. See normalmap.hpp for the conventions.
#include "normalmap.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace dermis {
namespace {

/// Derivative along one axis at index k of n samples: central inside, one-sided at the ends,
/// 0 when n == 1. `get(k)` returns sample k.
template <class Get> double derivative(int k, int n, Get&& get) {
    if (n < 2) return 0.0;
    if (k == 0) return static_cast<double>(get(1)) - get(0);
    if (k == n - 1) return static_cast<double>(get(n - 1)) - get(n - 2);
    return 0.5 * (static_cast<double>(get(k + 1)) - get(k - 1));
}

/// normalize(−s·dx, s·dy, 1) without overflow for any finite s ≥ 0 and finite dx, dy.
glm::vec3 normalFromSlopes(double s, double dx, double dy) {
    const double gx = -s * dx, gy = s * dy;
    double x, y, z;
    if (std::isfinite(gx) && std::isfinite(gy)) {
        // Scale by the largest component first so that the squared length cannot overflow.
        const double m = std::max({1.0, std::abs(gx), std::abs(gy)});
        x = gx / m, y = gy / m, z = 1.0 / m;
    } else {
        // s·slope overflowed: the normal lies in the surface plane (z underflows to 0 anyway).
        const double m = std::max(std::abs(dx), std::abs(dy));
        x = -dx / m, y = dy / m, z = 0.0;
    }
    const double len = std::sqrt(x * x + y * y + z * z);
    return {static_cast<float>(x / len), static_cast<float>(y / len), static_cast<float>(z / len)};
}

std::uint8_t encodeComponent(float c) {
    const double v = std::isfinite(c) ? std::clamp(static_cast<double>(c), -1.0, 1.0) : 0.0;
    return static_cast<std::uint8_t>(std::lround((v * 0.5 + 0.5) * 255.0));
}

} // namespace

Result<NormalImage> normalMapFromBump(const HeightImage& bump, double strength) {
    const char* where = "dermis::normalMapFromBump";
    if (bump.width <= 0 || bump.height <= 0)
        return makeError(ErrorCode::InvalidArgument, where, "bump",
                         "empty image (" + std::to_string(bump.width) + "x" +
                             std::to_string(bump.height) + ")");
    const std::size_t n = static_cast<std::size_t>(bump.width) * bump.height;
    if (bump.data.size() != n)
        return makeError(ErrorCode::InvalidArgument, where, "bump",
                         "data has " + std::to_string(bump.data.size()) +
                             " values, expected width*height = " + std::to_string(n));
    if (!std::isfinite(strength) || strength < 0.0)
        return makeError(ErrorCode::InvalidArgument, where, "strength",
                         "must be finite and >= 0, got " + std::to_string(strength));
    for (std::size_t k = 0; k < n; ++k)
        if (!std::isfinite(bump.data[k]))
            return makeError(ErrorCode::InvalidArgument, where,
                             "bump.data[" + std::to_string(k) + "]", "height is not finite");

    NormalImage out;
    out.width = bump.width;
    out.height = bump.height;
    out.data.resize(n);
    const int w = bump.width, h = bump.height;
    for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i) {
            const double dx = derivative(i, w, [&](int k) { return bump.at(k, j); });
            const double dy = derivative(j, h, [&](int k) { return bump.at(i, k); });
            out.data[static_cast<std::size_t>(j) * w + i] = normalFromSlopes(strength, dx, dy);
        }
    return out;
}

Image8 encodeNormalMap8(const NormalImage& n) {
    Image8 out;
    if (n.width <= 0 || n.height <= 0 ||
        n.data.size() != static_cast<std::size_t>(n.width) * n.height)
        return out;
    out.width = n.width;
    out.height = n.height;
    out.rgba.resize(n.data.size() * 4);
    for (std::size_t k = 0; k < n.data.size(); ++k) {
        const glm::vec3& v = n.data[k];
        std::uint8_t* d = &out.rgba[k * 4];
        d[0] = encodeComponent(v.x);
        d[1] = encodeComponent(v.y);
        d[2] = encodeComponent(v.z);
        d[3] = 255;
    }
    return out;
}

double normalMapStrength(double bumpStrength, int mapWidth) {
    return 0.01 * bumpStrength * mapWidth;
}

} // namespace dermis
