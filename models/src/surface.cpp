// Implicit body → closed triangle mesh (see surface.hpp).
#include "surface.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <numeric>
#include <queue>
#include <thread>
#include <unordered_map>

namespace dermis::chargen {
namespace {

float triQuality(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
    // 4·√3·area / (sum of squared edge lengths): 1 for an equilateral triangle, 0 if degenerate.
    const float area2 = glm::length(glm::cross(b - a, c - a));
    const float s = glm::dot(b - a, b - a) + glm::dot(c - b, c - b) + glm::dot(a - c, a - c);
    return s > 0 ? 2.0f * std::sqrt(3.0f) * area2 / s : 0.0f;
}

glm::vec3 triNormal(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
    return glm::cross(b - a, c - a);
}

/// Mutable triangle mesh with vertex → triangle lists, for local edits.
struct EditMesh {
    std::vector<glm::vec3>& P;
    std::vector<glm::uvec3>& T;
    std::vector<char> alive;
    std::vector<std::vector<std::uint32_t>> vt;
    std::size_t aliveCount = 0;

    EditMesh(std::vector<glm::vec3>& p, std::vector<glm::uvec3>& t) : P(p), T(t) {
        alive.assign(T.size(), 1);
        aliveCount = T.size();
        vt.assign(P.size(), {});
        for (std::uint32_t i = 0; i < T.size(); ++i)
            for (int c = 0; c < 3; ++c)
                vt[T[i][c]].push_back(i);
    }

    void prune(std::uint32_t v) {
        auto& l = vt[v];
        l.erase(std::remove_if(l.begin(), l.end(), [&](std::uint32_t t) { return !alive[t]; }),
                l.end());
    }

    /// Sorted one-ring neighbours of v.
    void neighbours(std::uint32_t v, std::vector<std::uint32_t>& out) const {
        out.clear();
        for (std::uint32_t t : vt[v]) {
            if (!alive[t]) continue;
            for (int c = 0; c < 3; ++c)
                if (T[t][c] != v) out.push_back(T[t][c]);
        }
        std::sort(out.begin(), out.end());
        out.erase(std::unique(out.begin(), out.end()), out.end());
    }

    /// Alive triangles containing both u and v.
    void edgeTris(std::uint32_t u, std::uint32_t v, std::vector<std::uint32_t>& out) const {
        out.clear();
        for (std::uint32_t t : vt[u])
            if (alive[t] && (T[t][0] == v || T[t][1] == v || T[t][2] == v)) out.push_back(t);
    }

    static std::uint32_t third(const glm::uvec3& t, std::uint32_t a, std::uint32_t b) {
        for (int c = 0; c < 3; ++c)
            if (t[c] != a && t[c] != b) return t[c];
        return t[0];
    }

