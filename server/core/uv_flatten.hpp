// Dermis core — flattening surface charts into the plane, and how much a flattening distorts:
//   * signedArea, mapSingularValues / conformalDistortion: the measures (a UV triangle's
//     orientation; σ_max, σ_min of the linear map surface triangle → UV triangle);
//   * SparseMatrix, conjugateGradient: the sparse symmetric positive definite solver of the disk
//     flattening (no external linear-algebra library; LSCM has its own, for its 2×2 blocks);
//   * flattenDisk: Tutte embedding on a circle, then as-rigid-as-possible local/global iterations
//     (Liu et al. 2008, "A Local/Global Approach to Mesh Parameterization") with flip-free
//     backtracking — bijective, for a disk with one boundary loop (the default character's atlas,
//     models/src/uv_atlas.cpp);
//   * flattenLscm: least-squares conformal maps (Lévy et al. 2002) with two pinned vertices —
//     any chart with boundary, one sparse solve (the generated layout, layout_gen.hpp).
//
// Pure (no GL, no I/O), deterministic (sequential, fixed operation order: the same input gives
// bit-identical output). Nothing here throws but std::bad_alloc. Failures are returned as empty
// results with a note; callers turn them into errors.
#pragma once

#include <glm/glm.hpp>

#include <cstdint>
#include <string>
#include <tuple>
#include <vector>

namespace dermis {

/// Whether the open segments p1p2 and q1q2 cross at one point inside both (touching ends or
/// collinear overlaps do not count).
bool segmentsCross(const glm::dvec2& p1, const glm::dvec2& p2, const glm::dvec2& q1,
                   const glm::dvec2& q2);

/// Signed area of the 2-D triangle (a, b, c), positive when counter-clockwise (y up).
double signedArea(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c);

/// The singular values σ_max ≥ σ_min of the linear map taking the surface triangle (q0, q1, q2)
/// onto the UV triangle (u0, u1, u2), and its determinant's absolute value (σ_max·σ_min: the
/// local area scale). Precondition: the surface triangle has a non-zero area (else NaN).
struct MapSingularValues {
    double smax = 0.0, smin = 0.0, det = 0.0;
};
MapSingularValues mapSingularValues(const glm::dvec3& q0, const glm::dvec3& q1,
                                    const glm::dvec3& q2, const glm::dvec2& u0,
                                    const glm::dvec2& u1, const glm::dvec2& u2);

/// σ_max / σ_min of the linear map taking a surface triangle onto its UV triangle (1 =
/// conformal). σ_min is clamped at 1e-15 (a collapsed UV triangle gives a huge value, not ∞).
double conformalDistortion(const glm::vec3& q0, const glm::vec3& q1, const glm::vec3& q2,
                           const glm::dvec2& u0, const glm::dvec2& u1, const glm::dvec2& u2);

/// A square sparse matrix in compressed rows (columns sorted within a row).
struct SparseMatrix {
    int n = 0;
    std::vector<int> rowStart, col;
    std::vector<double> val;
    /// Sums duplicate (row, column) entries. Preconditions: indices in [0, n).
    static SparseMatrix fromTriplets(int n, std::vector<std::tuple<int, int, double>> trip);
    /// y = A·x (y resized to n).
    void mul(const std::vector<double>& x, std::vector<double>& y) const;
};

/// Preconditioned conjugate gradients for a symmetric positive definite system: `a.mul(x, y)`
/// sets y = A·x (y has x's size), `invDiag(i)` is the preconditioner's factor for unknown i (1
/// for plain CG; Jacobi: the inverse of the diagonal). x holds the initial guess and receives
/// the solution. Stops after maxIter iterations, when ‖r‖ ≤ tol·‖b‖, or when the search
/// direction has no positive curvature (a singular or indefinite system, or NaN).
template <class Operator, class InvDiagonal>
void preconditionedConjugateGradient(const Operator& a, InvDiagonal invDiag, const std::vector<double>& b,
                                     std::vector<double>& x, int maxIter, double tol) {
    const std::size_t n = x.size();
    std::vector<double> r(n), z(n), p(n), ap(n);
    a.mul(x, ap);
    double bb = 0, rz = 0, rr = 0;
    for (std::size_t i = 0; i < n; ++i) {
        r[i] = b[i] - ap[i];
        z[i] = r[i] * invDiag(i);
        bb += b[i] * b[i];
        rz += r[i] * z[i];
        rr += r[i] * r[i];
    }
    p = z;
    if (bb == 0) bb = 1;
    for (int it = 0; it < maxIter && rr > tol * tol * bb; ++it) {
        a.mul(p, ap);
        double pap = 0;
        for (std::size_t i = 0; i < n; ++i) pap += p[i] * ap[i];
        if (!(pap > 0)) break;
        const double alpha = rz / pap;
        double rz2 = 0;
        rr = 0;
        for (std::size_t i = 0; i < n; ++i) {
            x[i] += alpha * p[i];
            r[i] -= alpha * ap[i];
            z[i] = r[i] * invDiag(i);
            rz2 += r[i] * z[i];
            rr += r[i] * r[i];
        }
        const double beta = rz2 / rz;
        rz = rz2;
        for (std::size_t i = 0; i < n; ++i) p[i] = z[i] + beta * p[i];
    }
}

/// Plain conjugate gradients on a SparseMatrix (preconditionedConjugateGradient with factor 1).
void conjugateGradient(const SparseMatrix& a, const std::vector<double>& b, std::vector<double>& x,
                       int maxIter = 4000, double tol = 1e-12);

/// A chart to flatten: its own vertices and triangles (counter-clockwise seen from outside: the
/// flattenings keep that orientation, positive signed areas).
struct ChartMesh {
    std::vector<glm::dvec3> positions;
    std::vector<glm::uvec3> triangles;
};

/// Flattens a disk-shaped chart whose one boundary loop is `boundary` (chart vertices in order,
/// counter-clockwise around the surface seen from outside). Returns UVs in the chart's length
/// unit (isometric scale), every triangle positively oriented; `note` says how many ARAP
/// iterations were kept. Fails (empty result, `note` says why) when the Tutte embedding already
/// flips (it cannot for a disk, up to solver accuracy). Precondition: the chart is a disk (one
/// boundary loop, χ = 1) without degenerate triangles. Up to `iterations` ARAP steps.
std::vector<glm::dvec2> flattenDisk(const ChartMesh& chart,
                                    const std::vector<std::uint32_t>& boundary, std::string& note,
                                    int iterations = 150);

/// Least-squares conformal map of a chart with boundary: minimises Σ_T A_T·|∇v − R90 ∇u|² with
/// chart vertices pins[0], pins[1] held at pinUv[0], pinUv[1] (the map is then unique for a
/// connected chart), solved by Jacobi-preconditioned conjugate gradients from `initial` (one UV
/// per vertex, e.g. a projection; the pins' entries are ignored). Returns one UV per vertex in
/// the unit of pinUv; triangles come out positively oriented where the chart allows a conformal
/// flattening (callers check flips and boundary overlaps: LSCM does not guarantee them away).
/// Preconditions: pins distinct vertices of the chart, every triangle of non-zero area, the
/// chart edge-connected. Empty result when the chart has fewer than 3 vertices.
std::vector<glm::dvec2> flattenLscm(const ChartMesh& chart, const std::uint32_t pins[2],
                                    const glm::dvec2 pinUv[2], std::vector<glm::dvec2> initial,
                                    int maxIter = 2000, double tol = 1e-9);

} // namespace dermis
