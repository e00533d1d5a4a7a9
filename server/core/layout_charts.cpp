// Dermis core — the generated layout's charts (layout_gen_internal.hpp): a part welded by
// position with its inner edges, charts grown inside a normal cone, a chart as a local mesh with
// its topology, and the split of a chart in two.
#include "layout_gen_internal.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <numeric>
#include <queue>
#include <tuple>

namespace dermis::layout_detail {
namespace {

constexpr double kDegToRad = 3.14159265358979323846 / 180.0;

/// Bit pattern of a coordinate, −0 read as +0 (so welding is by value for every finite number).
std::uint32_t bitsOf(float f) {
    if (f == 0.0f) f = 0.0f;
    std::uint32_t b = 0;
    std::memcpy(&b, &f, sizeof b);
    return b;
}

glm::dvec3 centroid(const PartMesh& mesh, std::uint32_t t) {
    const glm::uvec3& tri = mesh.tris[t];
    return (mesh.positions[tri[0]] + mesh.positions[tri[1]] + mesh.positions[tri[2]]) / 3.0;
}

} // namespace

PartMesh buildPartMesh(const MeshPart& part, const LayoutGenOptions& options) {
    PartMesh mesh;
    const std::size_t nv = part.positions.size(), nt = part.indices.size() / 3;
    // Weld: sort vertices by their coordinates' bits; equal runs are one vertex, numbered in
    // order of first appearance so that the welded numbering follows the part's.
    std::vector<std::array<std::uint32_t, 3>> key(nv);
    for (std::size_t v = 0; v < nv; ++v)
        key[v] = {bitsOf(part.positions[v].x), bitsOf(part.positions[v].y),
                  bitsOf(part.positions[v].z)};
    std::vector<std::uint32_t> order(nv);
    std::iota(order.begin(), order.end(), 0u);
    std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
        return key[a] != key[b] ? key[a] < key[b] : a < b;
    });
    std::vector<std::uint32_t> rep(nv); // vertex → lowest-index vertex at its position
    for (std::size_t i = 0; i < nv;) {
        std::size_t j = i;
        while (j < nv && key[order[j]] == key[order[i]])
            rep[order[j++]] = order[i];
        i = j;
    }
    std::vector<std::int64_t> weldedOf(nv, -1);
    for (std::size_t v = 0; v < nv; ++v)
        if (rep[v] == v) {
            weldedOf[v] = static_cast<std::int64_t>(mesh.positions.size());
            mesh.positions.emplace_back(part.positions[v]);
        }
    mesh.tris.resize(nt);
    mesh.normals.assign(nt, glm::dvec3(0));
    mesh.areas.assign(nt, 0.0);
    mesh.degenerate.assign(nt, 0);
    for (std::size_t t = 0; t < nt; ++t) {
        glm::uvec3 tri;
        for (int c = 0; c < 3; ++c)
            tri[c] = static_cast<std::uint32_t>(
                weldedOf[rep[part.indices[3 * t + static_cast<std::size_t>(c)]]]);
        mesh.tris[t] = tri;
        const glm::dvec3 a = mesh.positions[tri[0]], b = mesh.positions[tri[1]],
                         c = mesh.positions[tri[2]];
        const glm::dvec3 n = glm::cross(b - a, c - a);
        const double twice = glm::length(n);
        const double longest =
            std::max({glm::dot(b - a, b - a), glm::dot(c - b, c - b), glm::dot(a - c, a - c)});
        mesh.areas[t] = std::isfinite(twice) ? 0.5 * twice : 0.0;
        if (tri[0] == tri[1] || tri[1] == tri[2] || tri[2] == tri[0] ||
            !(0.5 * twice > 1e-6 * longest) || !std::isfinite(twice)) {
            mesh.degenerate[t] = 1;
            continue;
        }
        mesh.normals[t] = n / twice;
    }

    // Edges: (low, high, triangle, corner) sorted; a run of exactly two with opposite directions
    // is an inner edge unless the model's UVs differ across it or it is a crease.
    struct EdgeRec {
        std::uint32_t lo, hi, t;
        int c;
    };
    std::vector<EdgeRec> edges;
    edges.reserve(nt * 3);
    for (std::size_t t = 0; t < nt; ++t) {
        if (mesh.degenerate[t]) continue;
        for (int c = 0; c < 3; ++c) {
            const std::uint32_t a = mesh.tris[t][c], b = mesh.tris[t][(c + 1) % 3];
            edges.push_back({std::min(a, b), std::max(a, b), static_cast<std::uint32_t>(t), c});
        }
    }
    std::sort(edges.begin(), edges.end(), [](const EdgeRec& x, const EdgeRec& y) {
        return std::tie(x.lo, x.hi, x.t, x.c) < std::tie(y.lo, y.hi, y.t, y.c);
    });
    mesh.adj.assign(nt, {-1, -1, -1});
    const bool hasUVs = part.uvs.size() >= nv;
    const double cosCrease = std::cos(options.creaseDegrees * kDegToRad);
    auto corner = [&](std::uint32_t t, int c) {
        return part
            .indices[3 * static_cast<std::size_t>(t) + static_cast<std::size_t>((c + 3) % 3)];
    };
    auto uvSolid = [&](std::uint32_t t) {
        const glm::dvec2 a(part.uvs[corner(t, 0)]), b(part.uvs[corner(t, 1)]),
            c(part.uvs[corner(t, 2)]);
        return (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y) != 0.0;
    };
    for (std::size_t i = 0; i < edges.size();) {
        std::size_t j = i;
        while (j < edges.size() && edges[j].lo == edges[i].lo && edges[j].hi == edges[i].hi)
            ++j;
        if (j - i == 2) {
            const EdgeRec &e1 = edges[i], &e2 = edges[i + 1];
            // e1 runs a→b at corners (c1, c1+1); an opposite e2 runs b→a at (c2, c2+1).
            const bool opposite = mesh.tris[e1.t][e1.c] == mesh.tris[e2.t][(e2.c + 1) % 3];
            bool inner = opposite && e1.t != e2.t;
            // A UV seam counts where both sides are unwrapped (non-zero UV area): a face whose
            // UVs collapse to a point or a line (a palette swatch) says nothing about seams.
            if (inner && hasUVs && uvSolid(e1.t) && uvSolid(e2.t))
                inner = part.uvs[corner(e1.t, e1.c)] == part.uvs[corner(e2.t, e2.c + 1)] &&
                        part.uvs[corner(e1.t, e1.c + 1)] == part.uvs[corner(e2.t, e2.c)];
            if (inner) inner = glm::dot(mesh.normals[e1.t], mesh.normals[e2.t]) >= cosCrease;
            if (inner) {
                mesh.adj[e1.t][static_cast<std::size_t>(e1.c)] = static_cast<int>(e2.t);
                mesh.adj[e2.t][static_cast<std::size_t>(e2.c)] = static_cast<int>(e1.t);
            }
        }
        i = j;
    }
    return mesh;
}

