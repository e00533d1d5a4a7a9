// CPU height-map stage (paper §4 first stage, SPEC §2 "Height maps" and "Conventions").
//
// Cost model: each placement touches only the texels of its footprint (a texel rectangle, then
// per row the exact span inside the rotated rectangle), with the texel → pattern map
// precomputed as an affine form per row and a branch-free, call-free bilinear inner loop per
// deform case (paper eq. 1 and 2). Placements at t = 0 are skipped. The result equals the
// per-texel definition (placementHeight summed in document order) up to the last bits of the
// bilinear weights; HeightmapTest checks this against a straightforward per-texel evaluation.
#include "heightmap.hpp"

#include "row_bands.hpp"
#include "texture_layout.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <tuple>

namespace dermis {

std::shared_ptr<const PatternImage> makePatternImage(HeightImage pixels) {
    static std::atomic<std::uint64_t> next{1};
    auto out = std::make_shared<PatternImage>();
    out->contentId = next.fetch_add(1);
    out->pixels = std::move(pixels);
    return out;
}


float sampleBilinear(const HeightImage& image, double su, double sv) {
    // Texel k has its centre at (k + 0.5)/N: continuous texel coordinate x = s·N − 0.5.
    const double x = su * image.width - 0.5, y = sv * image.height - 0.5;
    const double fx0 = std::floor(x), fy0 = std::floor(y);
    const double fx = x - fx0, fy = y - fy0;
    auto clampi = [](double v, int n) {
        return static_cast<int>(std::clamp(v, 0.0, static_cast<double>(n - 1)));
    };
    const int x0 = clampi(fx0, image.width), x1 = clampi(fx0 + 1, image.width);
    const int y0 = clampi(fy0, image.height), y1 = clampi(fy0 + 1, image.height);
    const double top = image.at(x0, y0) * (1.0 - fx) + image.at(x1, y0) * fx;
    const double bottom = image.at(x0, y1) * (1.0 - fx) + image.at(x1, y1) * fx;
    return static_cast<float>(top * (1.0 - fy) + bottom * fy);
}

glm::dvec2 Footprint::toPattern(glm::dvec2 uv) const {
    const double a = glm::radians(rotationDeg), c = std::cos(a), s = std::sin(a);
    const glm::dvec2 d = uv - center;
    // R(−a)·d with R(a) = [[cos a, −sin a], [sin a, cos a]].
    const glm::dvec2 r(c * d.x + s * d.y, -s * d.x + c * d.y);
    return r / scale + 0.5;
}

glm::dvec2 Footprint::toUV(glm::dvec2 st) const {
    const double a = glm::radians(rotationDeg), c = std::cos(a), s = std::sin(a);
    const glm::dvec2 d = (st - 0.5) * scale;
    return center + glm::dvec2(c * d.x - s * d.y, s * d.x + c * d.y);
}

std::pair<glm::dvec2, glm::dvec2> Footprint::uvBounds() const {
    glm::dvec2 lo(INFINITY), hi(-INFINITY);
    for (double su : {0.0, 1.0})
        for (double sv : {0.0, 1.0}) {
            const glm::dvec2 p = toUV({su, sv});
            lo = glm::min(lo, p);
            hi = glm::max(hi, p);
        }
    return {lo, hi};
}

TexelRect footprintTexels(const Footprint& f, int width, int height) {
    const auto [lo, hi] = f.uvBounds();
    // Texel centres (i + 0.5)/W inside [lo, hi], widened by one texel against rounding.
    auto first = [](double v, int n) {
        return static_cast<int>(std::clamp(std::ceil(v * n - 0.5) - 1.0, 0.0, double(n)));
    };
    auto last = [](double v, int n) {
        return static_cast<int>(std::clamp(std::floor(v * n - 0.5) + 2.0, 0.0, double(n)));
    };
    TexelRect r;
    r.x0 = first(lo.x, width);
    r.x1 = last(hi.x, width);
    r.y0 = first(lo.y, height);
    r.y1 = last(hi.y, height);
    return r;
}

namespace {

bool insideUnit(glm::dvec2 s) {
    return s.x >= 0.0 && s.x <= 1.0 && s.y >= 0.0 && s.y <= 1.0;
}

/// sampleBilinear's arithmetic without the call, the HeightImage indirection or std::clamp on
/// doubles: pattern `pat` (pw × ph floats, row-major), s ∈ [0,1]² (the caller guarantees it).
/// x ≥ −0.5 here, so floor(x) = int(x + 1) − 1. Identical to sampleBilinear up to the last bit
/// of the weights (at most one rounding of x + 1).
inline float bilinearUnit(const float* pat, int pw, int ph, double su, double sv) {
    const double x = su * pw - 0.5, y = sv * ph - 0.5;
    const int xf = static_cast<int>(x + 1.0) - 1, yf = static_cast<int>(y + 1.0) - 1;
    const double fx = x - xf, fy = y - yf;
    const int x0 = xf < 0 ? 0 : xf, x1 = xf + 1 < pw ? xf + 1 : pw - 1;
    const int y0 = yf < 0 ? 0 : yf, y1 = yf + 1 < ph ? yf + 1 : ph - 1;
    const float* r0 = pat + static_cast<std::ptrdiff_t>(y0) * pw;
    const float* r1 = pat + static_cast<std::ptrdiff_t>(y1) * pw;
    const double top = r0[x0] * (1.0 - fx) + r0[x1] * fx;
    const double bottom = r1[x0] * (1.0 - fx) + r1[x1] * fx;
    return static_cast<float>(top * (1.0 - fy) + bottom * fy);
}

/// applyDeform (paper eq. 1 and 2, SPEC §2) split by case so the inner loop has no branch on t
/// or on the model: Full = L·h (t ≥ 1, either model), Gain = L·h·gain(t) (eq. 1, 0 < t < 1),
/// Bias = max(h·(L − offset(t)), 0) (eq. 2, 0 < t < 1). Same float arithmetic as applyDeform.
enum class Kernel { Full, Gain, Bias };

template <Kernel K>
inline float deformed(float L, float h, float k) {
    if constexpr (K == Kernel::Full) return L * h;
    else if constexpr (K == Kernel::Gain) return L * h * k;
    else {
        const float v = h * (L - k);
        return v > 0.0f ? v : 0.0f;
    }
}

/// [t0, t1) ⊆ [0, n): the steps t where lo ≤ X0 + DX·t < hi, exactly (integer arithmetic; the
/// set is an interval because X is linear in t).
std::pair<int, int> stepsWithin(std::int64_t X0, std::int64_t DX, std::int64_t lo, std::int64_t hi,
                                int n) {
    auto in = [&](int t) {
        const std::int64_t X = X0 + DX * t;
        return X >= lo && X < hi;
    };
    if (DX == 0) return in(0) ? std::pair{0, n} : std::pair{0, 0};
    // Real-valued crossings, then exact adjustment by a step or two.
    const double a = static_cast<double>(lo - X0) / static_cast<double>(DX),
                 b = static_cast<double>(hi - X0) / static_cast<double>(DX);
    double f0 = std::ceil(std::min(a, b)) - 1.0, f1 = std::floor(std::max(a, b)) + 2.0;
    int t0 = static_cast<int>(std::clamp(f0, 0.0, static_cast<double>(n)));
    int t1 = static_cast<int>(std::clamp(f1, 0.0, static_cast<double>(n)));
    while (t0 < t1 && !in(t0)) ++t0;
    while (t1 > t0 && !in(t1 - 1)) --t1;
    return {t0, t1};
}

/// The bilinear taps of one texel: pattern row `r0`/`r1`, columns x0/x1, weights fx/fy.
template <Kernel K>
inline float tapsToHeight(const float* r0, const float* r1, int x0, int x1, float fx, float fy,
                          float h, float k) {
    const float top = r0[x0] + (r0[x1] - r0[x0]) * fx;
    const float bottom = r1[x0] + (r1[x1] - r1[x0]) * fx;
    return deformed<K>(top + (bottom - top) * fy, h, k);
}

/// Fixed-point scale of the texel coordinates: 32.32.
constexpr double kFixedOne = 4294967296.0; // 2^32

/// Adds one placement's L_out to out[t] for t ∈ [t0, t1), t counting texels from a row span's
/// first texel; [ti0, ti1) are the steps whose taps need no clamping (RowSpan). Along a row the pattern coordinate
/// s = R(−rotation)·(p − center)/scale + 0.5 (SPEC "Conventions") is affine in i, and so are the
/// continuous texel coordinates x = s·N − 0.5; they are stepped here as X = x + 1 (≥ 0.5 inside
/// the footprint) in 32.32 fixed point: X0, Y0 at t = 0, DX, DY per texel. The integer part
/// indexes the pattern, the fraction is the bilinear weight, with no float→int conversion per
/// texel; stepping is exact integer arithmetic, so the result does not depend on how rows are
/// split into spans. The error against the double-precision reference is ≤ 2⁻³² texel plus float
/// lerps (≈ 1e-7 relative), far below the tests' tolerance. The steps whose 2×2 taps all lie
/// inside the pattern run in a loop without clamps; only texels within half a pattern texel of
/// the footprint's edge clamp to the edge texels (SPEC: "clamped to the edge texels").
template <Kernel K>
void addRange(float* out, int t0, int t1, int ti0, int ti1, std::int64_t X0, std::int64_t DX,
              std::int64_t Y0, std::int64_t DY, const float* pat, int pw, int ph, float h,
              float k) {
    constexpr float kFrac = 1.0f / 4294967296.0f;
    // Clamped taps (SPEC: "clamped to the edge texels inside the footprint"): s ∈ [0, 1] ⇔
    // x + 1 ∈ [0.5, N + 0.5].
    const std::int64_t xLo = std::int64_t{1} << 31, xHi = (std::int64_t{pw} << 32) + xLo;
    const std::int64_t yLo = xLo, yHi = (std::int64_t{ph} << 32) + yLo;
    const int xMax = pw - 1, yMax = ph - 1;
    auto clamped = [&](int c0, int c1) {
        for (int t = c0; t < c1; ++t) {
            std::int64_t X = X0 + DX * t, Y = Y0 + DY * t;
            X = X < xLo ? xLo : (X > xHi ? xHi : X);
            Y = Y < yLo ? yLo : (Y > yHi ? yHi : Y);
            const int xf = static_cast<int>(X >> 32) - 1, yf = static_cast<int>(Y >> 32) - 1;
            const int x0 = xf < 0 ? 0 : xf, x1 = xf < xMax ? xf + 1 : xMax;
            const int y0 = yf < 0 ? 0 : yf, y1 = yf < yMax ? yf + 1 : yMax;
            out[t] += tapsToHeight<K>(pat + static_cast<std::ptrdiff_t>(y0) * pw,
                                      pat + static_cast<std::ptrdiff_t>(y1) * pw, x0, x1,
                                      static_cast<float>(X & 0xFFFFFFFF) * kFrac,
                                      static_cast<float>(Y & 0xFFFFFFFF) * kFrac, h, k);
        }
    };
    const int f0 = std::max(t0, ti0), f1 = std::min(t1, ti1);
    if (f0 >= f1) {
        clamped(t0, t1);
        return;
    }
    clamped(t0, f0);
    std::int64_t X = X0 + DX * f0, Y = Y0 + DY * f0;
    for (int t = f0; t < f1; ++t, X += DX, Y += DY) {
        const float* r0 = pat + (static_cast<std::ptrdiff_t>(Y >> 32) - 1) * pw - 1;
        const int x = static_cast<int>(X >> 32);
        out[t] += tapsToHeight<K>(r0, r0 + pw, x, x + 1,
                                  static_cast<float>(X & 0xFFFFFFFF) * kFrac,
                                  static_cast<float>(Y & 0xFFFFFFFF) * kFrac, h, k);
    }
    clamped(f1, t1);
}

/// A placement prepared once per bake: its texel rectangle, rotation, deform case and constants,
/// pattern pointer and output map. Placements at t ≤ 0 contribute nothing and are not prepared.
struct Prepared {
    TexelRect rect;
    glm::dvec2 center, scale;
    double cosA = 1.0, sinA = 0.0;
    Kernel kernel = Kernel::Full;
    DeformModel model = DeformModel::Scale; ///< for the per-texel fallback
    double t = 1.0;
    bool fixedPoint = true; ///< false when a texel step spans ≥ 2²⁰ pattern texels (overflow guard)
    float h = 1.0f, k = 0.0f;
    const float* pattern = nullptr;
    int pw = 0, ph = 0;
    HeightImage* out = nullptr;
    const BakePlacement* surface = nullptr; ///< a surface placement (SPEC §8): per texel, below

