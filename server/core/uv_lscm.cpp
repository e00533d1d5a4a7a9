// Dermis core — least-squares conformal maps (uv_flatten.hpp; Lévy, Petitjean, Ray, Maillot
// 2002). Per triangle T with isometric corners p_j and edges e_j = p_{j+2} − p_{j+1} (opposite
// corner j), ∇f = (1/2A) Σ_j f_j R90(e_j), so the Cauchy–Riemann residual of (u, v) is
// r = ∇v − R90 ∇u = (1/2A) Σ_j (u_j e_j + v_j R90 e_j) and the energy A·|r|² is the quadratic
// form (1/4A) |Σ_j (u_j e_j + v_j R90 e_j)|²: 2×2 blocks [e_a·e_b, −e_a×e_b; e_a×e_b, e_a·e_b]/4A
// between vertices a and b — a similarity each, i.e. one complex number d + i·c acting on
// u + i·v, so the system is Hermitian of the free vertices' count. Its rows are assembled
// straight from the vertex neighbourhoods and solved by Jacobi-preconditioned conjugate
// gradients (the diagonal blocks are real: c = 0).
#include "uv_flatten.hpp"

#include <algorithm>
#include <cmath>

namespace dermis {
namespace {

/// Rows of 2×2 similarity blocks [d, −c; c, d], columns sorted within a row.
struct SimilarityRows {
    std::vector<std::size_t> rowStart;
    std::vector<std::uint32_t> col;
    std::vector<double> d, c;

    /// y = A·x, x and y interleaved (u, v) per row.
    void mul(const std::vector<double>& x, std::vector<double>& y) const {
        const std::size_t rows = rowStart.size() - 1;
        for (std::size_t r = 0; r < rows; ++r) {
            double yu = 0, yv = 0;
            for (std::size_t k = rowStart[r]; k < rowStart[r + 1]; ++k) {
                const double xu = x[2 * col[k]], xv = x[2 * col[k] + 1];
                yu += d[k] * xu - c[k] * xv;
                yv += c[k] * xu + d[k] * xv;
            }
            y[2 * r] = yu;
            y[2 * r + 1] = yv;
        }
    }
};


} // namespace

std::vector<glm::dvec2> flattenLscm(const ChartMesh& chart, const std::uint32_t pins[2],
                                    const glm::dvec2 pinUv[2], std::vector<glm::dvec2> initial,
                                    int maxIter, double tol) {
    const std::size_t n = chart.positions.size();
    if (n < 3 || pins[0] == pins[1] || pins[0] >= n || pins[1] >= n || initial.size() != n)
        return {};
    std::vector<std::int64_t> idx(n, -1);
    std::size_t nf = 0;
    for (std::size_t v = 0; v < n; ++v)
        if (v != pins[0] && v != pins[1]) idx[v] = static_cast<std::int64_t>(nf++);
    std::vector<glm::dvec2> uv = std::move(initial);
    uv[pins[0]] = pinUv[0];
    uv[pins[1]] = pinUv[1];
    if (nf == 0) return uv;

    // Row pattern: a free vertex's free neighbours (itself included), sorted.
    std::vector<std::vector<std::uint32_t>> nb(nf);
    for (const glm::uvec3& t : chart.triangles)
        for (int a = 0; a < 3; ++a)
            if (idx[t[a]] >= 0)
                for (int b = 0; b < 3; ++b)
                    if (idx[t[b]] >= 0)
                        nb[static_cast<std::size_t>(idx[t[a]])].push_back(
                            static_cast<std::uint32_t>(idx[t[b]]));
    SimilarityRows m;
    m.rowStart.assign(nf + 1, 0);
    for (std::size_t i = 0; i < nf; ++i) {
        auto& l = nb[i];
        std::sort(l.begin(), l.end());
        l.erase(std::unique(l.begin(), l.end()), l.end());
        m.rowStart[i + 1] = m.rowStart[i] + l.size();
    }
    m.col.reserve(m.rowStart.back());
    for (const auto& l : nb)
        m.col.insert(m.col.end(), l.begin(), l.end());
    m.d.assign(m.col.size(), 0.0);
    m.c.assign(m.col.size(), 0.0);
    auto slot = [&](std::size_t row, std::uint32_t column) {
        const auto b = m.col.begin() + static_cast<std::ptrdiff_t>(m.rowStart[row]);
        const auto e = m.col.begin() + static_cast<std::ptrdiff_t>(m.rowStart[row + 1]);
        return static_cast<std::size_t>(std::lower_bound(b, e, column) - m.col.begin());
    };

    std::vector<double> rhs(2 * nf, 0.0);
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
            if (idx[t[i]] < 0) continue;
            const auto fi = static_cast<std::size_t>(idx[t[i]]);
            for (int j = 0; j < 3; ++j) {
                const double dot = w * glm::dot(e[i], e[j]);
                const double cross = w * (e[i].x * e[j].y - e[i].y * e[j].x);
                if (idx[t[j]] >= 0) {
                    const std::size_t k = slot(fi, static_cast<std::uint32_t>(idx[t[j]]));
                    m.d[k] += dot;
                    m.c[k] += cross;
                } else {
                    const glm::dvec2 q = uv[t[j]];
                    rhs[2 * fi] -= dot * q.x - cross * q.y;
                    rhs[2 * fi + 1] -= cross * q.x + dot * q.y;
                }
            }
        }
    }
    std::vector<double> inv(nf, 1.0);
    for (std::size_t i = 0; i < nf; ++i) {
        const std::size_t k = slot(i, static_cast<std::uint32_t>(i));
        if (m.d[k] > 0) inv[i] = 1.0 / m.d[k];
    }
    std::vector<double> x(2 * nf);
    for (std::size_t v = 0; v < n; ++v)
        if (idx[v] >= 0) {
            x[2 * static_cast<std::size_t>(idx[v])] = uv[v].x;
            x[2 * static_cast<std::size_t>(idx[v]) + 1] = uv[v].y;
        }
    // Jacobi: the inverse of each row's (real) diagonal block, for both of its unknowns.
    preconditionedConjugateGradient(m, [&inv](std::size_t i) { return inv[i / 2]; }, rhs, x, maxIter, tol);
    for (std::size_t v = 0; v < n; ++v)
        if (idx[v] >= 0)
            uv[v] = {x[2 * static_cast<std::size_t>(idx[v])],
                     x[2 * static_cast<std::size_t>(idx[v]) + 1]};
    return uv;
}

} // namespace dermis