std::vector<std::vector<std::uint32_t>> growCharts(const PartMesh& mesh,
                                                   const LayoutGenOptions& options) {
    const std::size_t nt = mesh.tris.size();
    const double cosCone = std::cos(options.coneDegrees * kDegToRad);
    double total = 0;
    for (double a : mesh.areas)
        total += a;
    // The distance term: a chart of the whole part's size costs as much as 0.05 of normal
    // deviation (1 − cos), enough to grow flat regions outward rather than in index order.
    const double distScale = 0.05 / std::max(std::sqrt(total), 1e-30);
    std::vector<int> label(nt, -1);
    std::vector<std::vector<std::uint32_t>> charts;
    using Item = std::pair<double, std::uint32_t>;
    for (std::size_t seed = 0; seed < nt; ++seed) {
        if (mesh.degenerate[seed] || label[seed] >= 0) continue;
        const int id = static_cast<int>(charts.size());
        charts.emplace_back();
        const glm::dvec3 seedN = mesh.normals[seed];
        const glm::dvec3 seedC = centroid(mesh, static_cast<std::uint32_t>(seed));
        glm::dvec3 sum(0);
        std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
        queue.push({0.0, static_cast<std::uint32_t>(seed)});
        while (!queue.empty()) {
            const std::uint32_t t = queue.top().second;
            queue.pop();
            if (label[t] >= 0) continue;
            const glm::dvec3 n = mesh.normals[t];
            const double sl = glm::length(sum);
            if (glm::dot(n, seedN) < cosCone || (sl > 0 && glm::dot(n, sum / sl) < cosCone))
                continue;
            label[t] = id;
            charts.back().push_back(t);
            sum += n * mesh.areas[t];
            const glm::dvec3 mean = glm::normalize(sum);
            for (int c = 0; c < 3; ++c) {
                const int o = mesh.adj[t][static_cast<std::size_t>(c)];
                if (o < 0 || label[static_cast<std::size_t>(o)] >= 0) continue;
                const auto ou = static_cast<std::uint32_t>(o);
                const double cost = (1.0 - glm::dot(mesh.normals[ou], mean)) +
                                    distScale * glm::length(centroid(mesh, ou) - seedC);
                queue.push({cost, ou});
            }
        }
    }
    const std::size_t nc = charts.size();
    std::vector<glm::dvec3> sums(nc, glm::dvec3(0));
    std::vector<double> areas(nc, 0.0);
    for (std::size_t t = 0; t < nt; ++t)
        if (label[t] >= 0) {
            sums[static_cast<std::size_t>(label[t])] += mesh.normals[t] * mesh.areas[t];
            areas[static_cast<std::size_t>(label[t])] += mesh.areas[t];
        }
    auto fits = [&](std::size_t t, std::size_t c) {
        const double l = glm::length(sums[c]);
        return l > 0 && glm::dot(mesh.normals[t], sums[c] / l) >= cosCone;
    };
    // Smoother borders: a triangle with two inner-edge neighbours in one other chart joins it
    // when it fits that chart's cone (it has at most one neighbour left in its own chart, so
    // that chart stays connected).
    for (int pass = 0; pass < 8; ++pass) {
        bool changed = false;
        for (std::size_t t = 0; t < nt; ++t) {
            if (label[t] < 0) continue;
            int other = -1;
            for (int c = 0; c < 3 && other < 0; ++c) {
                const int o = mesh.adj[t][static_cast<std::size_t>(c)];
                if (o < 0 || label[static_cast<std::size_t>(o)] == label[t]) continue;
                const int lo = label[static_cast<std::size_t>(o)];
                int same = 0;
                for (int d = 0; d < 3; ++d) {
                    const int q = mesh.adj[t][static_cast<std::size_t>(d)];
                    same += q >= 0 && label[static_cast<std::size_t>(q)] == lo;
                }
                if (same >= 2) other = lo;
            }
            if (other < 0 || !fits(t, static_cast<std::size_t>(other))) continue;
            const auto from = static_cast<std::size_t>(label[t]),
                       to = static_cast<std::size_t>(other);
            sums[from] -= mesh.normals[t] * mesh.areas[t];
            areas[from] -= mesh.areas[t];
            sums[to] += mesh.normals[t] * mesh.areas[t];
            areas[to] += mesh.areas[t];
            label[t] = other;
            changed = true;
        }
        if (!changed) break;
    }
    // Small charts (under a tenth of the mean chart area) join the neighbour they share most
    // inner edges with, smallest first, when every triangle fits that neighbour's cone.
    std::vector<std::vector<std::uint32_t>> members(nc);
    for (std::size_t t = 0; t < nt; ++t)
        if (label[t] >= 0)
            members[static_cast<std::size_t>(label[t])].push_back(static_cast<std::uint32_t>(t));
    double partArea = 0;
    std::size_t live = 0;
    for (std::size_t c = 0; c < nc; ++c)
        if (!members[c].empty()) {
            partArea += areas[c];
            ++live;
        }
    const double small = live > 0 ? 0.1 * partArea / static_cast<double>(live) : 0.0;
    std::vector<std::size_t> bySize;
    for (std::size_t c = 0; c < nc; ++c)
        if (!members[c].empty() && areas[c] < small) bySize.push_back(c);
    std::stable_sort(bySize.begin(), bySize.end(),
                     [&](std::size_t a, std::size_t b) { return areas[a] < areas[b]; });
    for (std::size_t c : bySize) {
        std::vector<std::pair<int, int>> shared; // (chart, edges)
        for (std::uint32_t t : members[c])
            for (int e = 0; e < 3; ++e) {
                const int o = mesh.adj[t][static_cast<std::size_t>(e)];
                if (o < 0 || label[static_cast<std::size_t>(o)] == static_cast<int>(c)) continue;
                const int lo = label[static_cast<std::size_t>(o)];
                auto it = std::find_if(shared.begin(), shared.end(),
                                       [&](const auto& x) { return x.first == lo; });
                if (it == shared.end())
                    shared.push_back({lo, 1});
                else
                    ++it->second;
            }
        std::stable_sort(shared.begin(), shared.end(),
                         [](const auto& a, const auto& b) { return a.second > b.second; });
        for (const auto& [target, edgesShared] : shared) {
            (void)edgesShared;
            const auto to = static_cast<std::size_t>(target);
            bool all = true;
            for (std::uint32_t t : members[c])
                all = all && fits(t, to);
            if (!all) continue;
            for (std::uint32_t t : members[c]) {
                label[t] = target;
                members[to].push_back(t);
            }
            sums[to] += sums[c];
            areas[to] += areas[c];
            members[c].clear();
            break;
        }
    }
    // Charts in order of their first triangle, each sorted.
    std::vector<std::vector<std::uint32_t>> out;
    std::vector<int> renumber(nc, -1);
    for (std::size_t t = 0; t < nt; ++t) {
        if (label[t] < 0) continue;
        int& r = renumber[static_cast<std::size_t>(label[t])];
        if (r < 0) {
            r = static_cast<int>(out.size());
            out.emplace_back();
        }
        out[static_cast<std::size_t>(r)].push_back(static_cast<std::uint32_t>(t));
    }
    return out;
}

