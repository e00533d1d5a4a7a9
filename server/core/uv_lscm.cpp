// Dermis core — least-squares conformal maps (uv_flatten.hpp; Lévy, Petitjean, Ray, Maillot
// 2002). Per triangle T with isometric corners p_j and edges e_j = p_{j+2} − p_{j+1} (opposite
// corner j), ∇f = (1/2A) Σ_j f_j R90(e_j), so the Cauchy–Riemann residual of (u, v) is
// r = ∇v − R90 ∇u = (1/2A) Σ_j (u_j e_j + v_j R90 e_j) and the energy A·|r|² is the quadratic
// form (1/4A) |Σ_j (u_j e_j + v_j R90 e_j)|²: blocks [e_a·e_b, −e_a×e_b; e_a×e_b, e_a·e_b]/4A.
// The free vertices' normal equations are assembled straight into compressed rows (pattern from
// the vertex neighbourhoods) and solved by Jacobi-preconditioned conjugate gradients.
#include "uv_flatten.hpp"

#include <algorithm>
#include <cmath>

namespace dermis {

std::vector<glm::dvec2> flattenLscm(const ChartMesh& chart, const std::uint32_t pins[2],
                                    const glm::dvec2 pinUv[2], std::vector<glm::dvec2> initial,
                                    int maxIter, double tol) {
    const std::size_t n = chart.positions.size();
    if (n < 3 || pins[0] == pins[1] || pins[0] >= n || pins[1] >= n || initial.size() != n)
        return {};
    std::vector<int> idx(n, -1);
    int nf = 0;
    for (std::size_t v = 0; v < n; ++v)
        if (v != pins[0] && v != pins[1]) idx[v] = nf++;
    std::vector<glm::dvec2> uv = std::move(initial);
    uv[pins[0]] = pinUv[0];
    uv[pins[1]] = pinUv[1];
    if (nf == 0) return uv;

    // Row pattern: a free vertex's free neighbours (itself included), sorted; the u-row and the
    // v-row of a vertex share it, the u columns first.
    std::vector<std::vector<std::uint32_t>> nb(n);
    for (const glm::uvec3& t : chart.triangles)
        for (int a = 0; a < 3; ++a)
            if (idx[t[a]] >= 0)
                for (int b = 0; b < 3; ++b)
                    if (idx[t[b]] >= 0) nb[t[a]].push_back(static_cast<std::uint32_t>(idx[t[b]]));
    for (auto& l : nb) {
        std::sort(l.begin(), l.end());
        l.erase(std::unique(l.begin(), l.end()), l.end());
    }
    SparseMatrix m;
    m.n = 2 * nf;
    m.rowStart.assign(static_cast<std::size_t>(m.n) + 1, 0);
    std::vector<std::size_t> rowOfVertex(static_cast<std::size_t>(nf));
    for (std::size_t v = 0; v < n; ++v)
        if (idx[v] >= 0) rowOfVertex[static_cast<std::size_t>(idx[v])] = v;
    for (int c = 0; c < 2; ++c)
        for (int i = 0; i < nf; ++i) {
            const std::size_t row = static_cast<std::size_t>(c * nf + i);
            m.rowStart[row + 1] =
                m.rowStart[row] + 2 * static_cast<int>(nb[rowOfVertex[static_cast<std::size_t>(i)]].size());
        }
    m.col.resize(static_cast<std::size_t>(m.rowStart.back()));
    m.val.assign(m.col.size(), 0.0);
    for (int c = 0; c < 2; ++c)
        for (int i = 0; i < nf; ++i) {
            const auto& l = nb[rowOfVertex[static_cast<std::size_t>(i)]];
            auto at = static_cast<std::size_t>(m.rowStart[static_cast<std::size_t>(c * nf + i)]);
            for (std::uint32_t j : l)
                m.col[at++] = static_cast<int>(j);
            for (std::uint32_t j : l)
                m.col[at++] = nf + static_cast<int>(j);
        }
    // Adds `value` at (row, column) of the pattern.
    auto add = [&](int row, int column, double value) {
        const auto b = m.col.begin() + m.rowStart[static_cast<std::size_t>(row)];
        const auto e = m.col.begin() + m.rowStart[static_cast<std::size_t>(row) + 1];
        const auto it = std::lower_bound(b, e, column);
        m.val[static_cast<std::size_t>(it - m.col.begin())] += value;
    };

    std::vector<double> rhs(static_cast<std::size_t>(m.n), 0.0);
    for (const glm::uvec3& t : chart.triangles) {
        const glm::dvec3 a = chart.positions[t[0]], b = chart.positions[t[1]],
                         c = chart.positions[t[2]];
        const double len = glm::length(b - a);
        const glm::dvec3 nrm = glm::cross(b - a, c - a);
        const double nl = glm::length(nrm);
        if (!(len > 0) || !(nl > 0)) continue;
        const glm::dvec3 e1 = (b - a) / len;
        const glm::dvec3 e2 = glm::cross(nrm / nl, e1);
        const glm::dvec2 p[3] = {glm::dvec2(0), glm::dvec2(len, 0),
                                 glm::dvec2(glm::dot(c - a, e1), glm::dot(c - a, e2))};
        const double w = 1.0 / (2.0 * len * p[2].y); // 1 / 4A
        const glm::dvec2 e[3] = {p[2] - p[1], p[0] - p[2], p[1] - p[0]};
        for (int i = 0; i < 3; ++i) {
            const int fi = idx[t[i]];
            if (fi < 0) continue;
            for (int j = 0; j < 3; ++j) {
                const double dot = w * glm::dot(e[i], e[j]);
                const double cross = w * (e[i].x * e[j].y - e[i].y * e[j].x);
                const int fj = idx[t[j]];
                if (fj >= 0) {
                    add(fi, fj, dot);
                    add(fi, nf + fj, -cross);
                    add(nf + fi, fj, cross);
                    add(nf + fi, nf + fj, dot);
                } else {
                    const glm::dvec2 q = uv[t[j]];
                    rhs[static_cast<std::size_t>(fi)] -= dot * q.x - cross * q.y;
                    rhs[static_cast<std::size_t>(nf + fi)] -= cross * q.x + dot * q.y;
                }
            }
        }
    }
    std::vector<double> x(static_cast<std::size_t>(m.n));
    for (std::size_t v = 0; v < n; ++v)
        if (idx[v] >= 0) {
            x[static_cast<std::size_t>(idx[v])] = uv[v].x;
            x[static_cast<std::size_t>(nf + idx[v])] = uv[v].y;
        }
    jacobiConjugateGradient(m, rhs, x, maxIter, tol);
    for (std::size_t v = 0; v < n; ++v)
        if (idx[v] >= 0)
            uv[v] = {x[static_cast<std::size_t>(idx[v])], x[static_cast<std::size_t>(nf + idx[v])]};
    return uv;
}

} // namespace dermis
