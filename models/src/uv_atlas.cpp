// The default character's UV atlas (see uv_atlas.hpp): buildAtlas runs the steps — regions
// (made connected here), cuts into disks and flattening (with extra cuts to crushed parts),
// orientation, density and packing — and builds and verifies the output (seam vertices, every UV
// in [0,1], no flipped triangle, no overlapping charts, distortion statistics); uvAt looks a
// surface point up in the atlas. The regions are in uv_atlas_regions.cpp (uv_atlas_internal.hpp),
// flattening and packing in the core (core/uv_flatten.hpp, core/uv_pack.hpp).
#include "uv_atlas.hpp"

#include "uv_atlas_internal.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <numeric>
#include <queue>
#include <set>

namespace dermis::chargen {

using namespace atlas_detail;

bool buildAtlas(const TriMesh& mesh, const Body& body, const Skeleton& skeleton, Atlas& atlas,
                std::string& error, std::FILE* log) {
    const Rules rules(skeleton);
    const std::size_t nt = mesh.tris.size();
    const auto adj = adjacency(mesh);
    std::vector<glm::vec3> vn(mesh.positions.size());
    for (std::size_t v = 0; v < vn.size(); ++v)
        vn[v] = glm::normalize(body.gradient(mesh.positions[v]));

    // 1. Regions.
    std::vector<int> region(nt);
    for (std::size_t t = 0; t < nt; ++t) {
        const auto& tri = mesh.tris[t];
        const glm::vec3 c =
            (mesh.positions[tri[0]] + mesh.positions[tri[1]] + mesh.positions[tri[2]]) / 3.0f;
        const glm::vec3 n = glm::normalize(vn[tri[0]] + vn[tri[1]] + vn[tri[2]]);
        region[t] = rules.classify(c, n);
    }
    // Smooth ragged borders: a triangle with at most one neighbour in its own region (a tooth)
    // joins the region of its other neighbours (the lower region id on a tie).
    // Sequential updates (no oscillation); ends when no tooth is left.
    for (int pass = 0; pass < 30; ++pass) {
        std::vector<int>& next = region;
        bool changed = false;
        for (std::size_t t = 0; t < nt; ++t) {
            int same = 0;
            std::map<int, int> other;
            for (int o : adj[t]) {
                const int r = region[static_cast<std::size_t>(o)];
                if (r == region[t])
                    ++same;
                else
                    ++other[r];
            }
            if (same >= 2) continue;
            int best = -1, bestN = 0;
            for (const auto& [r, n] : other)
                if (n > bestN) best = r, bestN = n;
            next[t] = best;
            changed = true;
        }
        if (!changed) break;
    }
    // Connected pieces: keep each region's largest; smaller pieces join the neighbouring region
    // they share most edges with. Repeat until stable.
    for (int pass = 0; pass < 20; ++pass) {
        std::vector<int> comp(nt, -1);
        std::vector<int> compRegion, compSize;
        for (std::size_t s = 0; s < nt; ++s) {
            if (comp[s] >= 0) continue;
            const int id = static_cast<int>(compRegion.size());
            compRegion.push_back(region[s]);
            compSize.push_back(0);
            std::vector<std::size_t> stack{s};
            comp[s] = id;
            while (!stack.empty()) {
                const std::size_t t = stack.back();
                stack.pop_back();
                ++compSize[static_cast<std::size_t>(id)];
                for (int o : adj[t])
                    if (comp[static_cast<std::size_t>(o)] < 0 &&
                        region[static_cast<std::size_t>(o)] == region[s]) {
                        comp[static_cast<std::size_t>(o)] = id;
                        stack.push_back(static_cast<std::size_t>(o));
                    }
            }
        }
        std::vector<int> largest(kRegionCount, -1);
        for (std::size_t c = 0; c < compRegion.size(); ++c) {
            int& l = largest[static_cast<std::size_t>(compRegion[c])];
            if (l < 0 || compSize[c] > compSize[static_cast<std::size_t>(l)])
                l = static_cast<int>(c);
        }
        bool changed = false;
        for (std::size_t c = 0; c < compRegion.size(); ++c) {
            if (largest[static_cast<std::size_t>(compRegion[c])] == static_cast<int>(c)) continue;
            std::map<int, int> shared;
            for (std::size_t t = 0; t < nt; ++t)
                if (comp[t] == static_cast<int>(c))
                    for (int o : adj[t])
                        if (comp[static_cast<std::size_t>(o)] != static_cast<int>(c))
                            ++shared[region[static_cast<std::size_t>(o)]];
            int bestR = -1, bestN = -1;
            for (const auto& [r, cnt] : shared)
                if (cnt > bestN) bestR = r, bestN = cnt;
            for (std::size_t t = 0; t < nt; ++t)
                if (comp[t] == static_cast<int>(c)) region[t] = bestR;
            changed = true;
        }
        if (!changed) break;
    }

    // 2–3. Cut each region into a disk and flatten it.
    struct ChartUv {
        LocalMesh lm;
        std::vector<glm::dvec2> uv;
    };
    std::vector<ChartUv> charts;
    std::vector<int> chartRegion;
    for (int r = 0; r < kRegionCount; ++r) {
        std::vector<int> tris;
        for (std::size_t t = 0; t < nt; ++t)
            if (region[t] == r) tris.push_back(static_cast<int>(t));
        if (tris.empty()) continue;
        const RegionSpec& spec = rules.specs[static_cast<std::size_t>(r)];
        std::set<EdgeKey> cuts;
        LocalMesh lm = buildLocal(mesh, adj, tris, region, r, cuts);
        if (lm.loops.empty()) {
            error = "region " + spec.name + " has no boundary";
            return false;
        }
        // Shortest path (weighted to the seam side) from `sources` through interior vertices to
        // the first vertex where isTarget holds; its edges join `cuts`. False when none.
        auto cutPath = [&](const LocalMesh& l, const std::vector<std::uint32_t>& sources,
                           const std::function<bool(std::uint32_t)>& isTarget) {
            const std::size_t nv = l.source.size();
            std::vector<std::vector<std::pair<std::uint32_t, double>>> g(nv);
            std::map<EdgeKey, int> edgeTri;
            for (const auto& t : l.local)
                for (int c = 0; c < 3; ++c)
                    ++edgeTri[edgeKey(t[c], t[(c + 1) % 3])];
            for (const auto& [e, cnt] : edgeTri) {
                if (cnt != 2) continue; // boundary edge
                const glm::vec3 pa = mesh.positions[l.source[e.first]],
                                pb = mesh.positions[l.source[e.second]];
                const glm::vec3 n = glm::normalize(vn[l.source[e.first]] + vn[l.source[e.second]]);
                const double bias =
                    1.0 + 8.0 * (1.0 - glm::dot(n, glm::normalize(spec.seamSide))) * 0.5;
                const double w = glm::length(pb - pa) * bias;
                g[e.first].push_back({e.second, w});
                g[e.second].push_back({e.first, w});
            }
            std::vector<char> isSource(nv, 0);
            for (std::uint32_t v : sources)
                isSource[v] = 1;
            std::vector<double> dist(nv, 1e30);
            std::vector<std::int64_t> prev(nv, -1);
            using QE = std::pair<double, std::uint32_t>;
            std::priority_queue<QE, std::vector<QE>, std::greater<QE>> pq;
            for (std::uint32_t v : sources) {
                dist[v] = 0;
                pq.push({0.0, v});
            }
            std::int64_t hit = -1;
            while (!pq.empty()) {
                const auto [dv, v] = pq.top();
                pq.pop();
                if (dv > dist[v]) continue;
                if (!isSource[v] && isTarget(v)) {
                    hit = v;
                    break;
                }
                if (isSource[v] && dv > 0) continue; // never walk along the sources
                for (const auto& [w, len] : g[v]) {
                    if (isSource[w]) continue;
                    if (dv + len < dist[w]) {
                        dist[w] = dv + len;
                        prev[w] = v;
                        pq.push({dist[w], w});
                    }
                }
            }
            if (hit < 0) return false;
            for (std::int64_t v = hit; prev[static_cast<std::size_t>(v)] >= 0;
                 v = prev[static_cast<std::size_t>(v)])
                cuts.insert(
                    edgeKey(l.source[static_cast<std::size_t>(v)],
                            l.source[static_cast<std::size_t>(prev[static_cast<std::size_t>(v)])]));
            return true;
        };
        int guard = 0;
        while (lm.loops.size() > 1) {
            if (++guard > 16) {
                error = "region " + spec.name + ": cannot cut into a disk";
                return false;
            }
            // Cut from the last loop through interior vertices to any other loop.
            const int from = static_cast<int>(lm.loops.size()) - 1;
            std::vector<std::uint32_t> sources = lm.loops[static_cast<std::size_t>(from)];
            if (!cutPath(lm, sources, [&](std::uint32_t v) {
                    return lm.loopOf[v] >= 0 && lm.loopOf[v] != from;
                })) {
                error = "region " + spec.name + ": no cut path between boundary loops";
                return false;
            }
            lm = buildLocal(mesh, adj, tris, region, r, cuts);
        }
        std::string note;
        std::vector<glm::dvec2> uv;
        for (int extra = 0;; ++extra) {
            // Disk check: V − E + F = 1.
            std::set<EdgeKey> edges;
            for (const auto& t : lm.local)
                for (int c = 0; c < 3; ++c)
                    edges.insert(edgeKey(t[c], t[(c + 1) % 3]));
            const long chi = static_cast<long>(lm.source.size()) - static_cast<long>(edges.size()) +
                             static_cast<long>(lm.local.size());
            if (chi != 1 || lm.loops.size() != 1) {
                error = "region " + spec.name +
                        " is not a disk after cutting (χ = " + std::to_string(chi) + ")";
                return false;
            }
            ChartMesh chart;
            chart.triangles = lm.local;
            chart.positions.reserve(lm.source.size());
            for (std::uint32_t v : lm.source)
                chart.positions.emplace_back(mesh.positions[v]);
            uv = flattenDisk(chart, lm.loops[0], note);
            if (uv.empty()) {
                error = "region " + spec.name + ": " + note;
                return false;
            }
            // A part that stays crushed (a fingertip folded by the initial embedding) gets a cut
            // from the boundary to it, and the chart is flattened again.
            double worst = 0;
            std::int64_t worstVertex = -1;
            for (const auto& t : lm.local) {
                const double dist = conformalDistortion(
                    mesh.positions[lm.source[t[0]]], mesh.positions[lm.source[t[1]]],
                    mesh.positions[lm.source[t[2]]], uv[t[0]], uv[t[1]], uv[t[2]]);
                for (int c = 0; c < 3; ++c)
                    if (dist > worst && lm.loopOf[t[c]] < 0) {
                        worst = dist;
                        worstVertex = t[c];
                    }
            }
            if (log && worst >= 6.0)
                std::fprintf(log, "  %s: worst distortion %.1f, extra cut %d\n", spec.name.c_str(),
                             worst, extra);
            if (worst < 6.0 || worstVertex < 0 || extra == 6) break;
            const auto target = static_cast<std::uint32_t>(worstVertex);
            if (!cutPath(lm, lm.loops[0], [&](std::uint32_t v) { return v == target; })) break;
            lm = buildLocal(mesh, adj, tris, region, r, cuts);
        }
        if (log)
            std::fprintf(log, "flattened %-12s %5zu triangles, %4zu vertices, %2zu cut edges, %s\n",
                         spec.name.c_str(), lm.local.size(), lm.source.size(), cuts.size(),
                         note.c_str());
        charts.push_back({std::move(lm), std::move(uv)});
        chartRegion.push_back(r);
    }

    // 4. Orientation (body "up" → texture up, never mirrored), density, packing.
    std::vector<PackItem> items;
    std::vector<glm::dvec2> chartLo(charts.size());
    for (std::size_t c = 0; c < charts.size(); ++c) {
        ChartUv& ch = charts[c];
        const RegionSpec& spec = rules.specs[static_cast<std::size_t>(chartRegion[c])];
        // Flatten produced positively oriented triangles in (x, y-up) terms; in glTF's (u, v-down)
        // image space that reads as the surface seen from outside, not mirrored, once v = −y.
        // Rotate so that the gradient of the height function (world `up`) points to −v.
        glm::dvec2 grad(0);
        for (const auto& t : ch.lm.local) {
            const glm::dvec2 a = ch.uv[t[0]], b = ch.uv[t[1]], cc = ch.uv[t[2]];
            const double h0 =
                glm::dot(glm::dvec3(mesh.positions[ch.lm.source[t[0]]]), glm::dvec3(spec.up));
            const double h1 =
                glm::dot(glm::dvec3(mesh.positions[ch.lm.source[t[1]]]), glm::dvec3(spec.up));
            const double h2 =
                glm::dot(glm::dvec3(mesh.positions[ch.lm.source[t[2]]]), glm::dvec3(spec.up));
            // Gradient of the linear interpolant, times area (area-weighted sum).
            const glm::dvec2 g((h1 - h0) * (cc.y - a.y) - (h2 - h0) * (b.y - a.y),
                               (h2 - h0) * (b.x - a.x) - (h1 - h0) * (cc.x - a.x));
            grad += g;
        }
        const double ang = std::atan2(grad.y, grad.x);
        const double rotate = 3.14159265358979323846 / 2 - ang; // bring grad to +y (y-up)
        const double cs = std::cos(rotate), sn = std::sin(rotate);
        for (auto& p : ch.uv)
            p = glm::dvec2(cs * p.x - sn * p.y, sn * p.x + cs * p.y);
        for (auto& p : ch.uv)
            p = glm::dvec2(p.x, -p.y) * static_cast<double>(spec.scale);
        glm::dvec2 lo(1e30), hi(-1e30);
        for (const auto& p : ch.uv) {
            lo = glm::min(lo, p);
            hi = glm::max(hi, p);
        }
        chartLo[c] = lo;
        items.push_back({static_cast<int>(c), hi.x - lo.x, hi.y - lo.y});
    }
    // Largest scale at which everything fits in [0,1]² with a padding of 6 texels at 1024².
    const double pad = 6.0 / 1024.0;
    double lo = 0.05, hi = 2.0, bestScale = 0;
    std::vector<PackItem> bestItems;
    for (int it = 0; it < 40; ++it) {
        const double s = 0.5 * (lo + hi);
        std::vector<PackItem> trial = items;
        for (auto& p : trial) {
            p.w = p.w * s + 2 * pad;
            p.h = p.h * s + 2 * pad;
        }
        const double used = skylinePack(trial);
        if (used <= 1.0) {
            lo = s;
            bestScale = s;
            bestItems = trial;
        } else {
            hi = s;
        }
    }
    if (bestScale <= 0) {
        error = "packing failed";
        return false;
    }

    // Output vertices and triangles.
    atlas = Atlas{};
    atlas.tris.assign(nt, glm::uvec3(0));
    atlas.triChart.assign(nt, -1);
    for (const PackItem& it : bestItems) {
        const auto c = static_cast<std::size_t>(it.chart);
        const ChartUv& ch = charts[c];
        const auto base = static_cast<std::uint32_t>(atlas.uvs.size());
        ChartInfo info;
        info.name = rules.specs[static_cast<std::size_t>(chartRegion[c])].name;
        info.lo = glm::vec2(1e9f);
        info.hi = glm::vec2(-1e9f);
        for (std::size_t v = 0; v < ch.lm.source.size(); ++v) {
            const glm::dvec2 p =
                (ch.uv[v] - chartLo[c]) * bestScale + glm::dvec2(it.x + pad, it.y + pad);
            const glm::vec2 uv(static_cast<float>(p.x), static_cast<float>(p.y));
            atlas.uvs.push_back(uv);
            atlas.source.push_back(ch.lm.source[v]);
            info.lo = glm::min(info.lo, uv);
            info.hi = glm::max(info.hi, uv);
        }
        for (std::size_t i = 0; i < ch.lm.tris.size(); ++i) {
            const auto t = static_cast<std::size_t>(ch.lm.tris[i]);
            atlas.tris[t] = ch.lm.local[i] + glm::uvec3(base);
            atlas.triChart[t] = static_cast<int>(atlas.charts.size());
        }
        info.triangles = static_cast<int>(ch.lm.tris.size());
        atlas.charts.push_back(info);
    }
    // Chart order in the output: by name (stable, readable), remapped.
    {
        std::vector<int> order(atlas.charts.size());
        std::iota(order.begin(), order.end(), 0);
        std::sort(order.begin(), order.end(), [&](int a, int b) {
            return atlas.charts[static_cast<std::size_t>(a)].name <
                   atlas.charts[static_cast<std::size_t>(b)].name;
        });
        std::vector<int> rank(order.size());
        std::vector<ChartInfo> sorted;
        for (std::size_t k = 0; k < order.size(); ++k) {
            rank[static_cast<std::size_t>(order[k])] = static_cast<int>(k);
            sorted.push_back(atlas.charts[static_cast<std::size_t>(order[k])]);
        }
        atlas.charts = sorted;
        for (int& c : atlas.triChart)
            c = rank[static_cast<std::size_t>(c)];
    }

    // Verification and statistics.
    for (std::size_t t = 0; t < nt; ++t) {
        if (atlas.triChart[t] < 0) {
            error = "triangle " + std::to_string(t) + " has no chart";
            return false;
        }
        const glm::uvec3& tri = atlas.tris[t];
        for (int c = 0; c < 3; ++c) {
            if (atlas.source[tri[c]] != mesh.tris[t][c]) {
                error = "internal: seam vertex mismatch";
                return false;
            }
            const glm::vec2 uv = atlas.uvs[tri[c]];
            if (!(uv.x >= 0 && uv.x <= 1 && uv.y >= 0 && uv.y <= 1)) {
                error = "UV outside [0,1]";
                return false;
            }
        }
        // v-down: a front face reads clockwise in (u, v) maths terms, i.e. negative area.
        const glm::dvec2 a(atlas.uvs[tri[0]]), b(atlas.uvs[tri[1]]), c(atlas.uvs[tri[2]]);
        if (!(signedArea(a, b, c) < 0)) {
            error = "flipped or degenerate UV triangle " + std::to_string(t);
            return false;
        }
        ChartInfo& info = atlas.charts[static_cast<std::size_t>(atlas.triChart[t])];
        const glm::vec3 p0 = mesh.positions[mesh.tris[t][0]], p1 = mesh.positions[mesh.tris[t][1]],
                        p2 = mesh.positions[mesh.tris[t][2]];
        info.surfaceArea += 0.5f * glm::length(glm::cross(p1 - p0, p2 - p0));
        info.uvArea += static_cast<float>(-signedArea(a, b, c));
    }
    // Distortion: singular values of the map surface → UV per triangle.
    std::vector<double> confSum(atlas.charts.size(), 0), spreadSum(atlas.charts.size(), 0),
        areaSum(atlas.charts.size(), 0);
    for (std::size_t t = 0; t < nt; ++t) {
        const auto ci = static_cast<std::size_t>(atlas.triChart[t]);
        const ChartInfo& info = atlas.charts[ci];
        const glm::dvec3 p0(mesh.positions[mesh.tris[t][0]]), p1(mesh.positions[mesh.tris[t][1]]),
            p2(mesh.positions[mesh.tris[t][2]]);
        const glm::dvec2 u0(atlas.uvs[atlas.tris[t][0]]), u1(atlas.uvs[atlas.tris[t][1]]),
            u2(atlas.uvs[atlas.tris[t][2]]);
        const MapSingularValues sv = mapSingularValues(p0, p1, p2, u0, u1, u2);
        const double smax = sv.smax, smin = std::max(sv.smin, std::sqrt(1e-30)), det = sv.det;
        const double area = 0.5 * glm::length(glm::cross(p1 - p0, p2 - p0));
        const double chartScale = info.uvArea / info.surfaceArea;
        confSum[ci] += area * smax / smin;
        spreadSum[ci] += area * std::abs(std::log(det / chartScale));
        areaSum[ci] += area;
    }
    for (std::size_t c = 0; c < atlas.charts.size(); ++c) {
        atlas.charts[c].conformal = static_cast<float>(confSum[c] / areaSum[c]);
        atlas.charts[c].areaSpread = static_cast<float>(spreadSum[c] / areaSum[c]);
    }
    // Charts never overlap: packed boxes are disjoint (padding included).
    for (std::size_t a = 0; a < atlas.charts.size(); ++a)
        for (std::size_t b = a + 1; b < atlas.charts.size(); ++b) {
            const ChartInfo &A = atlas.charts[a], &B = atlas.charts[b];
            if (A.lo.x < B.hi.x && B.lo.x < A.hi.x && A.lo.y < B.hi.y && B.lo.y < A.hi.y) {
                error = "charts " + A.name + " and " + B.name + " overlap";
                return false;
            }
        }
    return true;
}

glm::vec2 uvAt(const TriMesh& mesh, const Atlas& atlas, const glm::vec3& p, int* chart) {
    // Closest point on any triangle (exact point-triangle distance, Ericson's method).
    double best = 1e30;
    glm::vec2 out(0);
    int outChart = -1;
    for (std::size_t t = 0; t < mesh.tris.size(); ++t) {
        const glm::dvec3 a(mesh.positions[mesh.tris[t][0]]), b(mesh.positions[mesh.tris[t][1]]),
            c(mesh.positions[mesh.tris[t][2]]);
        const glm::dvec3 q(p);
        // Barycentric of the projection, clamped by region.
        const glm::dvec3 ab = b - a, ac = c - a, ap = q - a;
        const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
        double u, v, w;
        const glm::dvec3 bp = q - b;
        const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
        const glm::dvec3 cp = q - c;
        const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
        const double vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
        if (d1 <= 0 && d2 <= 0) {
            u = 1;
            v = 0;
            w = 0;
        } else if (d3 >= 0 && d4 <= d3) {
            u = 0;
            v = 1;
            w = 0;
        } else if (vc <= 0 && d1 >= 0 && d3 <= 0) {
            v = d1 / (d1 - d3);
            u = 1 - v;
            w = 0;
        } else if (d6 >= 0 && d5 <= d6) {
            u = 0;
            v = 0;
            w = 1;
        } else if (vb <= 0 && d2 >= 0 && d6 <= 0) {
            w = d2 / (d2 - d6);
            u = 1 - w;
            v = 0;
        } else if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
            w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
            u = 0;
            v = 1 - w;
        } else {
            const double denom = 1.0 / (va + vb + vc);
            v = vb * denom;
            w = vc * denom;
            u = 1 - v - w;
        }
        const glm::dvec3 x = u * a + v * b + w * c;
        const double dist = glm::length(x - q);
        if (dist < best) {
            best = dist;
            const glm::vec2 ua = atlas.uvs[atlas.tris[t][0]], ub = atlas.uvs[atlas.tris[t][1]],
                            uc = atlas.uvs[atlas.tris[t][2]];
            out = static_cast<float>(u) * ua + static_cast<float>(v) * ub +
                  static_cast<float>(w) * uc;
            outChart = atlas.triChart[t];
        }
    }
    if (chart) *chart = outChart;
    return out;
}

} // namespace dermis::chargen
