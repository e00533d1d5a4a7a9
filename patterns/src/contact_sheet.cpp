// Dermis built-in pattern library — the contact sheet (shaded relief tiles with labels).
#include "patterns.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>

namespace dermis::patterngen {

namespace {

constexpr int kTile = 256, kPad = 10, kLabel = 22, kColumns = 3;

/// A 5×7 bitmap font: upper-case letters (used for lower-case too), digits, '_', '-', ' '.
struct Glyph {
    char c;
    std::array<const char*, 7> rows;
};
const Glyph kFont[] = {
    {'a', {" ### ", "#   #", "#   #", "#####", "#   #", "#   #", "#   #"}},
    {'b', {"#### ", "#   #", "#   #", "#### ", "#   #", "#   #", "#### "}},
    {'c', {" ### ", "#   #", "#    ", "#    ", "#    ", "#   #", " ### "}},
    {'d', {"#### ", "#   #", "#   #", "#   #", "#   #", "#   #", "#### "}},
    {'e', {"#####", "#    ", "#    ", "#### ", "#    ", "#    ", "#####"}},
    {'f', {"#####", "#    ", "#    ", "#### ", "#    ", "#    ", "#    "}},
    {'g', {" ### ", "#   #", "#    ", "# ###", "#   #", "#   #", " ####"}},
    {'h', {"#   #", "#   #", "#   #", "#####", "#   #", "#   #", "#   #"}},
    {'i', {" ### ", "  #  ", "  #  ", "  #  ", "  #  ", "  #  ", " ### "}},
    {'j', {"  ###", "   # ", "   # ", "   # ", "   # ", "#  # ", " ##  "}},
    {'k', {"#   #", "#  # ", "# #  ", "##   ", "# #  ", "#  # ", "#   #"}},
    {'l', {"#    ", "#    ", "#    ", "#    ", "#    ", "#    ", "#####"}},
    {'m', {"#   #", "## ##", "# # #", "# # #", "#   #", "#   #", "#   #"}},
    {'n', {"#   #", "#   #", "##  #", "# # #", "#  ##", "#   #", "#   #"}},
    {'o', {" ### ", "#   #", "#   #", "#   #", "#   #", "#   #", " ### "}},
    {'p', {"#### ", "#   #", "#   #", "#### ", "#    ", "#    ", "#    "}},
    {'q', {" ### ", "#   #", "#   #", "#   #", "# # #", "#  # ", " ## #"}},
    {'r', {"#### ", "#   #", "#   #", "#### ", "# #  ", "#  # ", "#   #"}},
    {'s', {" ####", "#    ", "#    ", " ### ", "    #", "    #", "#### "}},
    {'t', {"#####", "  #  ", "  #  ", "  #  ", "  #  ", "  #  ", "  #  "}},
    {'u', {"#   #", "#   #", "#   #", "#   #", "#   #", "#   #", " ### "}},
    {'v', {"#   #", "#   #", "#   #", "#   #", "#   #", " # # ", "  #  "}},
    {'w', {"#   #", "#   #", "#   #", "# # #", "# # #", "# # #", " # # "}},
    {'x', {"#   #", "#   #", " # # ", "  #  ", " # # ", "#   #", "#   #"}},
    {'y', {"#   #", "#   #", " # # ", "  #  ", "  #  ", "  #  ", "  #  "}},
    {'z', {"#####", "    #", "   # ", "  #  ", " #   ", "#    ", "#####"}},
    {'0', {" ### ", "#   #", "#  ##", "# # #", "##  #", "#   #", " ### "}},
    {'1', {"  #  ", " ##  ", "  #  ", "  #  ", "  #  ", "  #  ", " ### "}},
    {'2', {" ### ", "#   #", "    #", "   # ", "  #  ", " #   ", "#####"}},
    {'3', {"#####", "   # ", "  #  ", "   # ", "    #", "#   #", " ### "}},
    {'4', {"   # ", "  ## ", " # # ", "#  # ", "#####", "   # ", "   # "}},
    {'5', {"#####", "#    ", "#### ", "    #", "    #", "#   #", " ### "}},
    {'6', {"  ## ", " #   ", "#    ", "#### ", "#   #", "#   #", " ### "}},
    {'7', {"#####", "    #", "   # ", "  #  ", " #   ", " #   ", " #   "}},
    {'8', {" ### ", "#   #", "#   #", " ### ", "#   #", "#   #", " ### "}},
    {'9', {" ### ", "#   #", "#   #", " ####", "    #", "   # ", " ##  "}},
    {'_', {"     ", "     ", "     ", "     ", "     ", "     ", "#####"}},
    {'-', {"     ", "     ", "     ", "#####", "     ", "     ", "     "}},
};

const Glyph* glyph(char c) {
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
    for (const Glyph& g : kFont)
        if (g.c == c) return &g;
    return nullptr; // space and anything unknown: blank
}

struct Canvas {
    RgbImage& img;
    void put(int x, int y, std::array<unsigned char, 3> rgb) {
        if (x < 0 || y < 0 || x >= img.width || y >= img.height) return;
        std::size_t k = (static_cast<std::size_t>(y) * img.width + x) * 3;
        img.data[k] = rgb[0];
        img.data[k + 1] = rgb[1];
        img.data[k + 2] = rgb[2];
    }
    /// Draws text with its top-left corner at (x, y), `scale` pixels per font dot.
    void text(int x, int y, const std::string& s, int scale, std::array<unsigned char, 3> rgb) {
        for (char c : s) {
            if (const Glyph* g = glyph(c))
                for (int r = 0; r < 7; ++r)
                    for (int col = 0; col < 5; ++col)
                        if (g->rows[static_cast<std::size_t>(r)][col] == '#')
                            for (int dy = 0; dy < scale; ++dy)
                                for (int dx = 0; dx < scale; ++dx)
                                    put(x + col * scale + dx, y + r * scale + dy, rgb);
            x += 6 * scale;
        }
    }
};

unsigned char toByte(double linear) {
    double v = std::pow(std::clamp(linear, 0.0, 1.0), 1.0 / 2.2);
    return static_cast<unsigned char>(std::lround(v * 255.0));
}

/// Shaded relief of one pattern at full resolution, RGB in linear [0, 1].
std::vector<double> relief(const HeightImage& h) {
    const int w = h.width, n = h.height;
    auto at = [&](int i, int j) {
        return static_cast<double>(h.at(std::clamp(i, 0, w - 1), std::clamp(j, 0, n - 1)));
    };
    // Slopes in height per texel; the relief strength adapts so that the steep 1% of texels tilt
    // by about 45°, whatever the pattern's scale.
    std::vector<double> gx(h.data.size()), gy(h.data.size()), mag(h.data.size());
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < w; ++i) {
            std::size_t k = static_cast<std::size_t>(j) * w + i;
            gx[k] = 0.5 * (at(i + 1, j) - at(i - 1, j));
            gy[k] = 0.5 * (at(i, j + 1) - at(i, j - 1));
            mag[k] = std::sqrt(gx[k] * gx[k] + gy[k] * gy[k]);
        }
    std::vector<double> sorted = mag;
    auto p99 = sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() * 99 / 100);
    std::nth_element(sorted.begin(), p99, sorted.end());
    double strength = *p99 > 0.0 ? 1.0 / *p99 : 1.0;