LocalChart buildLocalChart(const PartMesh& mesh, std::vector<std::uint32_t> tris,
                           std::vector<int>& member) {
    LocalChart lc;
    lc.tris = std::move(tris);
    const std::size_t n = lc.tris.size();
    for (std::size_t i = 0; i < n; ++i)
        member[lc.tris[i]] = static_cast<int>(i);
    std::vector<std::uint32_t> parent(3 * n);
    std::iota(parent.begin(), parent.end(), 0u);
    auto find = [&](std::uint32_t x) {
        while (parent[x] != x)
            x = parent[x] = parent[parent[x]];
        return x;
    };
    auto unite = [&](std::uint32_t a, std::uint32_t b) {
        a = find(a);
        b = find(b);
        if (a != b) parent[std::max(a, b)] = std::min(a, b);
    };
    std::size_t innerHalfEdges = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const std::uint32_t t = lc.tris[i];
        for (int c = 0; c < 3; ++c) {
            const int o = mesh.adj[t][static_cast<std::size_t>(c)];
            if (o < 0 || member[static_cast<std::size_t>(o)] < 0) continue;
            ++innerHalfEdges;
            const std::uint32_t a = mesh.tris[t][c];
            const auto& ot = mesh.tris[static_cast<std::size_t>(o)];
            const auto oi = static_cast<std::uint32_t>(member[static_cast<std::size_t>(o)]);
            for (std::uint32_t oc = 0; oc < 3; ++oc)
                if (ot[static_cast<int>(oc)] == a) {
                    // o runs b→a: a is at oc, b at oc − 1.
                    unite(static_cast<std::uint32_t>(3 * i) + static_cast<std::uint32_t>(c),
                          3 * oi + oc);
                    unite(static_cast<std::uint32_t>(3 * i) +
                              static_cast<std::uint32_t>((c + 1) % 3),
                          3 * oi + (oc + 2) % 3);
                }
        }
    }
    std::vector<std::int64_t> idOf(3 * n, -1);
    lc.local.resize(n);
    for (std::size_t i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c) {
            const std::uint32_t r =
                find(static_cast<std::uint32_t>(3 * i) + static_cast<std::uint32_t>(c));
            if (idOf[r] < 0) {
                idOf[r] = static_cast<std::int64_t>(lc.welded.size());
                lc.welded.push_back(mesh.tris[lc.tris[i]][c]);
            }
            lc.local[i][c] = static_cast<std::uint32_t>(idOf[r]);
        }
    for (std::size_t i = 0; i < n; ++i) {
        const std::uint32_t t = lc.tris[i];
        for (int c = 0; c < 3; ++c) {
            const int o = mesh.adj[t][static_cast<std::size_t>(c)];
            if (o >= 0 && member[static_cast<std::size_t>(o)] >= 0) continue;
            lc.boundary.push_back({lc.local[i][c], lc.local[i][(c + 1) % 3]});
        }
    }
    for (std::uint32_t t : lc.tris)
        member[t] = -1;
    // Loops: each local vertex has at most one outgoing boundary edge (its corners form one
    // edge-connected fan).
    std::vector<std::int64_t> next(lc.welded.size(), -1);
    bool manifold = true;
    for (const auto& e : lc.boundary) {
        if (next[e[0]] >= 0) manifold = false;
        next[e[0]] = e[1];
    }
    std::vector<char> seen(lc.welded.size(), 0);
    for (const auto& e : lc.boundary) {
        if (seen[e[0]]) continue;
        ++lc.loops;
        std::int64_t v = e[0];
        while (v >= 0 && !seen[static_cast<std::size_t>(v)]) {
            seen[static_cast<std::size_t>(v)] = 1;
            v = next[static_cast<std::size_t>(v)];
        }
        if (v < 0) manifold = false;
    }
    lc.euler = static_cast<int>(lc.welded.size()) -
               static_cast<int>(innerHalfEdges / 2 + lc.boundary.size()) + static_cast<int>(n);
    if (!manifold) lc.loops = 0; // not a surface with boundary: isDiskLike() is false
    return lc;
}

