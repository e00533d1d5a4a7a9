// CPU check images (see preview.hpp).
#include "preview.hpp"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>

namespace dermis::chargen {

RgbImage::RgbImage(int w, int h, glm::vec3 background) : width(w), height(h) {
    rgb.resize(static_cast<std::size_t>(w) * h * 3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            set(x, y, background);
}

void RgbImage::set(int x, int y, glm::vec3 c) {
    if (x < 0 || y < 0 || x >= width || y >= height) return;
    const std::size_t i = (static_cast<std::size_t>(y) * width + x) * 3;
    for (int k = 0; k < 3; ++k)
        rgb[i + k] = static_cast<std::uint8_t>(std::clamp(c[k], 0.0f, 1.0f) * 255.0f + 0.5f);
}

namespace {

float edgeFn(const glm::vec2& a, const glm::vec2& b, const glm::vec2& p) {
    return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
}

} // namespace

void renderMesh(RgbImage& img, const ViewSpec& view, const std::vector<glm::vec3>& positions,
                const std::vector<glm::vec3>& normals, const std::vector<glm::uvec3>& tris,
                const std::vector<glm::vec3>& colors) {
    const float yaw = view.yawDeg * 3.14159265f / 180.0f;
    const float pitch = view.pitchDeg * 3.14159265f / 180.0f;
    // Camera basis: forward f points from the camera into the scene.
    const glm::vec3 toCam(std::sin(yaw) * std::cos(pitch), std::sin(pitch),
                          std::cos(yaw) * std::cos(pitch));
    const glm::vec3 f = -toCam;
    const glm::vec3 right = glm::normalize(glm::cross(f, glm::vec3(0, 1, 0)));
    const glm::vec3 up = glm::cross(right, f);
    const glm::vec3 light = glm::normalize(toCam + glm::vec3(0.3f, 0.6f, 0.0f));
    std::vector<float> zbuf(static_cast<std::size_t>(view.width) * view.height,
                            std::numeric_limits<float>::infinity());
    auto project = [&](const glm::vec3& p) {
        const glm::vec3 d = p - view.centre;
        return glm::vec3(static_cast<float>(view.x0) + 0.5f * static_cast<float>(view.width) +
                             glm::dot(d, right) * view.pixelsPerMetre,
                         static_cast<float>(view.y0) + 0.5f * static_cast<float>(view.height) -
                             glm::dot(d, up) * view.pixelsPerMetre,
                         glm::dot(d, f));
    };
    for (const auto& t : tris) {
        const glm::vec3 s[3] = {project(positions[t[0]]), project(positions[t[1]]),
                                project(positions[t[2]])};
        const glm::vec2 a(s[0]), b(s[1]), c(s[2]);
        const float area = edgeFn(a, b, c);
        if (area >= 0.0f) continue; // back-facing (screen y points down)
        const int xmin = std::max(view.x0, static_cast<int>(std::floor(std::min({a.x, b.x, c.x}))));
        const int xmax = std::min(view.x0 + view.width - 1,
                                  static_cast<int>(std::ceil(std::max({a.x, b.x, c.x}))));
        const int ymin = std::max(view.y0, static_cast<int>(std::floor(std::min({a.y, b.y, c.y}))));
        const int ymax = std::min(view.y0 + view.height - 1,
                                  static_cast<int>(std::ceil(std::max({a.y, b.y, c.y}))));
        const float la = glm::length(b - c), lb = glm::length(c - a), lc = glm::length(a - b);
        for (int y = ymin; y <= ymax; ++y)
            for (int x = xmin; x <= xmax; ++x) {
                const glm::vec2 p(static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f);
                float w0 = edgeFn(b, c, p) / area, w1 = edgeFn(c, a, p) / area,
                      w2 = edgeFn(a, b, p) / area;
                if (w0 < 0 || w1 < 0 || w2 < 0) continue;
                const float z = w0 * s[0].z + w1 * s[1].z + w2 * s[2].z;
                float& zb =
                    zbuf[static_cast<std::size_t>(y - view.y0) * view.width + (x - view.x0)];
                if (z >= zb) continue;
                zb = z;
                glm::vec3 n =
                    glm::normalize(w0 * normals[t[0]] + w1 * normals[t[1]] + w2 * normals[t[2]]);
                glm::vec3 base(0.86f, 0.68f, 0.58f);
                if (!colors.empty())
                    base = w0 * colors[t[0]] + w1 * colors[t[1]] + w2 * colors[t[2]];
                const float lambert = std::max(glm::dot(n, light), 0.0f);
                const float rim = std::pow(1.0f - std::abs(glm::dot(n, toCam)), 3.0f) * 0.15f;
                glm::vec3 col = base * (0.25f + 0.75f * lambert) + glm::vec3(rim);
                if (view.wireframe) {
                    const float twiceArea = std::abs(area);
                    const float d =
                        std::min({w0 * twiceArea / la, w1 * twiceArea / lb, w2 * twiceArea / lc});
                    if (d < 0.6f) col *= 0.55f;
                }
                img.set(x, y, col);
            }
    }
}

void renderUv(RgbImage& img, int x0, int y0, int size, const std::vector<glm::vec2>& uvs,
              const std::vector<glm::uvec3>& tris, const std::vector<glm::vec3>& triColors) {
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x)
            img.set(x0 + x, y0 + y, glm::vec3(0.12f));
    for (std::size_t ti = 0; ti < tris.size(); ++ti) {
        const auto& t = tris[ti];
        const glm::vec2 a = uvs[t[0]] * float(size), b = uvs[t[1]] * float(size),
                        c = uvs[t[2]] * float(size);
        const float area = edgeFn(a, b, c);
        if (area == 0.0f) continue;
        const float la = glm::length(b - c), lb = glm::length(c - a), lc = glm::length(a - b);
        const int xmin = std::max(0, static_cast<int>(std::floor(std::min({a.x, b.x, c.x}))));
        const int xmax = std::min(size - 1, static_cast<int>(std::ceil(std::max({a.x, b.x, c.x}))));
        const int ymin = std::max(0, static_cast<int>(std::floor(std::min({a.y, b.y, c.y}))));
        const int ymax = std::min(size - 1, static_cast<int>(std::ceil(std::max({a.y, b.y, c.y}))));
        for (int y = ymin; y <= ymax; ++y)
            for (int x = xmin; x <= xmax; ++x) {
                const glm::vec2 p(static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f);
                const float w0 = edgeFn(b, c, p) / area, w1 = edgeFn(c, a, p) / area,
                            w2 = edgeFn(a, b, p) / area;
                if (w0 < 0 || w1 < 0 || w2 < 0) continue;
                glm::vec3 col = triColors.empty() ? glm::vec3(0.7f) : triColors[ti];
                const float twiceArea = std::abs(area);
                const float d =
                    std::min({w0 * twiceArea / la, w1 * twiceArea / lb, w2 * twiceArea / lc});
                if (d < 0.5f) col *= 0.45f;
                img.set(x0 + x, y0 + y, col);
            }
    }
}

bool writePng(const std::string& path, const RgbImage& img) {
    auto out = OIIO::ImageOutput::create(path);
    if (!out) {
        std::cerr << "cannot write " << path << ": " << OIIO::geterror() << "\n";
        return false;
    }
    OIIO::ImageSpec spec(img.width, img.height, 3, OIIO::TypeDesc::UINT8);
    if (!out->open(path, spec)) {
        std::cerr << out->geterror() << "\n";
        return false;
    }
    const bool ok = out->write_image(OIIO::TypeDesc::UINT8, img.rgb.data());
    return out->close() && ok;
}

} // namespace dermis::chargen