    /// s of texel (i, ·) with dv = v − center.v, with exactly the arithmetic of
    /// Footprint::toPattern (so that the inside test below agrees with placementHeight).
    glm::dvec2 exactS(int i, int W, double dv) const {
        const double du = (i + 0.5) / W - center.x;
        return {(cosA * du + sinA * dv) / scale.x + 0.5, (-sinA * du + cosA * dv) / scale.y + 0.5};
    }
};

/// Texels [i0, i1) of row j whose centres are inside the footprint, exactly as placementHeight
/// decides it. s is linear in i along a row, so the analytic span of s ∈ [0,1]² (widened by a
/// texel) is trimmed and grown by the exact test at its ends; every floating-point step of
/// exactS is monotone in i, so the exact inside set of a row is one interval.
std::pair<int, int> insideSpan(const Prepared& a, int W, double dv, double ax, double bx,
                               double ay, double by) {
    double lo = a.rect.x0, hi = a.rect.x1;
    for (auto [a0, b] : {std::pair{ax, bx}, std::pair{ay, by}}) {
        if (std::abs(b) < 1e-300) {
            if (a0 < -1e-9 || a0 > 1.0 + 1e-9) hi = lo; // the whole row is outside
            continue;
        }
        const double e0 = (0.0 - a0) / b, e1 = (1.0 - a0) / b;
        lo = std::max(lo, std::floor(std::min(e0, e1)) - 1.0);
        hi = std::min(hi, std::ceil(std::max(e0, e1)) + 2.0);
    }
    int i0 = static_cast<int>(lo), i1 = static_cast<int>(std::max(lo, hi));
    while (i0 < i1 && !insideUnit(a.exactS(i0, W, dv))) ++i0;
    while (i1 > i0 && !insideUnit(a.exactS(i1 - 1, W, dv))) --i1;
    if (i0 == i1) return {0, 0};
    while (i0 > a.rect.x0 && insideUnit(a.exactS(i0 - 1, W, dv))) --i0;
    while (i1 < a.rect.x1 && insideUnit(a.exactS(i1, W, dv))) ++i1;
    return {i0, i1};
}

/// One row of a tile: its inside span and the fixed-point texel coordinates at its first texel.
struct RowSpan {
    int i0 = 0, i1 = 0;         ///< inside span
    int ti0 = 0, ti1 = 0;       ///< steps (from i0) whose 2×2 taps are all inside the pattern
    int cursor = 0;             ///< steps not drawn yet: [cursor, n) (DY ≥ 0) or [0, cursor)
    std::int64_t X = 0, Y = 0;  ///< fixed-point x + 1, y + 1 at i0
};

/// Adds surface placement `p`'s L_out (surfacePlacementHeight at each texel's rest-surface
/// point, SPEC §8) to rows [r0, r1) of `out` within `rect`, skipping the rest map's tiles it
/// cannot reach and texels without coverage. Same arithmetic as surfacePlacementHeight.
void addSurfaceRows(const BakePlacement& p, const RestSurfaceMap& rest, const TexelRect& rect,
                    int r0, int r1, HeightImage& out) {
    const SurfaceFrame frame(p);
    const float h = static_cast<float>(p.h), k = deformConstant(p.model, p.response, p.t);
    constexpr int T = RestSurfaceMap::kTile;
    const bool tiled = rest.tileMin.size() == static_cast<std::size_t>(rest.tilesX) * rest.tilesY &&
                       rest.tileMax.size() == rest.tileMin.size();
    const int W = rest.width;
    for (int j = r0; j < r1; ++j) {
        float* row = &out.data[static_cast<std::size_t>(j) * W];
        for (int i0 = rect.x0; i0 < rect.x1;) {
            const int i1 = std::min(rect.x1, (i0 / T + 1) * T); // to the end of this tile
            if (tiled && !surfaceTileNear(frame, rest, static_cast<std::size_t>(j / T) * rest.tilesX +
                                                           static_cast<std::size_t>(i0 / T))) {
                i0 = i1;
                continue;
            }
            for (int i = i0; i < i1; ++i) {
                const std::size_t idx = static_cast<std::size_t>(j) * W + i;
                if (!rest.coverage[idx]) continue;
                glm::dvec2 s;
                if (!frame.toPattern(glm::dvec3(rest.position[idx]), glm::dvec3(rest.normal[idx]), s))
                    continue;
                row[i] += applyDeform(p.model, sampleBilinear(*p.pattern, s.x, s.y), h, p.t, k);
            }
            i0 = i1;
        }
    }
}

/// Pattern rows per band of the placement loop (see bakeRows).
constexpr int kBandRows = 32;

} // namespace

float placementHeight(const BakePlacement& p, glm::dvec2 uv) {
    const glm::dvec2 s = p.footprint.toPattern(uv);
    if (!insideUnit(s)) return 0.0f;
    const float L = sampleBilinear(*p.pattern, s.x, s.y);
    return applyDeform(p.model, L, static_cast<float>(p.h), p.t,
                       deformConstant(p.model, p.response, p.t));
}

Status bakeHeightMapsInto(const std::vector<BakePlacement>& placements,
                          const BakeSettings& settings, HeightMaps& maps) {
    const char* where = "dermis::bakeHeightMaps";
    const int W = settings.width, H = settings.height;
    if (W <= 0 || H <= 0 || W > kMaxHeightmapSize || H > kMaxHeightmapSize)
        return makeError(ErrorCode::InvalidArgument, where, "/heightmap/size",
                         "each side must be in [1, " + std::to_string(kMaxHeightmapSize) + "]");
    for (std::size_t k = 0; k < placements.size(); ++k) {
        const BakePlacement& p = placements[k];
        const HeightImage* img = p.pattern;
        if (!img || img->width <= 0 || img->height <= 0 ||
            img->data.size() != static_cast<std::size_t>(img->width) * img->height)
            return makeError(ErrorCode::InvalidArgument, where,
                             "/placements/" + std::to_string(k) + "/pattern", "no pattern image");
        if (!(p.footprint.scale.x > 0.0) || !(p.footprint.scale.y > 0.0))
            return makeError(ErrorCode::InvalidArgument, where,
                             "/placements/" + std::to_string(k) + "/scale", "must be > 0");
    }
    const RestSurfaceMap* rest = settings.rest;
    for (std::size_t k = 0; k < placements.size(); ++k) {
        const BakePlacement& p = placements[k];
        if (!p.surface) continue;
        const std::string field = "/placements/" + std::to_string(k);
        if (!rest || rest->width != W || rest->height != H ||
            rest->position.size() != static_cast<std::size_t>(W) * H ||
            rest->normal.size() != rest->position.size() || rest->coverage.size() != rest->position.size())
            return makeError(ErrorCode::InvalidArgument, where, field + "/projection",
                             "a surface placement needs the rest-surface map of the layout in use "
                             "at the map size (" + std::to_string(W) + "x" + std::to_string(H) + ")");
        if (!(p.size.x > 0.0) || !(p.size.y > 0.0))
            return makeError(ErrorCode::InvalidArgument, where, field + "/size", "must be > 0");
        if (!(p.depth > 0.0))
            return makeError(ErrorCode::InvalidArgument, where, field + "/depth", "must be > 0");
    }
    const HeightImage* base = settings.base;
    if (base && (base->width <= 0 || base->height <= 0 ||
                 base->data.size() != static_cast<std::size_t>(base->width) * base->height))
        return makeError(ErrorCode::InvalidArgument, where, "/heightmap/base", "empty base map");

    // Reuse the caller's storage when it has the right size (a per-frame loop then never
    // allocates); rows are cleared by the worker that bakes them.
    for (HeightImage* m : {&maps.bump, &maps.displacement}) {
        m->width = W;
        m->height = H;
        m->data.resize(static_cast<std::size_t>(W) * H);
    }

    // Per-placement constants (paper §4.2: eq. 1 for Scale, eq. 2 for Bias, with SPEC §2's t);
    // placements at t = 0 give L_out = 0 everywhere and are dropped.
    std::vector<Prepared> active;
    active.reserve(placements.size());
    for (const BakePlacement& p : placements) {
        if (p.t <= 0.0) continue;
        Prepared a;
        if (p.surface) {
            a.rect = surfacePlacementTexels(p, *rest);
            if (a.rect.x0 >= a.rect.x1 || a.rect.y0 >= a.rect.y1) continue; // reaches no texel
            a.surface = &p;
            a.out = p.target == Target::Bump ? &maps.bump : &maps.displacement;
            active.push_back(a);
            continue;
        }
        a.rect = footprintTexels(p.footprint, W, H);
        if (a.rect.x0 >= a.rect.x1 || a.rect.y0 >= a.rect.y1) continue; // off the map
        const double rad = glm::radians(p.footprint.rotationDeg);
        a.center = p.footprint.center;
        a.scale = p.footprint.scale;
        a.cosA = std::cos(rad);
        a.sinA = std::sin(rad);
        a.kernel = p.t >= 1.0 ? Kernel::Full
                   : p.model == DeformModel::Scale ? Kernel::Gain : Kernel::Bias;
        a.model = p.model;
        a.t = p.t;
        a.h = static_cast<float>(p.h);
        a.k = deformConstant(p.model, p.response, p.t);
        a.pattern = p.pattern->data.data();
        a.pw = p.pattern->width;
        a.ph = p.pattern->height;
        a.fixedPoint = std::abs(a.cosA / (W * a.scale.x)) * a.pw < 0x1p20 &&
                       std::abs(a.sinA / (W * a.scale.y)) * a.ph < 0x1p20 &&
                       a.pw < (1 << 28) && a.ph < (1 << 28);
        a.out = p.target == Target::Bump ? &maps.bump : &maps.displacement;
        active.push_back(a);
    }

    // Rows [y0, y1): base first, then each placement in document order, so every texel's sum
    // has the same order whatever the split.
    auto bakeRows = [&](int y0, int y1) {
        const std::size_t first = static_cast<std::size_t>(y0) * W,
                          last = static_cast<std::size_t>(y1) * W;
        std::fill(maps.displacement.data.begin() + first, maps.displacement.data.begin() + last,
                  0.0f);
        if (!base) {
            std::fill(maps.bump.data.begin() + first, maps.bump.data.begin() + last, 0.0f);
        } else if (base->width == W && base->height == H) {
            std::copy(base->data.begin() + first, base->data.begin() + last,
                      maps.bump.data.begin() + first);
        } else { // resampled: sampleBilinear(base, (i + 0.5)/W, (j + 0.5)/H)
            for (int j = y0; j < y1; ++j) {
                float* row = &maps.bump.data[static_cast<std::size_t>(j) * W];
                const double sv = (j + 0.5) / H;
                for (int i = 0; i < W; ++i)
                    row[i] = bilinearUnit(base->data.data(), base->width, base->height,
                                          (i + 0.5) / W, sv);
            }
        }
        // Each placement is visited in bands of kBandRows pattern rows: within a band every map
        // row adds the sub-span of texels whose bilinear taps start in those pattern rows, so
        // the band's taps read one contiguous slice of the pattern (kBandRows + 1 rows, 64 KB
        // for a 512-wide pattern) that stays in cache while the band is drawn. Visiting map rows
        // in order instead walks a rotated pattern diagonally: a new cache line, often a new
        // page, per texel once the patterns outgrow the cache. Each texel falls in exactly one
        // band, and the fixed-point stepping is exact, so the split changes no value.
        std::vector<RowSpan> spans;
        for (const Prepared& a : active) {
            const int r0 = std::max(y0, a.rect.y0), r1 = std::min(y1, a.rect.y1);
            if (r0 >= r1) continue;
            if (a.surface) {
                addSurfaceRows(*a.surface, *rest, a.rect, r0, r1, *a.out);
                continue;
            }
            // Along row j, s(i) = R(−rotation)·((i + 0.5)/W − cu, dv)/scale + 0.5 is affine in i:
            // s = (ax + bx·i, ay + by·i).
            const double du0 = 0.5 / W - a.center.x;
            const double bx = a.cosA / (W * a.scale.x), by = -a.sinA / (W * a.scale.y);
            const std::int64_t DX = std::llround(bx * a.pw * kFixedOne),
                               DY = std::llround(by * a.ph * kFixedOne);
            spans.assign(static_cast<std::size_t>(r1 - r0), RowSpan{});
            for (int j = r0; j < r1; ++j) {
                const double dv = (j + 0.5) / H - a.center.y;
                const double ax = (a.cosA * du0 + a.sinA * dv) / a.scale.x + 0.5;
                const double ay = (-a.sinA * du0 + a.cosA * dv) / a.scale.y + 0.5;
                RowSpan& sp = spans[static_cast<std::size_t>(j - r0)];
                std::tie(sp.i0, sp.i1) = insideSpan(a, W, dv, ax, bx, ay, by);
                if (sp.i0 >= sp.i1) continue;
                if (!a.fixedPoint) { // a texel step spans ≥ 2²⁰ pattern texels: per texel
                    float* row = &a.out->data[static_cast<std::size_t>(j) * W];
                    for (int i = sp.i0; i < sp.i1; ++i) {
                        const glm::dvec2 st = glm::clamp(a.exactS(i, W, dv), 0.0, 1.0);
                        row[i] += applyDeform(a.model, bilinearUnit(a.pattern, a.pw, a.ph, st.x, st.y),
                                              a.h, a.t, a.k);
                    }
                    sp.i1 = sp.i0; // done
                    continue;
                }
                sp.X = std::llround(((ax + bx * sp.i0) * a.pw + 0.5) * kFixedOne);
                sp.Y = std::llround(((ay + by * sp.i0) * a.ph + 0.5) * kFixedOne);
                // Interior: ⌊x⌋ ∈ [0, N − 2] on both axes ⇔ x + 1 ∈ [1, N).
                const int n = sp.i1 - sp.i0;
                const auto [xi0, xi1] = stepsWithin(sp.X, DX, std::int64_t{1} << 32,
                                                    std::int64_t{a.pw} << 32, n);
                const auto [yi0, yi1] = stepsWithin(sp.Y, DY, std::int64_t{1} << 32,
                                                    std::int64_t{a.ph} << 32, n);
                sp.ti0 = std::max(xi0, yi0);
                sp.ti1 = std::min(xi1, yi1);
                sp.cursor = DY >= 0 ? 0 : n;
            }
            // Y = y + 1 ∈ [0.5, N + 0.5]: band b holds ⌊Y⌋ < (b+1)·kBandRows; the last band is
            // open-ended. Y is monotone along a row, so a row's bands are consecutive pieces:
            // from its start when DY ≥ 0, from its end when DY < 0 (cursor).
            const int bands = a.ph / kBandRows + 1;
            const double invDY = DY != 0 ? 1.0 / static_cast<double>(DY) : 0.0;
            for (int band = 0; band < bands; ++band) {
                // Ask for the next band's pattern rows while this one is drawn: the first touch
                // of a pattern row is otherwise a cache miss per line, one at a time.
                if (band + 1 < bands) {
                    const int p0 = (band + 1) * kBandRows, p1 = std::min(a.ph, p0 + kBandRows + 1);
                    const float* from = a.pattern + static_cast<std::ptrdiff_t>(p0) * a.pw;
                    const float* to = a.pattern + static_cast<std::ptrdiff_t>(p1) * a.pw;
                    for (const float* q = from; q < to; q += 16) __builtin_prefetch(q);
                }
                const std::int64_t hi = band == bands - 1 ? (std::int64_t{1} << 62)
                                                          : (std::int64_t{band + 1} * kBandRows) << 32;
                for (int j = r0; j < r1; ++j) {
                    RowSpan& sp = spans[static_cast<std::size_t>(j - r0)];
                    const int n = sp.i1 - sp.i0;
                    int t0, t1;
                    auto below = [&](int t) { return sp.Y + DY * t < hi; };
                    if (DY >= 0) { // draw [cursor, e): the steps with Y < hi
                        if (sp.cursor >= n || !below(sp.cursor)) continue;
                        int e = DY == 0 ? n
                                        : static_cast<int>(std::clamp(
                                              std::ceil(static_cast<double>(hi - sp.Y) * invDY),
                                              static_cast<double>(sp.cursor), static_cast<double>(n)));
                        while (e > sp.cursor + 1 && !below(e - 1)) --e;
                        while (e < n && below(e)) ++e;
                        t0 = sp.cursor;
                        t1 = sp.cursor = e;
                    } else { // Y decreases: draw [b, cursor)
                        if (sp.cursor <= 0 || !below(sp.cursor - 1)) continue;
                        int b = static_cast<int>(std::clamp(
                            std::floor(static_cast<double>(hi - sp.Y) * invDY),
                            0.0, static_cast<double>(sp.cursor - 1)));
                        while (b < sp.cursor - 1 && !below(b)) ++b;
                        while (b > 0 && below(b - 1)) --b;
                        t0 = b;
                        t1 = sp.cursor;
                        sp.cursor = b;
                    }
                    float* out = &a.out->data[static_cast<std::size_t>(j) * W] + sp.i0;
                    switch (a.kernel) {
                    case Kernel::Full:
                        addRange<Kernel::Full>(out, t0, t1, sp.ti0, sp.ti1, sp.X, DX, sp.Y, DY, a.pattern, a.pw, a.ph, a.h, a.k);
                        break;
                    case Kernel::Gain:
                        addRange<Kernel::Gain>(out, t0, t1, sp.ti0, sp.ti1, sp.X, DX, sp.Y, DY, a.pattern, a.pw, a.ph, a.h, a.k);
                        break;
                    case Kernel::Bias:
                        addRange<Kernel::Bias>(out, t0, t1, sp.ti0, sp.ti1, sp.X, DX, sp.Y, DY, a.pattern, a.pw, a.ph, a.h, a.k);
                        break;
                    }
                }
            }
        }
    };

    const int threads = settings.threads > 0 ? settings.threads : automaticThreadCount();
    forRowBands(H, threads, [&](int, int y0, int y1) { bakeRows(y0, y1); });
    return Ok{};
}

Result<HeightMaps> bakeHeightMaps(const std::vector<BakePlacement>& placements,
                                  const BakeSettings& settings) {
    HeightMaps maps;
    if (auto s = bakeHeightMapsInto(placements, settings, maps); !s) return s.error();
    return maps;
}

} // namespace dermis
