// Dermis core — a small 5×7 pixel font for labels drawn into images (the sweep's contact sheet,
// SPEC §6 Sweep): digits, lower-case letters (upper case draws as lower case), space and
// . , - + = _ : / ( ) ? ° and θ. Each glyph is 5 columns × 7 rows on a 6-pixel advance; a
// code point the font lacks draws as '?'. Text is UTF-8; a malformed byte draws as '?'.
//
// Pure and thread-safe (the glyph table is immutable). Not a vector rasteriser: every font pixel
// becomes a scale×scale block; nothing is anti-aliased.
#pragma once

#include "model.hpp"

#include <array>
#include <cstdint>
#include <string_view>

namespace dermis {

inline constexpr int kGlyphWidth = 5;   ///< font pixels per glyph row
inline constexpr int kGlyphHeight = 7;  ///< font pixels per glyph column
inline constexpr int kGlyphAdvance = 6; ///< glyph width plus one pixel of space
inline constexpr int kLineHeight = 9;   ///< glyph height plus two pixels of space

using Rgba = std::array<std::uint8_t, 4>;

/// The rows of the glyph of `c`, top row first; bit 4 of a row is its leftmost pixel. nullptr
/// when the font has no glyph for `c` (upper-case ASCII letters map to their lower-case glyphs).
const std::array<std::uint8_t, kGlyphHeight>* glyphRows(char32_t c);

/// Width in pixels of `utf8` drawn at `scale` (≥ 1): code points × kGlyphAdvance × scale, less
/// the space after the last glyph; 0 for an empty string.
int textWidth(std::string_view utf8, int scale);

/// Draws `utf8` into `img` with the top-left of its first glyph at (x, y): every set font pixel
/// becomes a scale×scale block of `color` (alpha written as given). Clipped at the image's edges
/// (any x, y is allowed). Returns the x just after the last glyph's advance. Precondition:
/// scale ≥ 1 and img.rgba holds width·height·4 bytes.
int drawText(Image8& img, int x, int y, std::string_view utf8, int scale, Rgba color);

/// Darkens the rectangle [x, x+w) × [y, y+h) (clipped): each pixel's RGB times (1 − amount),
/// amount in [0, 1]; alpha untouched. The background that keeps a label readable on any frame.
void shadeRect(Image8& img, int x, int y, int w, int h, double amount);

} // namespace dermis