std::array<std::vector<std::uint32_t>, 2>
splitChart(const PartMesh& mesh, const std::vector<std::uint32_t>& tris, std::vector<int>& member) {
    std::array<std::vector<std::uint32_t>, 2> halves;
    auto finish = [&]() {
        for (std::uint32_t t : tris)
            member[t] = -1;
        for (auto& h : halves)
            std::sort(h.begin(), h.end());
        return halves;
    };
    // Not edge-connected: the piece holding the first triangle, and the rest.
    for (std::uint32_t t : tris)
        member[t] = -2; // in the set, not yet reached
    std::vector<std::uint32_t> stack{tris[0]};
    member[tris[0]] = 0;
    std::size_t reached = 0;
    while (!stack.empty()) {
        const std::uint32_t t = stack.back();
        stack.pop_back();
        ++reached;
        for (int c = 0; c < 3; ++c) {
            const int o = mesh.adj[t][static_cast<std::size_t>(c)];
            if (o < 0 || member[static_cast<std::size_t>(o)] != -2) continue;
            member[static_cast<std::size_t>(o)] = 0;
            stack.push_back(static_cast<std::uint32_t>(o));
        }
    }
    if (reached < tris.size()) {
        for (std::uint32_t t : tris)
            halves[member[t] == 0 ? 0 : 1].push_back(t);
        return finish();
    }

    glm::dvec3 mid(0);
    for (std::uint32_t t : tris)
        mid += centroid(mesh, t);
    mid /= static_cast<double>(tris.size());
    auto farthest = [&](const glm::dvec3& from) {
        std::uint32_t best = tris[0];
        double bestD = -1;
        for (std::uint32_t t : tris) {
            const double d = glm::length(centroid(mesh, t) - from);
            if (d > bestD) bestD = d, best = t;
        }
        return best;
    };
    const std::uint32_t a = farthest(mid);
    std::uint32_t b = farthest(centroid(mesh, a));
    if (b == a) b = tris[0] == a ? tris[1] : tris[0];
    for (std::uint32_t t : tris)
        member[t] = -2; // in the chart, not yet claimed
    // Two-source Dijkstra over inner edges (centroid distances): each triangle joins the seed it
    // is nearer to, so both halves are edge-connected.
    using Item = std::tuple<double, std::uint32_t, int>;
    std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
    queue.push({0.0, a, 0});
    queue.push({0.0, b, 1});
    while (!queue.empty()) {
        const auto [d, t, side] = queue.top();
        queue.pop();
        if (member[t] != -2) continue;
        member[t] = side;
        halves[static_cast<std::size_t>(side)].push_back(t);
        const glm::dvec3 ct = centroid(mesh, t);
        for (int c = 0; c < 3; ++c) {
            const int o = mesh.adj[t][static_cast<std::size_t>(c)];
            if (o < 0 || member[static_cast<std::size_t>(o)] != -2) continue;
            const auto ou = static_cast<std::uint32_t>(o);
            queue.push({d + glm::length(centroid(mesh, ou) - ct), ou, side});
        }
    }
    if (halves[0].empty() || halves[1].empty()) { // coincident centroids: peel one triangle
        halves = {std::vector<std::uint32_t>{tris[0]},
                  std::vector<std::uint32_t>(tris.begin() + 1, tris.end())};
    }
    return finish();
}

} // namespace dermis::layout_detail
