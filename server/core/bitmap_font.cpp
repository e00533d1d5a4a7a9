// The 5×7 label font. See bitmap_font.hpp.
#include "bitmap_font.hpp"

#include <algorithm>
#include <map>

namespace dermis {

namespace {

struct GlyphArt {
    char32_t c;
    const char* rows[kGlyphHeight]; ///< '#' set, '.' clear; 5 characters each
};

// Digits and lower case after the HD44780 character ROM; punctuation drawn to match.
constexpr GlyphArt kArt[] = {
    {U' ', {".....", ".....", ".....", ".....", ".....", ".....", "....."}},
    {U'0', {".###.", "#...#", "#..##", "#.#.#", "##..#", "#...#", ".###."}},
    {U'1', {"..#..", ".##..", "..#..", "..#..", "..#..", "..#..", ".###."}},
    {U'2', {".###.", "#...#", "....#", "...#.", "..#..", ".#...", "#####"}},
    {U'3', {"#####", "...#.", "..#..", "...#.", "....#", "#...#", ".###."}},
    {U'4', {"...#.", "..##.", ".#.#.", "#..#.", "#####", "...#.", "...#."}},
    {U'5', {"#####", "#....", "####.", "....#", "....#", "#...#", ".###."}},
    {U'6', {"..##.", ".#...", "#....", "####.", "#...#", "#...#", ".###."}},
    {U'7', {"#####", "....#", "...#.", "..#..", ".#...", ".#...", ".#..."}},
    {U'8', {".###.", "#...#", "#...#", ".###.", "#...#", "#...#", ".###."}},
    {U'9', {".###.", "#...#", "#...#", ".####", "....#", "...#.", ".##.."}},
    {U'a', {".....", ".....", ".###.", "....#", ".####", "#...#", ".####"}},
    {U'b', {"#....", "#....", "#.##.", "##..#", "#...#", "#...#", "####."}},
    {U'c', {".....", ".....", ".###.", "#....", "#....", "#...#", ".###."}},
    {U'd', {"....#", "....#", ".##.#", "#..##", "#...#", "#...#", ".####"}},
    {U'e', {".....", ".....", ".###.", "#...#", "#####", "#....", ".###."}},
    {U'f', {"..##.", ".#..#", ".#...", "###..", ".#...", ".#...", ".#..."}},
    {U'g', {".....", ".####", "#...#", "#...#", ".####", "....#", ".###."}},
    {U'h', {"#....", "#....", "#.##.", "##..#", "#...#", "#...#", "#...#"}},
    {U'i', {"..#..", ".....", ".##..", "..#..", "..#..", "..#..", ".###."}},
    {U'j', {"...#.", ".....", "..##.", "...#.", "...#.", "#..#.", ".##.."}},
    {U'k', {"#....", "#....", "#..#.", "#.#..", "##...", "#.#..", "#..#."}},
    {U'l', {".##..", "..#..", "..#..", "..#..", "..#..", "..#..", ".###."}},
    {U'm', {".....", ".....", "##.#.", "#.#.#", "#.#.#", "#...#", "#...#"}},
    {U'n', {".....", ".....", "#.##.", "##..#", "#...#", "#...#", "#...#"}},
    {U'o', {".....", ".....", ".###.", "#...#", "#...#", "#...#", ".###."}},
    {U'p', {".....", ".....", "####.", "#...#", "####.", "#....", "#...."}},
    {U'q', {".....", ".....", ".##.#", "#..##", ".####", "....#", "....#"}},
    {U'r', {".....", ".....", "#.##.", "##..#", "#....", "#....", "#...."}},
    {U's', {".....", ".....", ".###.", "#....", ".###.", "....#", "####."}},
    {U't', {".#...", ".#...", "###..", ".#...", ".#...", ".#..#", "..##."}},
    {U'u', {".....", ".....", "#...#", "#...#", "#...#", "#..##", ".##.#"}},
    {U'v', {".....", ".....", "#...#", "#...#", "#...#", ".#.#.", "..#.."}},
    {U'w', {".....", ".....", "#...#", "#...#", "#.#.#", "#.#.#", ".#.#."}},
    {U'x', {".....", ".....", "#...#", ".#.#.", "..#..", ".#.#.", "#...#"}},
    {U'y', {".....", ".....", "#...#", "#...#", ".####", "....#", ".###."}},
    {U'z', {".....", ".....", "#####", "...#.", "..#..", ".#...", "#####"}},
    {U'.', {".....", ".....", ".....", ".....", ".....", ".##..", ".##.."}},
    {U',', {".....", ".....", ".....", ".....", ".##..", "..#..", ".#..."}},
    {U'-', {".....", ".....", ".....", "#####", ".....", ".....", "....."}},
    {U'+', {".....", "..#..", "..#..", "#####", "..#..", "..#..", "....."}},
    {U'=', {".....", ".....", "#####", ".....", "#####", ".....", "....."}},
    {U'_', {".....", ".....", ".....", ".....", ".....", ".....", "#####"}},
    {U':', {".....", ".##..", ".##..", ".....", ".##..", ".##..", "....."}},
    {U'/', {".....", "....#", "...#.", "..#..", ".#...", "#....", "....."}},
    {U'(', {"...#.", "..#..", ".#...", ".#...", ".#...", "..#..", "...#."}},
    {U')', {".#...", "..#..", "...#.", "...#.", "...#.", "..#..", ".#..."}},
    {U'?', {".###.", "#...#", "....#", "...#.", "..#..", ".....", "..#.."}},
    {U'\u00B0', {".##..", "#..#.", "#..#.", ".##..", ".....", ".....", "....."}}, // °
    {U'\u03B8', {".###.", "#...#", "#...#", "#####", "#...#", "#...#", ".###."}}, // θ
};

using Glyph = std::array<std::uint8_t, kGlyphHeight>;

const std::map<char32_t, Glyph>& glyphTable() {
    static const std::map<char32_t, Glyph> table = [] {
        std::map<char32_t, Glyph> t;
        for (const GlyphArt& art : kArt) {
            Glyph g{};
            for (int r = 0; r < kGlyphHeight; ++r)
                for (int c = 0; c < kGlyphWidth; ++c)
                    if (art.rows[r][c] == '#')
                        g[static_cast<std::size_t>(r)] |=
                            static_cast<std::uint8_t>(1u << (kGlyphWidth - 1 - c));
            t[art.c] = g;
        }
        return t;
    }();
    return table;
}

/// Decodes the next code point of `s` at `i` (advancing i); U+FFFD for a malformed sequence.
char32_t nextCodePoint(std::string_view s, std::size_t& i) {
    const auto b0 = static_cast<unsigned char>(s[i++]);
    if (b0 < 0x80) return b0;
    int extra = b0 >= 0xF0 && b0 < 0xF8 ? 3 : b0 >= 0xE0 ? 2 : b0 >= 0xC0 ? 1 : -1;
    if (extra < 0) return 0xFFFD;
    char32_t c = b0 & (0x3F >> extra);
    for (; extra > 0; --extra) {
        if (i >= s.size() || (static_cast<unsigned char>(s[i]) & 0xC0) != 0x80) return 0xFFFD;
        c = (c << 6) | (static_cast<unsigned char>(s[i++]) & 0x3F);
    }
    return c;
}

} // namespace

const Glyph* glyphRows(char32_t c) {
    if (c >= U'A' && c <= U'Z') c = c - U'A' + U'a';
    const auto& table = glyphTable();
    const auto it = table.find(c);
    return it == table.end() ? nullptr : &it->second;
}

int textWidth(std::string_view utf8, int scale) {
    int n = 0;
    for (std::size_t i = 0; i < utf8.size();) {
        nextCodePoint(utf8, i);
        ++n;
    }
    return n == 0 ? 0 : (n * kGlyphAdvance - 1) * scale;
}

int drawText(Image8& img, int x, int y, std::string_view utf8, int scale, Rgba color) {
    scale = std::max(scale, 1);
    for (std::size_t i = 0; i < utf8.size();) {
        const Glyph* g = glyphRows(nextCodePoint(utf8, i));
        if (!g) g = glyphRows(U'?');
        for (int r = 0; r < kGlyphHeight; ++r)
            for (int c = 0; c < kGlyphWidth; ++c) {
                if (!((*g)[static_cast<std::size_t>(r)] & (1u << (kGlyphWidth - 1 - c)))) continue;
                for (int dy = 0; dy < scale; ++dy)
                    for (int dx = 0; dx < scale; ++dx) {
                        const int px = x + c * scale + dx, py = y + r * scale + dy;
                        if (px < 0 || py < 0 || px >= img.width || py >= img.height) continue;
                        std::uint8_t* p =
                            &img.rgba[(static_cast<std::size_t>(py) * img.width + px) * 4];
                        std::copy(color.begin(), color.end(), p);
                    }
            }
        x += kGlyphAdvance * scale;
    }
    return x;
}

void shadeRect(Image8& img, int x, int y, int w, int h, double amount) {
    const double keep = 1.0 - std::clamp(amount, 0.0, 1.0);
    const int x0 = std::max(x, 0), y0 = std::max(y, 0);
    const int x1 = std::min(x + w, img.width), y1 = std::min(y + h, img.height);
    for (int py = y0; py < y1; ++py)
        for (int px = x0; px < x1; ++px) {
            std::uint8_t* p = &img.rgba[(static_cast<std::size_t>(py) * img.width + px) * 4];
            for (int k = 0; k < 3; ++k)
                p[k] = static_cast<std::uint8_t>(p[k] * keep + 0.5);
        }
}

} // namespace dermis
