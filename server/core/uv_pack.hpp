// Dermis core — packing chart boxes into the UV square:
//   * skylinePack: bottom-left skyline packing of real-sized boxes into a strip of width 1 (the
//     default character's atlas, models/src/uv_atlas.cpp, searches the scale at which the strip
//     stays within height 1);
//   * skylinePackGrid: the same on a texel grid with integer boxes, each box optionally turned
//     by 90°, into a fixed rectangle (the generated layout, layout_gen.hpp).
//
// Pure, deterministic (ties broken by position and input order). Does not scale, rotate or move
// the charts themselves: callers map each box's place back onto their chart.
#pragma once

#include <vector>

namespace dermis {

/// One box of skylinePack: `chart` is the caller's tag; w, h its size in UV units (padding
/// included); x, y its place, written by skylinePack.
struct PackItem {
    int chart;
    double w, h; // size in UV units, padding included
    double x = 0, y = 0;
};

/// Skyline bottom-left packing into a strip of width 1 (items placed tallest first, stable for
/// equal heights). Returns the height used, or 1e30 when an item is wider than the strip.
double skylinePack(std::vector<PackItem>& items);

/// One box of skylinePackGrid, in whole cells: w, h ≥ 1 as given; x, y (the lower corner) and
/// `turned` (w and h swapped in place) written by skylinePackGrid.
struct GridBox {
    int w = 1, h = 1;
    int x = 0, y = 0;
    bool turned = false;
};

/// Places every box inside [0, width) × [0, height) without overlap: longest side first (then
/// the other side, then input order), each on the skyline where its top ends lowest, then where
/// it leaves the least empty area under it, then leftmost; with `allowTurn` both orientations
/// compete. Returns false (boxes partly placed) when one does not fit.
bool skylinePackGrid(std::vector<GridBox>& boxes, int width, int height, bool allowTurn = true);

} // namespace dermis