    /// Removes dead triangles and unused vertices.
    void compact() {
        std::vector<std::uint32_t> remap(P.size(), UINT32_MAX);
        std::vector<glm::vec3> np;
        std::vector<glm::uvec3> nt;
        for (std::size_t t = 0; t < T.size(); ++t) {
            if (!alive[t]) continue;
            glm::uvec3 tri;
            for (int c = 0; c < 3; ++c) {
                std::uint32_t& r = remap[T[t][c]];
                if (r == UINT32_MAX) {
                    r = static_cast<std::uint32_t>(np.size());
                    np.push_back(P[T[t][c]]);
                }
                tri[c] = r;
            }
            nt.push_back(tri);
        }
        P = std::move(np);
        T = std::move(nt);
    }
};

} // namespace

TriMesh polygonize(const Body& body, float cell) {
    const glm::vec3 lo = body.boundsMin(), hi = body.boundsMax();
    const int nx = static_cast<int>(std::ceil((hi.x - lo.x) / cell)) + 1;
    const int ny = static_cast<int>(std::ceil((hi.y - lo.y) / cell)) + 1;
    const int nz = static_cast<int>(std::ceil((hi.z - lo.z) / cell)) + 1;
    auto idx = [&](int i, int j, int k) {
        return static_cast<std::size_t>(i) +
               static_cast<std::size_t>(nx) *
                   (static_cast<std::size_t>(j) +
                    static_cast<std::size_t>(ny) * static_cast<std::size_t>(k));
    };
    auto point = [&](int i, int j, int k) {
        return lo + glm::vec3(static_cast<float>(i), static_cast<float>(j), static_cast<float>(k)) *
                        cell;
    };
    const float nan = std::numeric_limits<float>::quiet_NaN();
    std::vector<float> f(static_cast<std::size_t>(nx) * ny * nz, nan);

    // Sparse evaluation: blocks of B³ cells far from the surface only record their sign.
    constexpr int B = 4;
    const int bx = (nx - 1 + B - 1) / B, by = (ny - 1 + B - 1) / B, bz = (nz - 1 + B - 1) / B;
    std::vector<float> blockValue(static_cast<std::size_t>(bx) * by * bz);
    const float blockRadius = 0.5f * std::sqrt(3.0f) * B * cell;
    auto work = [&](int k0, int k1) {
        for (int bk = k0; bk < k1; ++bk)
            for (int bj = 0; bj < by; ++bj)
                for (int bi = 0; bi < bx; ++bi) {
                    const glm::vec3 c = lo + (glm::vec3(bi, bj, bk) + 0.5f) * (B * cell);
                    const float fc = body.sdf(c);
                    blockValue[static_cast<std::size_t>(bi) +
                               static_cast<std::size_t>(bx) *
                                   (bj + static_cast<std::size_t>(by) * bk)] = fc;
                    if (std::abs(fc) > 1.5f * blockRadius + 2.0f * cell) continue;
                    for (int k = bk * B; k <= std::min(bk * B + B, nz - 1); ++k)
                        for (int j = bj * B; j <= std::min(bj * B + B, ny - 1); ++j)
                            for (int i = bi * B; i <= std::min(bi * B + B, nx - 1); ++i) {
                                // Points on a block face are shared; every writer computes the
                                // same value, so the race-free rule is: the owner block writes.
                                const bool own = (k < bk * B + B || k == nz - 1) &&
                                                 (j < bj * B + B || j == ny - 1) &&
                                                 (i < bi * B + B || i == nx - 1);
                                if (!own) continue;
                                f[idx(i, j, k)] = body.sdf(point(i, j, k));
                            }
                }
    };
    {
        // Two threads over disjoint block slabs; the values do not depend on the split.
        const int mid = bz / 2;
        std::thread th(work, 0, mid);
        work(mid, bz);
        th.join();
    }
    // Points of near blocks owned by far blocks (block faces): evaluate them now.
    for (int bk = 0; bk < bz; ++bk)
        for (int bj = 0; bj < by; ++bj)
            for (int bi = 0; bi < bx; ++bi) {
                const float fc = blockValue[static_cast<std::size_t>(bi) +
                                            static_cast<std::size_t>(bx) *
                                                (bj + static_cast<std::size_t>(by) * bk)];
                if (std::abs(fc) > 1.5f * blockRadius + 2.0f * cell) continue;
                for (int k = bk * B; k <= std::min(bk * B + B, nz - 1); ++k)
                    for (int j = bj * B; j <= std::min(bj * B + B, ny - 1); ++j)
                        for (int i = bi * B; i <= std::min(bi * B + B, nx - 1); ++i)
                            if (std::isnan(f[idx(i, j, k)]))
                                f[idx(i, j, k)] = body.sdf(point(i, j, k));
            }
    // Far points take their block's sign (no surface inside a far block).
    for (int k = 0; k < nz; ++k)
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i) {
                float& v = f[idx(i, j, k)];
                if (!std::isnan(v)) continue;
                const int bi = std::min(i / B, bx - 1), bj = std::min(j / B, by - 1),
                          bk = std::min(k / B, bz - 1);
                v = blockValue[static_cast<std::size_t>(bi) +
                               static_cast<std::size_t>(bx) *
                                   (bj + static_cast<std::size_t>(by) * bk)] > 0
                        ? 1.0f
                        : -1.0f;
            }

