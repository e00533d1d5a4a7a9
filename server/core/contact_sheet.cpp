// Contact sheets. See contact_sheet.hpp.
#include "contact_sheet.hpp"

#include <algorithm>
#include <cmath>

namespace dermis {

SheetLayout sheetLayout(std::size_t cells) {
    if (cells == 0) return {};
    int cols = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(cells)) - 1e-9));
    cols = std::max(cols, 1);
    const int rows = static_cast<int>((cells + static_cast<std::size_t>(cols) - 1) /
                                      static_cast<std::size_t>(cols));
    return {cols, rows};
}

Result<Image8> composeSheet(const std::vector<Image8>& cells, SheetLayout layout, Rgba background) {
    const char* where = "dermis::composeSheet";
    if (cells.empty()) return makeError(ErrorCode::InvalidArgument, where, "cells", "no cells");
    const int w = cells[0].width, h = cells[0].height;
    if (w <= 0 || h <= 0)
        return makeError(ErrorCode::InvalidArgument, where, "cells", "an empty cell");
    for (std::size_t k = 0; k < cells.size(); ++k)
        if (cells[k].width != w || cells[k].height != h ||
            cells[k].rgba.size() != static_cast<std::size_t>(w) * h * 4)
            return makeError(ErrorCode::InvalidArgument, where, "cells",
                             "cell " + std::to_string(k) + " is not " + std::to_string(w) + "x" +
                                 std::to_string(h) + " RGBA8 like the first");
    if (layout.cols <= 0 || layout.rows <= 0 ||
        static_cast<std::size_t>(layout.cols) * static_cast<std::size_t>(layout.rows) <
            cells.size())
        return makeError(ErrorCode::InvalidArgument, where, "cells",
                         "the layout has fewer slots than the " + std::to_string(cells.size()) +
                             " cells");
    Image8 sheet;
    sheet.width = layout.cols * w;
    sheet.height = layout.rows * h;
    sheet.rgba.resize(static_cast<std::size_t>(sheet.width) * sheet.height * 4);
    for (std::size_t p = 0; p < sheet.rgba.size(); p += 4)
        std::copy(background.begin(), background.end(),
                  sheet.rgba.begin() + static_cast<std::ptrdiff_t>(p));
    const std::size_t rowBytes = static_cast<std::size_t>(w) * 4;
    for (std::size_t k = 0; k < cells.size(); ++k) {
        const int col = static_cast<int>(k % static_cast<std::size_t>(layout.cols));
        const int row = static_cast<int>(k / static_cast<std::size_t>(layout.cols));
        for (int y = 0; y < h; ++y) {
            const auto src = cells[k].rgba.begin() + static_cast<std::ptrdiff_t>(y * rowBytes);
            const std::size_t dst =
                (static_cast<std::size_t>(row * h + y) * sheet.width + col * w) * 4;
            std::copy(src, src + static_cast<std::ptrdiff_t>(rowBytes),
                      sheet.rgba.begin() + static_cast<std::ptrdiff_t>(dst));
        }
    }
    return sheet;
}

int labelScale(const Image8& cell) {
    return std::min(cell.width, cell.height) < 192 ? 1 : 2;
}

void labelCell(Image8& cell, const std::vector<std::string>& lines, std::size_t maxLines) {
    if (lines.empty()) return;
    const int scale = labelScale(cell);
    const int pad = scale, lineH = kLineHeight * scale;
    const std::size_t fit = std::min<std::size_t>(
        maxLines,
        static_cast<std::size_t>(std::max(0, (cell.height - 2 * pad + 2 * scale) / lineH)));
    std::vector<std::string> shown(
        lines.begin(), lines.begin() + static_cast<std::ptrdiff_t>(std::min(fit, lines.size())));
    if (shown.size() < lines.size() && !shown.empty())
        shown.back() = "+" + std::to_string(lines.size() - shown.size() + 1);
    if (shown.empty()) return;
    int width = 0;
    for (const std::string& l : shown)
        width = std::max(width, textWidth(l, scale));
    const int boxH = static_cast<int>(shown.size()) * lineH - 2 * scale + 2 * pad;
    shadeRect(cell, 0, 0, width + 2 * pad, boxH, 0.6);
    for (std::size_t k = 0; k < shown.size(); ++k)
        drawText(cell, pad, pad + static_cast<int>(k) * lineH, shown[k], scale,
                 {255, 255, 255, 255});
}

} // namespace dermis
