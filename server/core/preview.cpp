#include "preview.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>

namespace dermis {

Image8 heightPreview(const HeightImage& src, int maxSide) {
    // The longer side gets maxSide, the other keeps the aspect ratio (issue #12.6: a 1×4096
    // pattern at width 256 asked for 256×1048576 pixels).
    const int longer = std::max(src.width, src.height);
    auto scaled = [&](int side) {
        return side == longer ? maxSide
                              : std::clamp(static_cast<int>(std::lround(double(side) * maxSide / longer)),
                                           1, maxSide);
    };
    const int w = scaled(src.width);
    const int h = scaled(src.height);
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

Image8 downsizeImage(const Image8& src, int maxSide) {
    const int longer = std::max(src.width, src.height);
    if (longer <= maxSide) return src;
    auto scaled = [&](int side) {
        return std::max(1, static_cast<int>(std::lround(double(side) * maxSide / longer)));
    };
    Image8 img;
    img.width = src.width == longer ? maxSide : scaled(src.width);
    img.height = src.height == longer ? maxSide : scaled(src.height);
    img.rgba.resize(static_cast<std::size_t>(img.width) * img.height * 4);
    // Source pixel k's centre (k + 0.5) lies in output pixel i's [i, i+1)·src/out when
    // k ∈ [ceil(i·src/out − 0.5), ceil((i+1)·src/out − 0.5)); never empty as out ≤ src.
    auto range = [](int i, int out, int in) {
        const double f = double(in) / out;
        int a = static_cast<int>(std::ceil(i * f - 0.5)), b = static_cast<int>(std::ceil((i + 1) * f - 0.5));
        a = std::clamp(a, 0, in - 1);
        b = std::clamp(b, a + 1, in);
        return std::pair<int, int>(a, b);
    };
    for (int j = 0; j < img.height; ++j) {
        const auto [y0, y1] = range(j, img.height, src.height);
        for (int i = 0; i < img.width; ++i) {
            const auto [x0, x1] = range(i, img.width, src.width);
            std::uint32_t sum[4] = {0, 0, 0, 0};
            for (int y = y0; y < y1; ++y)
                for (int x = x0; x < x1; ++x) {
                    const std::uint8_t* px = &src.rgba[(static_cast<std::size_t>(y) * src.width + x) * 4];
                    for (int c = 0; c < 4; ++c) sum[c] += px[c];
                }
            const std::uint32_t n = static_cast<std::uint32_t>((y1 - y0) * (x1 - x0));
            std::uint8_t* out = &img.rgba[(static_cast<std::size_t>(j) * img.width + i) * 4];
            for (int c = 0; c < 4; ++c) out[c] = static_cast<std::uint8_t>((sum[c] + n / 2) / n);
        }
    }
    return img;
}

} // namespace dermis