    // Marching tetrahedra: 6 tetrahedra per cube around the diagonal 0 → 7 (Kuhn split).
    static const int kTets[6][4] = {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7},
                                    {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}};
    TriMesh mesh;
    std::unordered_map<std::uint64_t, std::uint32_t> edgeVertex;
    edgeVertex.reserve(1 << 20);
    const std::uint64_t N = f.size();
    auto vertexOn = [&](std::size_t g0, std::size_t g1, const glm::vec3& p0, const glm::vec3& p1) {
        if (g0 > g1) return 0u; // never called that way
        const std::uint64_t key = static_cast<std::uint64_t>(g0) * N + g1;
        auto it = edgeVertex.find(key);
        if (it != edgeVertex.end()) return it->second;
        const float f0 = f[g0], f1 = f[g1];
        const float t = std::clamp(f0 / (f0 - f1), 0.0f, 1.0f);
        const auto id = static_cast<std::uint32_t>(mesh.positions.size());
        mesh.positions.push_back(p0 + (p1 - p0) * t);
        edgeVertex.emplace(key, id);
        return id;
    };
    for (int k = 0; k + 1 < nz; ++k)
        for (int j = 0; j + 1 < ny; ++j)
            for (int i = 0; i + 1 < nx; ++i) {
                std::size_t g[8];
                int inside = 0;
                for (int c = 0; c < 8; ++c) {
                    g[c] = idx(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1));
                    inside += f[g[c]] < 0.0f ? 1 : 0;
                }
                if (inside == 0 || inside == 8) continue;
                for (const auto& tet : kTets) {
                    std::size_t gi[4];
                    glm::vec3 pi[4];
                    int in[4], nin = 0, out[4], nout = 0;
                    for (int c = 0; c < 4; ++c) {
                        const int corner = tet[c];
                        gi[c] = g[corner];
                        pi[c] = point(i + (corner & 1), j + ((corner >> 1) & 1),
                                      k + ((corner >> 2) & 1));
                        if (f[gi[c]] < 0.0f)
                            in[nin++] = c;
                        else
                            out[nout++] = c;
                    }
                    if (nin == 0 || nin == 4) continue;
                    auto ev = [&](int a, int b) {
                        return gi[a] < gi[b] ? vertexOn(gi[a], gi[b], pi[a], pi[b])
                                             : vertexOn(gi[b], gi[a], pi[b], pi[a]);
                    };
                    // Orientation from the tetrahedron, not from the (possibly degenerate)
                    // triangle: for a positively oriented tetrahedron (L, o0, o1, o2) the
                    // triangle on edges (L-o0, L-o1, L-o2) faces away from L.
                    auto orient = [&](int a, int b, int c, int d) {
                        return glm::dot(glm::cross(pi[b] - pi[a], pi[c] - pi[a]), pi[d] - pi[a]) >
                               0.0f;
                    };
                    if (nin == 1 || nin == 3) {
                        const int lone = nin == 1 ? in[0] : out[0];
                        int o[3];
                        for (int c = 0, n = 0; c < 4; ++c)
                            if (c != lone) o[n++] = c;
                        if (!orient(lone, o[0], o[1], o[2])) std::swap(o[1], o[2]);
                        if (nin == 3) std::swap(o[1], o[2]); // face toward the outside vertex
                        mesh.tris.emplace_back(ev(lone, o[0]), ev(lone, o[1]), ev(lone, o[2]));
                    } else {
                        int a = in[0], b = in[1], c = out[0], d = out[1];
                        if (!orient(a, b, c, d)) std::swap(c, d);
                        const std::uint32_t ac = ev(a, c), ad = ev(a, d), bd = ev(b, d),
                                            bc = ev(b, c);
                        mesh.tris.emplace_back(ac, ad, bd);
                        mesh.tris.emplace_back(ac, bd, bc);
                    }
                }
            }

    // Keep the largest connected component (by triangles).
    std::vector<std::uint32_t> parent(mesh.positions.size());
    std::iota(parent.begin(), parent.end(), 0u);
    auto find = [&](std::uint32_t x) {
        while (parent[x] != x)
            x = parent[x] = parent[parent[x]];
        return x;
    };
    for (const auto& t : mesh.tris) {
        parent[find(t[1])] = find(t[0]);
        parent[find(t[2])] = find(t[0]);
    }
    std::vector<std::uint32_t> count(mesh.positions.size(), 0);
    for (const auto& t : mesh.tris)
        ++count[find(t[0])];
    const auto best =
        static_cast<std::uint32_t>(std::max_element(count.begin(), count.end()) - count.begin());
    std::vector<glm::vec3> P = mesh.positions;
    std::vector<glm::uvec3> T;
    for (const auto& t : mesh.tris)
        if (find(t[0]) == best) T.push_back(t);
    EditMesh em(P, T);
    em.compact();
    return TriMesh{std::move(P), std::move(T)};
}

