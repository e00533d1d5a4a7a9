#include "image_similarity.hpp"

#include <vector>

namespace dermis {

Result<double> ssim(const Image8& a, const Image8& b) {
    const char* where = "dermis::ssim";
    const auto holds = [](const Image8& i) {
        return i.width > 0 && i.height > 0 &&
               i.rgba.size() == static_cast<std::size_t>(i.width) * static_cast<std::size_t>(i.height) * 4;
    };
    if (!holds(a) || !holds(b)) return makeError(ErrorCode::InvalidArgument, where, "b", "an image's buffer does not match its size");
    if (a.width != b.width || a.height != b.height)
        return makeError(ErrorCode::InvalidArgument, where, "b",
                         "sizes differ: " + std::to_string(a.width) + "x" + std::to_string(a.height) + " and " +
                             std::to_string(b.width) + "x" + std::to_string(b.height));
    if (a.width < 8 || a.height < 8) return makeError(ErrorCode::InvalidArgument, where, "b", "images smaller than 8x8");
    const int w = a.width, h = a.height;
    const auto luma = [&](const Image8& img) {
        std::vector<float> y(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
        for (std::size_t i = 0; i < y.size(); ++i)
            y[i] = 0.299f * img.rgba[4 * i] + 0.587f * img.rgba[4 * i + 1] + 0.114f * img.rgba[4 * i + 2];
        return y;
    };
    const std::vector<float> ya = luma(a), yb = luma(b);
    constexpr double c1 = (0.01 * 255) * (0.01 * 255), c2 = (0.03 * 255) * (0.03 * 255);
    constexpr int kWindow = 8, kStride = 4;
    double sum = 0.0;
    long long windows = 0;
    for (int y0 = 0; y0 + kWindow <= h; y0 += kStride)
        for (int x0 = 0; x0 + kWindow <= w; x0 += kStride) {
            double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
            for (int y = y0; y < y0 + kWindow; ++y)
                for (int x = x0; x < x0 + kWindow; ++x) {
                    const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
                    const double pa = ya[i], pb = yb[i];
                    sa += pa;
                    sb += pb;
                    saa += pa * pa;
                    sbb += pb * pb;
                    sab += pa * pb;
                }
            const double n = kWindow * kWindow;
            const double ma = sa / n, mb = sb / n;
            const double va = saa / n - ma * ma, vb = sbb / n - mb * mb, cov = sab / n - ma * mb;
            sum += ((2 * ma * mb + c1) * (2 * cov + c2)) / ((ma * ma + mb * mb + c1) * (va + vb + c2));
            ++windows;
        }
    return sum / static_cast<double>(windows);
}

Result<Image8> boxDownsample(const Image8& image, int factor) {
    const char* where = "dermis::boxDownsample";
    if (factor < 1) return makeError(ErrorCode::InvalidArgument, where, "factor", "must be at least 1");
    if (image.rgba.size() != static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height) * 4 ||
        image.width < factor || image.height < factor)
        return makeError(ErrorCode::InvalidArgument, where, "image", "smaller than one block or a buffer that does not match its size");
    Image8 out;
    out.width = image.width / factor;
    out.height = image.height / factor;
    out.rgba.resize(static_cast<std::size_t>(out.width) * static_cast<std::size_t>(out.height) * 4);
    const int n = factor * factor;
    for (int y = 0; y < out.height; ++y)
        for (int x = 0; x < out.width; ++x)
            for (std::size_t c = 0; c < 4; ++c) {
                int sum = 0;
                for (int dy = 0; dy < factor; ++dy)
                    for (int dx = 0; dx < factor; ++dx)
                        sum += image.rgba[(static_cast<std::size_t>(y * factor + dy) * static_cast<std::size_t>(image.width) +
                                           static_cast<std::size_t>(x * factor + dx)) * 4 + c];
                out.rgba[(static_cast<std::size_t>(y) * static_cast<std::size_t>(out.width) + static_cast<std::size_t>(x)) * 4 + c] =
                    static_cast<std::uint8_t>((sum + n / 2) / n);
            }
    return out;
}

} // namespace dermis
