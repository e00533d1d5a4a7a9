// Dermis core — contact sheets: equal-sized cells (rendered frames) laid out in a roughly square
// grid, each labelled with a few lines of the 5×7 label font (SPEC §6 Sweep).
//
// Pure CPU work on RGBA8 images; no encoding (the shell writes the PNG).
#pragma once

#include "bitmap_font.hpp"
#include "model.hpp"
#include "result.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace dermis {

struct SheetLayout {
    int cols = 0, rows = 0;
};

/// The grid of `cells` cells: cols = ceil(sqrt(cells)), rows = ceil(cells / cols) (0×0 for none).
SheetLayout sheetLayout(std::size_t cells);

/// Cells of `layout` in row-major order, each copied to (col·w, row·h) of a cols·w × rows·h image
/// (w, h: the first cell's size); grid slots without a cell are `background`. Fails
/// (InvalidArgument, field "cells") when there is no cell, a cell's size differs from the first's
/// or its pixel buffer does not match its size, or the layout has fewer slots than cells.
Result<Image8> composeSheet(const std::vector<Image8>& cells, SheetLayout layout,
                            Rgba background = {40, 40, 40, 255});

/// The label scale for a cell: 1 below 192 pixels on its shorter side, else 2.
int labelScale(const Image8& cell);

/// Draws `lines` in the cell's top-left corner at labelScale(cell): white text on a darkened box
/// as wide as the longest line. At most `maxLines` lines are drawn, and only as many as fit the
/// cell's height: when some are left out, the last line drawn is "+N" (how many were left out).
/// Text wider than the cell is clipped.
void labelCell(Image8& cell, const std::vector<std::string>& lines,
               std::size_t maxLines = SIZE_MAX);

} // namespace dermis