namespace {

/// Edge collapse and split with the checks that keep a closed 2-manifold without folds.
struct Editor {
    TriMesh& mesh;
    const Body& body;
    EditMesh em;
    std::vector<float> size;        ///< sizing per vertex
    std::vector<std::uint32_t> ver; ///< bumped when a vertex moves or dies
    std::vector<std::uint32_t> nu, nv, et, common, nc;

    Editor(TriMesh& m, const Body& b) : mesh(m), body(b), em(m.positions, m.tris) {
        size.resize(m.positions.size());
        for (std::size_t v = 0; v < size.size(); ++v)
            size[v] = body.sizing(m.positions[v]);
        ver.assign(m.positions.size(), 0);
    }

    float relLength(std::uint32_t u, std::uint32_t v) const {
        return glm::length(mesh.positions[u] - mesh.positions[v]) / (0.5f * (size[u] + size[v]));
    }

    /// Collapses edge (u, v) into u at the edge midpoint (projected on the body when
    /// `project`). Returns false, changing nothing, when the collapse is not allowed.
    bool collapse(std::uint32_t u, std::uint32_t v, bool project) {
        em.edgeTris(u, v, et);
        if (et.size() != 2) return false;
        const std::uint32_t c = EditMesh::third(mesh.tris[et[0]], u, v);
        const std::uint32_t d = EditMesh::third(mesh.tris[et[1]], u, v);
        if (c == d) return false;
        em.neighbours(u, nu);
        em.neighbours(v, nv);
        common.clear();
        std::set_intersection(nu.begin(), nu.end(), nv.begin(), nv.end(),
                              std::back_inserter(common));
        if (common.size() != 2) return false; // link condition
        em.neighbours(c, nc);
        if (nc.size() <= 3) return false;
        em.neighbours(d, nc);
        if (nc.size() <= 3) return false;
        if (nu.size() + nv.size() - 4 > 11) return false; // valence of the merged vertex

        // Reference normal: area-weighted normal of the two fans.
        glm::vec3 ref(0);
        for (std::uint32_t w : {u, v})
            for (std::uint32_t t : em.vt[w])
                if (em.alive[t])
                    ref +=
                        triNormal(mesh.positions[mesh.tris[t][0]], mesh.positions[mesh.tris[t][1]],
                                  mesh.positions[mesh.tris[t][2]]);
        if (glm::dot(ref, ref) < 1e-20f) return false;
        ref = glm::normalize(ref);
        const glm::vec3 mid = 0.5f * (mesh.positions[u] + mesh.positions[v]);
        const glm::vec3 p = project ? body.project(mid, 2) : mid;
        float worstOld = 1.0f, worstNew = 1.0f;
        for (std::uint32_t w : {u, v}) {
            for (std::uint32_t t : em.vt[w]) {
                if (!em.alive[t]) continue;
                glm::vec3 q[3], o[3];
                for (int k = 0; k < 3; ++k) {
                    o[k] = mesh.positions[mesh.tris[t][k]];
                    q[k] = (mesh.tris[t][k] == u || mesh.tris[t][k] == v) ? p : o[k];
                }
                worstOld = std::min(worstOld, triQuality(o[0], o[1], o[2]));
                if (t == et[0] || t == et[1]) continue;
                const glm::vec3 nn = triNormal(q[0], q[1], q[2]);
                const float ln = glm::length(nn);
                if (ln < 1e-14f || glm::dot(nn, ref) < 0.3f * ln) return false;
                const glm::vec3 no = triNormal(o[0], o[1], o[2]);
                const float lo = glm::length(no);
                if (lo > 1e-14f && glm::dot(nn, no) < 0.3f * ln * lo) return false;
                worstNew = std::min(worstNew, triQuality(q[0], q[1], q[2]));
            }
        }
        if (worstNew < 0.15f && worstNew < 0.7f * worstOld) return false;

        mesh.positions[u] = p;
        size[u] = std::min(size[u], size[v]);
        em.alive[et[0]] = em.alive[et[1]] = 0;
        em.aliveCount -= 2;
        for (std::uint32_t t : em.vt[v]) {
            if (!em.alive[t]) continue;
            for (int k = 0; k < 3; ++k)
                if (mesh.tris[t][k] == v) mesh.tris[t][k] = u;
            em.vt[u].push_back(t);
        }
        em.vt[v].clear();
        em.prune(u);
        em.prune(c);
        em.prune(d);
        ++ver[u];
        ++ver[v];
        return true;
    }

