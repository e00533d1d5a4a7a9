// Dermis core — packing chart boxes (uv_pack.hpp). skylinePack moved here from the default
// character's generator (models/src/uv_atlas_pack.cpp), unchanged in arithmetic so that its
// output stays bit-identical.
#include "uv_pack.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>

namespace dermis {

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

namespace {

struct Segment {
    int x, w, y;
};

/// Where a w×h box starting at skyline segment i would rest: its lower y and the empty area
/// under it; false when it runs past the right edge.
bool restAt(const std::vector<Segment>& sky, std::size_t i, int w, int width, int& y,
            std::int64_t& waste) {
    const int x0 = sky[i].x;
    if (x0 + w > width) return false;
    y = 0;
    int covered = 0;
    for (std::size_t j = i; j < sky.size() && covered < w; ++j) {
        y = std::max(y, sky[j].y);
        covered = sky[j].x + sky[j].w - x0;
    }
    if (covered < w) return false;
    waste = 0;
    for (std::size_t j = i; j < sky.size() && sky[j].x < x0 + w; ++j) {
        const int a = std::max(sky[j].x, x0), b = std::min(sky[j].x + sky[j].w, x0 + w);
        waste += static_cast<std::int64_t>(b - a) * (y - sky[j].y);
    }
    return true;
}

} // namespace

bool skylinePackGrid(std::vector<GridBox>& boxes, int width, int height, bool allowTurn) {
    std::vector<std::size_t> order(boxes.size());
    std::iota(order.begin(), order.end(), std::size_t(0));
    auto longSide = [&](const GridBox& b) { return allowTurn ? std::max(b.w, b.h) : b.h; };
    auto shortSide = [&](const GridBox& b) { return allowTurn ? std::min(b.w, b.h) : b.w; };
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        const GridBox &A = boxes[a], &B = boxes[b];
        if (longSide(A) != longSide(B)) return longSide(A) > longSide(B);
        return shortSide(A) > shortSide(B);
    });
    std::vector<Segment> sky{{0, width, 0}};
    for (std::size_t k : order) {
        GridBox& box = boxes[k];
        bool found = false;
        int bestTop = 0, bestX = 0, bestY = 0;
        std::int64_t bestWaste = 0;
        bool bestTurned = false;
        for (int turn = 0; turn < (allowTurn && box.w != box.h ? 2 : 1); ++turn) {
            const int w = turn ? box.h : box.w, h = turn ? box.w : box.h;
            for (std::size_t i = 0; i < sky.size(); ++i) {
                int y = 0;
                std::int64_t waste = 0;
                if (!restAt(sky, i, w, width, y, waste) || y + h > height) continue;
                const int top = y + h;
                if (!found || top < bestTop || (top == bestTop && waste < bestWaste) ||
                    (top == bestTop && waste == bestWaste && sky[i].x < bestX)) {
                    found = true;
                    bestTop = top;
                    bestWaste = waste;
                    bestX = sky[i].x;
                    bestY = y;
                    bestTurned = turn != 0;
                }
            }
        }
        if (!found) return false;
        box.turned = bestTurned;
        box.x = bestX;
        box.y = bestY;
        const int w = bestTurned ? box.h : box.w;
        // Replace [x, x + w) of the skyline with one segment at the box's top.
        std::vector<Segment> next;
        next.reserve(sky.size() + 2);
        bool inserted = false;
        for (const Segment& s : sky) {
            const int s0 = s.x, s1 = s.x + s.w;
            if (s1 <= bestX || s0 >= bestX + w) {
                if (!inserted && s0 >= bestX + w) {
                    next.push_back({bestX, w, bestTop});
                    inserted = true;
                }
                next.push_back(s);
                continue;
            }
            if (s0 < bestX) next.push_back({s0, bestX - s0, s.y});
            if (!inserted) {
                next.push_back({bestX, w, bestTop});
                inserted = true;
            }
            if (s1 > bestX + w) next.push_back({bestX + w, s1 - bestX - w, s.y});
        }
        if (!inserted) next.push_back({bestX, w, bestTop});
        sky.clear();
        for (const Segment& s : next) {
            if (!sky.empty() && sky.back().y == s.y)
                sky.back().w += s.w;
            else
                sky.push_back(s);
        }
    }
    return true;
}

} // namespace dermis
