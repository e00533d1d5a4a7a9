// The default character's UV atlas (see uv_atlas.hpp), step 4's packing: skyline bottom-left
// packing of the charts' boxes into a strip of width 1. buildAtlas searches the scale at which
// the strip stays within height 1. Declared in uv_atlas_internal.hpp.
#include "uv_atlas_internal.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace dermis::chargen::atlas_detail {

// --- packing ----------------------------------------------------------------------------------

/// Skyline bottom-left packing into a strip of width 1 (items sorted by height). Returns the
/// height used.
double skylinePack(std::vector<PackItem>& items) {
    std::vector<std::size_t> order(items.size());
    std::iota(order.begin(), order.end(), std::size_t(0));
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return items[a].h > items[b].h; });
    struct Seg {
        double x, w, y;
    };
    std::vector<Seg> sky{{0.0, 1.0, 0.0}};
    double used = 0;
    for (std::size_t k : order) {
        PackItem& it = items[k];
        double bestY = 1e30, bestX = 0;
        for (std::size_t i = 0; i < sky.size(); ++i) {
            if (sky[i].x + it.w > 1.0 + 1e-12) break;
            // Height needed to place at sky[i].x: max y over segments covered.
            double y = 0, covered = 0;
            for (std::size_t j = i; j < sky.size() && covered < it.w - 1e-12; ++j) {
                y = std::max(y, sky[j].y);
                covered = sky[j].x + sky[j].w - sky[i].x;
            }
            if (covered < it.w - 1e-12) continue;
            if (y < bestY - 1e-12) {
                bestY = y;
                bestX = sky[i].x;
            }
        }
        if (bestY > 1e29) return 1e30;
        it.x = bestX;
        it.y = bestY;
        used = std::max(used, bestY + it.h);
        // Update the skyline: replace [bestX, bestX + w) with one segment at bestY + h.
        std::vector<Seg> next;
        const double x0 = bestX, x1 = bestX + it.w;
        for (const Seg& s : sky) {
            const double s0 = s.x, s1 = s.x + s.w;
            if (s1 <= x0 + 1e-15 || s0 >= x1 - 1e-15) {
                next.push_back(s);
                continue;
            }
            if (s0 < x0) next.push_back({s0, x0 - s0, s.y});
            if (s1 > x1) next.push_back({x1, s1 - x1, s.y});
        }
        next.push_back({x0, x1 - x0, bestY + it.h});
        std::sort(next.begin(), next.end(), [](const Seg& a, const Seg& b) { return a.x < b.x; });
        // Merge neighbours at the same height.
        sky.clear();
        for (const Seg& s : next) {
            if (!sky.empty() && std::abs(sky.back().y - s.y) < 1e-15 &&
                std::abs(sky.back().x + sky.back().w - s.x) < 1e-12)
                sky.back().w += s.w;
            else
                sky.push_back(s);
        }
    }
    return used;
}

} // namespace dermis::chargen::atlas_detail