    /// Splits edge (a, b) at its midpoint projected on the body. Returns false when the edge is
    /// not an interior manifold edge.
    bool split(std::uint32_t a, std::uint32_t b) {
        em.edgeTris(a, b, et);
        if (et.size() != 2) return false;
        std::uint32_t t1 = et[0], t2 = et[1];
        auto directed = [&](std::uint32_t tri, std::uint32_t x, std::uint32_t y) {
            for (int k = 0; k < 3; ++k)
                if (mesh.tris[tri][k] == x && mesh.tris[tri][(k + 1) % 3] == y) return true;
            return false;
        };
        if (!directed(t1, a, b)) std::swap(t1, t2);
        if (!directed(t1, a, b) || !directed(t2, b, a)) return false;
        const std::uint32_t c = EditMesh::third(mesh.tris[t1], a, b);
        const std::uint32_t d = EditMesh::third(mesh.tris[t2], a, b);
        const glm::vec3 p = body.project(0.5f * (mesh.positions[a] + mesh.positions[b]), 3);
        const auto m = static_cast<std::uint32_t>(mesh.positions.size());
        mesh.positions.push_back(p);
        size.push_back(0.5f * (size[a] + size[b]));
        ver.push_back(0);
        const auto t3 = static_cast<std::uint32_t>(mesh.tris.size());
        const std::uint32_t t4 = t3 + 1;
        mesh.tris[t1] = glm::uvec3(a, m, c);
        mesh.tris.emplace_back(m, b, c);
        mesh.tris[t2] = glm::uvec3(b, m, d);
        mesh.tris.emplace_back(m, a, d);
        em.alive.push_back(1);
        em.alive.push_back(1);
        em.aliveCount += 2;
        em.vt.push_back({t1, t2, t3, t4});
        auto drop = [&](std::uint32_t v, std::uint32_t tri) {
            auto& l = em.vt[v];
            l.erase(std::remove(l.begin(), l.end(), tri), l.end());
        };
        drop(b, t1);
        em.vt[b].push_back(t3);
        drop(a, t2);
        em.vt[a].push_back(t4);
        em.vt[c].push_back(t3);
        em.vt[d].push_back(t4);
        ++ver[a];
        ++ver[b];
        return true;
    }
};

struct Entry {
    float cost;
    std::uint32_t u, v, vu, vv;
    bool operator>(const Entry& o) const {
        if (cost != o.cost) return cost > o.cost;
        if (u != o.u) return u > o.u;
        return v > o.v;
    }
};
using MinHeap = std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>>;
using MaxHeap = std::priority_queue<Entry, std::vector<Entry>, std::less<Entry>>;
bool operator<(const Entry& a, const Entry& b) {
    return b > a;
}

/// Collapses shortest relative edges first until `targetTris` triangles remain or no edge
/// shorter than `maxRel` can be collapsed. `projectAbove`: relative length from which the new
/// vertex is projected on the body (shorter edges use the plain midpoint).
void collapseRound(TriMesh& mesh, const Body& body, std::size_t targetTris, float maxRel,
                   float projectAbove) {
    Editor ed(mesh, body);
    MinHeap heap;
    auto push = [&](std::uint32_t u, std::uint32_t v) {
        if (u > v) std::swap(u, v);
        const float r = ed.relLength(u, v);
        if (r < maxRel) heap.push({r, u, v, ed.ver[u], ed.ver[v]});
    };
    for (const auto& t : mesh.tris)
        for (int c = 0; c < 3; ++c)
            if (t[c] < t[(c + 1) % 3]) push(t[c], t[(c + 1) % 3]);
    std::vector<std::uint32_t> ring;
    while (ed.em.aliveCount > targetTris && !heap.empty()) {
        const Entry e = heap.top();
        heap.pop();
        if (e.vu != ed.ver[e.u] || e.vv != ed.ver[e.v]) continue;
        if (!ed.collapse(e.u, e.v, e.cost > projectAbove)) continue;
        ed.em.neighbours(e.u, ring);
        for (std::uint32_t w : ring)
            push(e.u, w);
    }
    ed.em.compact();
}

/// Splits longest relative edges first while the mesh has fewer than `targetTris` triangles
/// and edges longer than `minRel` remain.
void splitRound(TriMesh& mesh, const Body& body, std::size_t targetTris, float minRel) {
    Editor ed(mesh, body);
    MaxHeap heap;
    auto push = [&](std::uint32_t u, std::uint32_t v) {
        if (u > v) std::swap(u, v);
        const float r = ed.relLength(u, v);
        if (r > minRel) heap.push({r, u, v, ed.ver[u], ed.ver[v]});
    };
    for (const auto& t : mesh.tris)
        for (int c = 0; c < 3; ++c)
            if (t[c] < t[(c + 1) % 3]) push(t[c], t[(c + 1) % 3]);
    std::vector<std::uint32_t> ring;
    while (ed.em.aliveCount < targetTris && !heap.empty()) {
        const Entry e = heap.top();
        heap.pop();
        if (e.vu != ed.ver[e.u] || e.vv != ed.ver[e.v]) continue;
        if (!ed.split(e.u, e.v)) continue;
        const auto m = static_cast<std::uint32_t>(mesh.positions.size() - 1);
        for (std::uint32_t w : {e.u, e.v}) {
            ed.em.neighbours(w, ring);
            for (std::uint32_t x : ring)
                push(w, x);
        }
        ed.em.neighbours(m, ring);
        for (std::uint32_t x : ring)
            push(m, x);
    }
    ed.em.compact();
}

/// Mean relative edge length.
float meanRel(const TriMesh& mesh, const Body& body) {
    std::vector<float> size(mesh.positions.size());
    for (std::size_t v = 0; v < size.size(); ++v)
        size[v] = body.sizing(mesh.positions[v]);
    double sum = 0;
    std::size_t n = 0;
    for (const auto& t : mesh.tris)
        for (int c = 0; c < 3; ++c) {
            const std::uint32_t a = t[c], b = t[(c + 1) % 3];
            sum +=
                glm::length(mesh.positions[a] - mesh.positions[b]) / (0.5f * (size[a] + size[b]));
            ++n;
        }
    return n ? static_cast<float>(sum / static_cast<double>(n)) : 0.0f;
}

} // namespace