    const double lx = -0.45, ly = -0.55, lz = 0.70; // light from the top left
    const double ll = std::sqrt(lx * lx + ly * ly + lz * lz);
    const double flat = lz / ll;
    std::vector<double> rgb(h.data.size() * 3);
    for (std::size_t k = 0; k < h.data.size(); ++k) {
        double nx = -strength * gx[k], ny = -strength * gy[k], nz = 1.0;
        double nl = std::sqrt(nx * nx + ny * ny + nz * nz);
        double diffuse = std::max(0.0, (nx * lx + ny * ly + nz * lz) / (nl * ll));
        double shade = 0.2 + 0.8 * diffuse / flat * 0.8;
        double L = static_cast<double>(h.data[k]);
        // Skin-like base; raised → warm, sunken → cool.
        double base[3] = {0.62, 0.55, 0.5};
        double warm[3] = {0.95, 0.45, 0.25}, cool[3] = {0.2, 0.38, 0.9};
        const double* tint = L >= 0.0 ? warm : cool;
        double a = 0.7 * std::min(1.0, std::abs(L));
        for (int c = 0; c < 3; ++c)
            rgb[k * 3 + c] = shade * (base[c] + a * (tint[c] - base[c]));
    }
    return rgb;
}

} // namespace

RgbImage contactSheet(const std::vector<GeneratedPattern>& patterns) {
    const int count = static_cast<int>(patterns.size());
    const int rows = (count + kColumns - 1) / kColumns;
    RgbImage sheet;
    sheet.width = kColumns * kTile + (kColumns + 1) * kPad;
    sheet.height = rows * (kTile + kLabel) + (rows + 1) * kPad;
    sheet.data.assign(static_cast<std::size_t>(sheet.width) * sheet.height * 3, 34);
    Canvas canvas{sheet};

    for (int p = 0; p < count; ++p) {
        const HeightImage& h = patterns[static_cast<std::size_t>(p)].image;
        const PatternInfo& info = patterns[static_cast<std::size_t>(p)].info;
        const int ox = kPad + (p % kColumns) * (kTile + kPad);
        const int oy = kPad + (p / kColumns) * (kTile + kLabel + kPad);
        std::vector<double> rgb = relief(h);
        // Box-filter the relief down to the tile (nearest when the pattern is smaller).
        for (int b = 0; b < kTile; ++b)
            for (int a = 0; a < kTile; ++a) {
                int i0 = a * h.width / kTile, i1 = std::max(i0 + 1, (a + 1) * h.width / kTile);
                int j0 = b * h.height / kTile, j1 = std::max(j0 + 1, (b + 1) * h.height / kTile);
                double acc[3] = {0, 0, 0};
                for (int j = j0; j < j1; ++j)
                    for (int i = i0; i < i1; ++i)
                        for (int c = 0; c < 3; ++c)
                            acc[c] += rgb[(static_cast<std::size_t>(j) * h.width + i) * 3 + c];
                double inv = 1.0 / ((i1 - i0) * (j1 - j0));
                canvas.put(ox + a, oy + b,
                           {toByte(acc[0] * inv), toByte(acc[1] * inv), toByte(acc[2] * inv)});
            }
        canvas.text(ox, oy + kTile + 5, info.id, 2, {235, 235, 235});
        std::string kind(toString(info.kind));
        canvas.text(ox + kTile - static_cast<int>(kind.size()) * 6, oy + kTile + 9, kind, 1,
                    {150, 170, 200});
    }
    return sheet;
}

} // namespace dermis::patterngen
