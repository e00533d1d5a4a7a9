#include "preview.hpp"

#include <algorithm>
#include <cmath>

namespace dermis {

Image8 heightPreview(const HeightImage& src, int width) {
    const int w = width;
    const int h = std::max(1, static_cast<int>(std::lround(double(width) * src.height / src.width)));
    Image8 img;
    img.width = w;
    img.height = h;
    img.rgba.resize(static_cast<std::size_t>(w) * h * 4);
    for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i) {
            const float L = sampleBilinear(src, (i + 0.5) / w, (j + 0.5) / h);
            const auto g = static_cast<std::uint8_t>(
                std::lround(std::clamp((L + 1.0f) * 0.5f, 0.0f, 1.0f) * 255.0f));
            std::uint8_t* px = &img.rgba[(static_cast<std::size_t>(j) * w + i) * 4];
            px[0] = px[1] = px[2] = g;
            px[3] = 255;
        }
    return img;
}

} // namespace dermis