void decimate(TriMesh& mesh, const Body& body, std::size_t targetTris) {
    // Coarsening: collapse rounds alternate with flips and relaxation, which repair the slivers
    // and high valences that block further collapses.
    for (int stall = 0; mesh.tris.size() > targetTris && stall < 3;) {
        const std::size_t before = mesh.tris.size();
        const float scale =
            std::sqrt(static_cast<float>(mesh.tris.size()) / static_cast<float>(targetTris));
        collapseRound(mesh, body, targetTris, 1e9f, 0.35f / scale);
        if (mesh.tris.size() <= targetTris) break;
        stall = mesh.tris.size() < before ? 0 : stall + 1;
        optimize(mesh, body, 1);
    }
    // Balancing: split the longest and collapse the shortest relative edges (isotropic
    // remeshing at a fixed budget), then land exactly on the budget.
    for (int it = 0; it < 6; ++it) {
        const float m = meanRel(mesh, body);
        splitRound(mesh, body, targetTris + targetTris / 10, 1.33f * m);
        collapseRound(mesh, body, targetTris, 0.8f * m, 0.0f);
        collapseRound(mesh, body, targetTris, 1e9f, 0.0f);
        optimize(mesh, body, 2);
    }
    splitRound(mesh, body, targetTris, 0.0f);
}

void optimize(TriMesh& mesh, const Body& body, int iterations) {
    std::vector<float> size(mesh.positions.size());
    for (std::size_t v = 0; v < size.size(); ++v)
        size[v] = body.sizing(mesh.positions[v]);
    for (int it = 0; it < iterations; ++it) {
        // --- valence-improving flips ------------------------------------------------------------
        {
            EditMesh em(mesh.positions, mesh.tris);
            std::vector<std::uint32_t> et, na, nb;
            std::vector<int> valence(mesh.positions.size(), 0);
            for (std::size_t v = 0; v < valence.size(); ++v) {
                em.neighbours(static_cast<std::uint32_t>(v), na);
                valence[v] = static_cast<int>(na.size());
            }
            const std::size_t nt = mesh.tris.size();
            for (std::size_t t = 0; t < nt; ++t) {
                for (int e = 0; e < 3; ++e) {
                    if (!em.alive[t]) break;
                    const std::uint32_t a = mesh.tris[t][e], b = mesh.tris[t][(e + 1) % 3];
                    if (a > b) continue; // each edge once per pass (from one side)
                    em.edgeTris(a, b, et);
                    if (et.size() != 2) continue;
                    // t1 = (a, b, c) in its winding, t2 = (b, a, d).
                    std::uint32_t t1 = et[0], t2 = et[1];
                    auto hasDirected = [&](std::uint32_t tri, std::uint32_t x, std::uint32_t y) {
                        for (int k = 0; k < 3; ++k)
                            if (mesh.tris[tri][k] == x && mesh.tris[tri][(k + 1) % 3] == y)
                                return true;
                        return false;
                    };
                    if (!hasDirected(t1, a, b)) std::swap(t1, t2);
                    if (!hasDirected(t1, a, b) || !hasDirected(t2, b, a)) continue;
                    const std::uint32_t c = EditMesh::third(mesh.tris[t1], a, b);
                    const std::uint32_t d = EditMesh::third(mesh.tris[t2], a, b);
                    if (valence[a] <= 4 || valence[b] <= 4) continue;
                    const auto dev = [](int x) { return (x - 6) * (x - 6); };
                    const int before =
                        dev(valence[a]) + dev(valence[b]) + dev(valence[c]) + dev(valence[d]);
                    const int after = dev(valence[a] - 1) + dev(valence[b] - 1) +
                                      dev(valence[c] + 1) + dev(valence[d] + 1);
                    const glm::vec3 &A = mesh.positions[a], &Bp = mesh.positions[b],
                                    &C = mesh.positions[c], &D = mesh.positions[d];
                    const float qBefore = std::min(triQuality(A, Bp, C), triQuality(Bp, A, D));
                    const float qAfter = std::min(triQuality(A, D, C), triQuality(D, Bp, C));
                    const bool valenceGain = after < before && qAfter > 0.6f * qBefore;
                    const bool shapeGain = after <= before && qAfter > 1.3f * qBefore;
                    if (!valenceGain && !shapeGain) continue;
                    em.neighbours(c, na);
                    if (std::binary_search(na.begin(), na.end(), d)) continue; // edge exists
                    const glm::vec3 n1 = triNormal(A, Bp, C), n2 = triNormal(Bp, A, D);
                    const float l1 = glm::length(n1), l2 = glm::length(n2);
                    if (l1 < 1e-14f || l2 < 1e-14f) continue;
                    if (glm::dot(n1, n2) < 0.85f * l1 * l2) continue; // crease
                    const glm::vec3 m1 = triNormal(A, D, C), m2 = triNormal(D, Bp, C);
                    const glm::vec3 navg = n1 / l1 + n2 / l2;
                    if (glm::dot(m1, navg) < 0.8f * glm::length(m1) * glm::length(navg)) continue;
                    if (glm::dot(m2, navg) < 0.8f * glm::length(m2) * glm::length(navg)) continue;
                    // Flip: t1 = (a, d, c), t2 = (d, b, c).
                    mesh.tris[t1] = glm::uvec3(a, d, c);
                    mesh.tris[t2] = glm::uvec3(d, b, c);
                    auto drop = [&](std::uint32_t v, std::uint32_t tri) {
                        auto& l = em.vt[v];
                        l.erase(std::remove(l.begin(), l.end(), tri), l.end());
                    };
                    drop(a, t2);
                    drop(b, t1);
                    em.vt[c].push_back(t2);
                    em.vt[d].push_back(t1);
                    --valence[a];
                    --valence[b];
                    ++valence[c];
                    ++valence[d];
                }
            }
        }
        // --- tangential relaxation ---------------------------------------------------------------
        {
            const std::size_t nv = mesh.positions.size();
            std::vector<glm::vec3> acc(nv, glm::vec3(0));
            std::vector<float> wsum(nv, 0.0f);
            for (const auto& t : mesh.tris) {
                const glm::vec3 &A = mesh.positions[t[0]], &Bp = mesh.positions[t[1]],
                                &C = mesh.positions[t[2]];
                const float s = (size[t[0]] + size[t[1]] + size[t[2]]) / 3.0f;
                const float w = 0.5f * glm::length(glm::cross(Bp - A, C - A)) / (s * s);
                const glm::vec3 cen = (A + Bp + C) / 3.0f;
                for (int k = 0; k < 3; ++k) {
                    acc[t[k]] += w * cen;
                    wsum[t[k]] += w;
                }
            }
            std::vector<glm::vec3> old = mesh.positions;
            for (std::size_t v = 0; v < nv; ++v) {
                if (wsum[v] <= 0) continue;
                const glm::vec3 p = old[v];
                glm::vec3 n = body.gradient(p);
                if (glm::dot(n, n) < 1e-12f) continue;
                n = glm::normalize(n);
                glm::vec3 delta = acc[v] / wsum[v] - p;
                delta -= n * glm::dot(delta, n);
                mesh.positions[v] = body.project(p + 0.5f * delta, 3);
            }
            // Undo moves that fold a triangle against the surface normal.
            for (int pass = 0; pass < 3; ++pass) {
                bool any = false;
                for (const auto& t : mesh.tris) {
                    const glm::vec3 &A = mesh.positions[t[0]], &Bp = mesh.positions[t[1]],
                                    &C = mesh.positions[t[2]];
                    const glm::vec3 nn = triNormal(A, Bp, C);
                    const glm::vec3 g = body.gradient((A + Bp + C) / 3.0f);
                    if (glm::dot(nn, g) > 0.2f * glm::length(nn) * glm::length(g)) continue;
                    for (int k = 0; k < 3; ++k) {
                        if (mesh.positions[t[k]] != old[t[k]]) any = true;
                        mesh.positions[t[k]] = old[t[k]];
                    }
                }
                if (!any) break;
            }
            for (std::size_t v = 0; v < nv; ++v)
                size[v] = body.sizing(mesh.positions[v]);
        }
    }
}

TopologyReport checkTopology(const TriMesh& mesh) {
    TopologyReport r;
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
    for (const auto& t : mesh.tris)
        for (int c = 0; c < 3; ++c) {
            const std::uint32_t a = t[c], b = t[(c + 1) % 3];
            if (a == b) {
                r.problem = "degenerate triangle";
                return r;
            }
            if (++directed[{a, b}] > 1) {
                r.problem = "directed edge used twice (" + std::to_string(a) + "," +
                            std::to_string(b) + ")";
                return r;
            }
        }
    for (const auto& [e, n] : directed)
        if (!directed.count({e.second, e.first})) {
            r.problem =
                "open edge (" + std::to_string(e.first) + "," + std::to_string(e.second) + ")";
            return r;
        }
    // Vertex links: the triangles around each vertex form one cycle.
    std::vector<std::vector<std::pair<std::uint32_t, std::uint32_t>>> fan(mesh.positions.size());
    for (const auto& t : mesh.tris)
        for (int c = 0; c < 3; ++c)
            fan[t[c]].push_back({t[(c + 1) % 3], t[(c + 2) % 3]});
    for (std::size_t v = 0; v < fan.size(); ++v) {
        const auto& f = fan[v];
        if (f.empty()) {
            r.problem = "unused vertex " + std::to_string(v);
            return r;
        }
        std::map<std::uint32_t, std::uint32_t> next;
        for (const auto& [a, b] : f)
            next[a] = b;
        std::uint32_t x = f[0].first;
        std::size_t steps = 0;
        do {
            x = next[x];
            ++steps;
        } while (x != f[0].first && steps <= f.size());
        if (steps != f.size()) {
            r.problem = "vertex " + std::to_string(v) + " is not a manifold vertex";
            return r;
        }
    }
    r.closedManifold = true;
    r.euler = static_cast<int>(mesh.positions.size()) - static_cast<int>(directed.size() / 2) +
              static_cast<int>(mesh.tris.size());
    float minAngle = 180.0f;
    for (const auto& t : mesh.tris)
        for (int c = 0; c < 3; ++c) {
            const glm::vec3 a = mesh.positions[t[(c + 1) % 3]] - mesh.positions[t[c]];
            const glm::vec3 b = mesh.positions[t[(c + 2) % 3]] - mesh.positions[t[c]];
            const float cs = glm::dot(a, b) / (glm::length(a) * glm::length(b));
            minAngle = std::min(minAngle, std::acos(std::clamp(cs, -1.0f, 1.0f)) * 57.2957795f);
        }
    r.minAngleDeg = minAngle;
    return r;
}

} // namespace dermis::chargen
