// Dermis built-in pattern library — the procedural patterns. See patterns.hpp.
#include "patterns.hpp"

#include <glm/glm.hpp>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>

namespace dermis::patterngen {

namespace {

constexpr double kPi = 3.14159265358979323846;

// --- deterministic noise -------------------------------------------------------------------

/// A 32-bit integer mixer (lowbias32 by C. Wellons): a bijection with good avalanche.
std::uint32_t hash32(std::uint32_t x) {
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

std::uint32_t hash2(std::uint32_t a, std::uint32_t b) {
    return hash32(a ^ hash32(b + 0x9e3779b9u));
}

/// Uniform in [0, 1) from (seed, index).
double rand01(std::uint32_t seed, std::uint32_t index) {
    return static_cast<double>(hash2(seed, index)) / 4294967296.0;
}

/// A counter-based generator: the n-th draw of a seed is always the same number.
struct Rng {
    std::uint32_t seed;
    std::uint32_t n = 0;
    explicit Rng(std::uint32_t s) : seed(s) {}
    double next() { return rand01(seed, n++); }
    double range(double lo, double hi) { return lo + (hi - lo) * next(); }
    std::uint32_t sub() { return hash2(seed, 0x51ed270bu + n++); }
};

double quintic(double t) { return t * t * t * (t * (t * 6.0 - 15.0) + 10.0); }

/// 1D value noise in [−1, 1], C² (quintic interpolation of hashed lattice values).
double noise1(double x, std::uint32_t seed) {
    double fl = std::floor(x);
    auto i = static_cast<std::int64_t>(fl);
    double a = 2.0 * rand01(seed, static_cast<std::uint32_t>(i)) - 1.0;
    double b = 2.0 * rand01(seed, static_cast<std::uint32_t>(i + 1)) - 1.0;
    return a + (b - a) * quintic(x - fl);
}

/// Two octaves of value noise, roughly in [−1, 1].
double fbm1(double x, std::uint32_t seed) {
    return (noise1(x, seed) + 0.5 * noise1(2.03 * x + 17.0, seed ^ 0xa5a5a5a5u)) / 1.5;
}

// --- smooth helpers ------------------------------------------------------------------------

double smoothstep(double e0, double e1, double x) {
    double t = std::clamp((x - e0) / (e1 - e0), 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}

double smootherstep(double e0, double e1, double x) {
    return quintic(std::clamp((x - e0) / (e1 - e0), 0.0, 1.0));
}

/// Border window: 1 inside, falling smoothly (C²) to 0 at the image edge over `margin`.
double borderWindow(double x, double y, double margin) {
    return smootherstep(0.0, margin, x) * smootherstep(0.0, margin, 1.0 - x) *
           smootherstep(0.0, margin, y) * smootherstep(0.0, margin, 1.0 - y);
}

/// Texel-centre coordinate in [0,1] and the centred one in (−0.5, 0.5), exactly antisymmetric
/// under mirroring (i ↔ N−1−i), so mirror-symmetric shapes are bit-symmetric.
double texelCoord(int i, int n) { return (i + 0.5) / n; }
double centredCoord(int i, int n) {
    return static_cast<double>(2 * i + 1 - n) / static_cast<double>(2 * n);
}

/// Screen blend of non-negative heights in [0, 1]: a smooth union that never exceeds 1.
double screen(double a, double b) { return a + b - a * b; }

// --- strokes: grooves and ridges along a centre line ----------------------------------------

/// A centre line sampled as a polyline with arc-length parameter s ∈ [0, 1].
struct Curve {
    std::vector<glm::dvec2> pts;
    std::vector<double> cum; ///< arc length up to each point
    glm::dvec2 lo{1e9}, hi{-1e9};

    static Curve sample(const std::function<glm::dvec2(double)>& f, int n = 160) {
        Curve c;
        for (int k = 0; k < n; ++k) {
            glm::dvec2 p = f(static_cast<double>(k) / (n - 1));
            if (!c.pts.empty()) c.cum.push_back(c.cum.back() + glm::length(p - c.pts.back()));
            else c.cum.push_back(0.0);
            c.pts.push_back(p);
            c.lo = glm::min(c.lo, p);
            c.hi = glm::max(c.hi, p);
        }
        return c;
    }
    double length() const { return cum.back(); }

    /// Distance from p to the polyline and the arc-length parameter s ∈ [0,1] of the nearest point.
    void nearest(glm::dvec2 p, double& dist, double& s) const {
        double best = std::numeric_limits<double>::max(), bestArc = 0.0;
        for (std::size_t k = 0; k + 1 < pts.size(); ++k) {
            glm::dvec2 a = pts[k], ab = pts[k + 1] - a;
            double len2 = glm::dot(ab, ab);
            double t = len2 > 0.0 ? std::clamp(glm::dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
            glm::dvec2 d = p - (a + t * ab);
            double d2 = glm::dot(d, d);
            if (d2 < best) {
                best = d2;
                bestArc = cum[k] + t * (cum[k + 1] - cum[k]);
            }
        }
        dist = std::sqrt(best);
        s = length() > 0.0 ? bestArc / length() : 0.0;
    }
};

/// A wrinkle groove: depth and width taper to 0 at both ends (over `endFade` of the length) and
/// the depth wanders along the groove by ±depthVar.
struct Groove {
    Curve curve;
    double depth = 1.0;   ///< peak depth (positive number; the groove is negative)
    double width = 0.012; ///< valley half-width scale (pattern units) in the middle
    double endFade = 0.3; ///< fraction of the length over which each end tapers
    double depthVar = 0.2;
    double varFreq = 3.0; ///< noise features along the groove
    std::uint32_t seed = 1;
};

/// Cross profile of a fold at u = distance / width: a narrow valley (−1 at the centre) with
/// broad, low shoulders of compressed skin either side (peak ≈ +0.2 at |u| ≈ 1.8). Smooth at 0.
constexpr double kShoulder = 0.2, kShoulderAt = 1.8, kGrooveCut = 7.0;
double grooveProfile(double u) {
    double q = (u * u) / (kShoulderAt * kShoulderAt);
    return -std::exp(-u * u) + kShoulder * q * std::exp(1.0 - q);
}

double grooveAt(const Groove& g, glm::dvec2 p) {
    double reach = kGrooveCut * g.width;
    if (p.x < g.curve.lo.x - reach || p.x > g.curve.hi.x + reach || p.y < g.curve.lo.y - reach ||
        p.y > g.curve.hi.y + reach)
        return 0.0;
    double d, s;
    g.curve.nearest(p, d, s);
    double taper = smootherstep(0.0, g.endFade, s) * smootherstep(0.0, g.endFade, 1.0 - s);
    if (taper <= 0.0) return 0.0;
    double w = g.width * (0.4 + 0.6 * std::sqrt(taper));
    double u = d / w;
    if (u >= kGrooveCut) return 0.0;
    double amp = g.depth * taper * (1.0 + g.depthVar * fbm1(s * g.varFreq, g.seed));
    return amp * grooveProfile(u);
}

/// A bone ridge: a rounded bar with compact (1 − (d/w)²)³ cross-section whose crest height and
/// width follow the bone along its length.
struct Ridge {
    Curve curve;
    std::function<double(double)> height; ///< crest height at s, 0 at both ends
    std::function<double(double)> width;  ///< half-width at s
    double maxWidth = 0.05;
};

double ridgeAt(const Ridge& r, glm::dvec2 p) {
    double reach = r.maxWidth;
    if (p.x < r.curve.lo.x - reach || p.x > r.curve.hi.x + reach || p.y < r.curve.lo.y - reach ||
        p.y > r.curve.hi.y + reach)
        return 0.0;
    double d, s;
    r.curve.nearest(p, d, s);
    double w = r.width(s);
    if (d >= w) return 0.0;
    double q = 1.0 - (d / w) * (d / w);
    return r.height(s) * q * q * q;
}

/// Sums grooves, scales so that the deepest point is −1, applies the border window.
HeightImage renderGrooves(int n, const std::vector<Groove>& grooves, double margin) {
    std::vector<double> raw(static_cast<std::size_t>(n) * n, 0.0);
    double lo = 0.0;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            glm::dvec2 p{texelCoord(i, n), texelCoord(j, n)};
            double v = 0.0;
            for (const Groove& g : grooves) v += grooveAt(g, p);
            raw[static_cast<std::size_t>(j) * n + i] = v;
            lo = std::min(lo, v);
        }
    double k = lo < 0.0 ? -1.0 / lo : 1.0;
    HeightImage img(n, n);
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            double v = raw[static_cast<std::size_t>(j) * n + i] * k *
                       borderWindow(texelCoord(i, n), texelCoord(j, n), margin);
            img.at(i, j) = static_cast<float>(std::clamp(v, -1.0, 1.0));
        }
    return img;
}

/// Normalises a non-negative field so its maximum is exactly 1, then applies the border window.
HeightImage finishBone(int n, const std::function<double(glm::dvec2)>& field, double margin) {
    std::vector<double> raw(static_cast<std::size_t>(n) * n, 0.0);
    double hi = 0.0;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            double v = field({texelCoord(i, n), texelCoord(j, n)});
            raw[static_cast<std::size_t>(j) * n + i] = v;
            hi = std::max(hi, v);
        }
    double k = hi > 0.0 ? 1.0 / hi : 1.0;
    HeightImage img(n, n);
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            double v = raw[static_cast<std::size_t>(j) * n + i] * k *
                       borderWindow(texelCoord(i, n), texelCoord(j, n), margin);
            img.at(i, j) = static_cast<float>(std::clamp(v, 0.0, 1.0));
        }
    return img;
}

// --- wrinkles ------------------------------------------------------------------------------

/// Horizontal stomach folds (bending the spine forward): six folds of unequal length, depth and
/// spacing, sagging slightly, the deepest just above the middle, plus short shallow creases in
/// some of the gaps.
HeightImage stomachWrinkles(int n) {
    Rng rng(0x5704ac01u);
    struct Fold {
        double y, x0, x1, sag, depth, width;
    };
    const Fold folds[] = {
        {0.170, 0.24, 0.74, 0.020, 0.48, 0.012}, {0.300, 0.12, 0.87, 0.030, 0.78, 0.015},
        {0.415, 0.08, 0.93, 0.040, 1.00, 0.019}, {0.555, 0.16, 0.80, 0.035, 0.66, 0.014},
        {0.665, 0.10, 0.89, 0.045, 0.86, 0.017}, {0.805, 0.30, 0.72, 0.030, 0.42, 0.011},
    };
    std::vector<Groove> gs;
    std::vector<std::function<double(double)>> centre; // y of each fold's centre line at x
    for (const Fold& f : folds) {
        double y0 = f.y + rng.range(-0.008, 0.008);
        double x0 = f.x0 + rng.range(-0.03, 0.03), x1 = f.x1 + rng.range(-0.03, 0.03);
        double tilt = rng.range(-0.015, 0.015), sag = f.sag;
        std::uint32_t ws = rng.sub();
        auto yAt = [=](double x) {
            double xc = (x - 0.5) / 0.5;
            return y0 + sag * (1.0 - xc * xc) + tilt * xc + 0.007 * fbm1(x * 5.0, ws);
        };
        centre.push_back(yAt);
        Groove g;
        g.curve = Curve::sample([=](double s) {
            double x = x0 + (x1 - x0) * s;
            return glm::dvec2{x, yAt(x)};
        });
        g.depth = f.depth * rng.range(0.95, 1.05);
        g.width = f.width;
        g.endFade = rng.range(0.28, 0.4);
        g.depthVar = 0.22;
        g.varFreq = 3.5;
        g.seed = rng.sub();
        gs.push_back(std::move(g));
    }
    // Short secondary creases midway in some of the gaps, slightly oblique: {gap, x, angle}.
    const double gaps[][3] = {{0, 0.56, -0.05}, {1, 0.32, 0.07}, {2, 0.66, -0.08}, {3, 0.4, 0.05}};
    for (const auto& gp : gaps) {
        auto k = static_cast<std::size_t>(gp[0]);
        double xc = gp[1] + rng.range(-0.03, 0.03);
        double yc = 0.5 * (centre[k](xc) + centre[k + 1](xc));
        double len = rng.range(0.13, 0.22), ang = gp[2];
        std::uint32_t ws = rng.sub();
        Groove g;
        g.curve = Curve::sample([=](double s) {
            double a = (s - 0.5) * len;
            return glm::dvec2{xc + a * std::cos(ang),
                              yc + a * std::sin(ang) + 0.003 * noise1(s * 3.0, ws)};
        });
        g.depth = rng.range(0.22, 0.34);
        g.width = rng.range(0.0065, 0.008);
        g.endFade = 0.45;
        g.depthVar = 0.15;
        g.seed = rng.sub();
        gs.push_back(std::move(g));
    }
    return renderGrooves(n, gs, 0.08);
}

/// Diagonal folds on the side of the waist (twisting the torso): a fan of gently S-curved
/// grooves, from about 28° (top) to 48° (bottom), of unequal length, depth and spacing.
HeightImage waistTwist(int n) {
    Rng rng(0x3a157201u);
    std::vector<Groove> gs;
    const double depths[] = {0.55, 0.92, 0.7, 1.0, 0.6, 0.82};
    const double lengths[] = {0.42, 0.62, 0.55, 0.72, 0.5, 0.46};
    double o = -0.30;
    for (int k = 0; k < 6; ++k) {
        if (k > 0) o += 0.115 + rng.range(-0.03, 0.03);
        const double ang = (28.0 + 4.0 * k + rng.range(-2.0, 2.0)) * kPi / 180.0;
        const glm::dvec2 dir{std::cos(ang), -std::sin(ang)}; // rising to the right (y is down)
        const glm::dvec2 nrm{std::sin(ang), std::cos(ang)};
        const glm::dvec2 c = glm::dvec2{0.5, 0.5} + o * glm::dvec2{0.7071, 0.7071} +
                             rng.range(-0.04, 0.04) * dir;
        double len = lengths[k] * rng.range(0.92, 1.06);
        double bend = rng.range(0.012, 0.025);
        std::uint32_t ws = rng.sub();
        Groove g;
        g.curve = Curve::sample([=](double s) {
            double a = (s - 0.5) * len;
            double across = bend * std::sin(2.0 * kPi * (s - 0.5)) + 0.006 * fbm1(s * 4.0, ws);
            return c + a * dir + across * nrm;
        });
        g.depth = depths[k] * rng.range(0.94, 1.06);
        g.width = rng.range(0.011, 0.016);
        g.endFade = rng.range(0.3, 0.42);
        g.depthVar = 0.25;
        g.varFreq = 3.0;
        g.seed = rng.sub();
        gs.push_back(std::move(g));
    }
    // A few short shallow creases between the main folds.
    for (int k = 0; k < 3; ++k) {
        double oo = -0.19 + 0.21 * k + rng.range(-0.015, 0.015);
        double a2 = (32.0 + 6.0 * k + rng.range(-6.0, 6.0)) * kPi / 180.0;
        glm::dvec2 d2{std::cos(a2), -std::sin(a2)};
        glm::dvec2 c = glm::dvec2{0.5, 0.5} + oo * glm::dvec2{0.7071, 0.7071} +
                       rng.range(-0.12, 0.12) * d2;
        double len = rng.range(0.12, 0.2);
        Groove g;
        g.curve = Curve::sample([=](double s) { return c + (s - 0.5) * len * d2; });
        g.depth = rng.range(0.22, 0.35);
        g.width = rng.range(0.006, 0.008);
        g.endFade = 0.45;
        g.depthVar = 0.15;
        g.seed = rng.sub();
        gs.push_back(std::move(g));
    }
    return renderGrooves(n, gs, 0.08);
}

/// Inner elbow / back of the knee: one deep curved crease with shallower, shorter arcs above and
/// below it, not quite concentric.
HeightImage crease(int n) {
    Rng rng(0xc4ea5e01u);
    struct Arc {
        double cx, radius, a0, a1, depth, width, fade;
    };
    // Arcs of circles centred below the image; apex at y = 1.35 − radius.
    const Arc arcs[] = {
        {0.50, 0.83, -0.50, 0.48, 1.00, 0.019, 0.35}, // the main crease
        {0.47, 0.74, -0.22, 0.40, 0.62, 0.012, 0.40}, // below
        {0.53, 0.925, -0.36, 0.22, 0.48, 0.011, 0.42}, // above
        {0.44, 0.665, -0.34, 0.02, 0.30, 0.008, 0.45}, // faint, further below
        {0.56, 1.01, -0.08, 0.26, 0.26, 0.007, 0.45},  // faint, further above
    };
    std::vector<Groove> gs;
    for (const Arc& a : arcs) {
        std::uint32_t ws = rng.sub();
        double cy = 1.35;
        Groove g;
        g.curve = Curve::sample([=](double s) {
            double th = a.a0 + (a.a1 - a.a0) * s;
            double r = a.radius + 0.005 * fbm1(s * 4.0, ws);
            return glm::dvec2{a.cx + r * std::sin(th), cy - r * std::cos(th)};
        });
        g.depth = a.depth * rng.range(0.95, 1.05);
        g.width = a.width;
        g.endFade = a.fade;
        g.depthVar = 0.18;
        g.varFreq = 3.0;
        g.seed = rng.sub();
        gs.push_back(std::move(g));
    }
    return renderGrooves(n, gs, 0.08);
}

/// Neck rings: three long, thin horizontal rings dipping slightly in the middle, of unequal
/// depth and partly broken, plus two short partial rings.
HeightImage neckRings(int n) {
    Rng rng(0x7eccb001u);
    struct Ring {
        double y, x0, x1, dip, depth, width, fade, var;
    };
    const Ring rings[] = {
        {0.29, 0.05, 0.95, 0.035, 0.72, 0.0095, 0.3, 0.32},
        {0.50, 0.03, 0.97, 0.045, 1.00, 0.0125, 0.3, 0.25},
        {0.72, 0.06, 0.92, 0.05, 0.62, 0.0090, 0.32, 0.35},
        {0.395, 0.30, 0.62, 0.04, 0.30, 0.0065, 0.45, 0.15},
        {0.615, 0.52, 0.86, 0.045, 0.26, 0.0060, 0.45, 0.15},
    };
    std::vector<Groove> gs;
    for (const Ring& r : rings) {
        std::uint32_t ws = rng.sub();
        double y0 = r.y + rng.range(-0.01, 0.01);
        Groove g;
        g.curve = Curve::sample([=](double s) {
            double x = r.x0 + (r.x1 - r.x0) * s;
            double xc = (x - 0.5) / 0.5;
            return glm::dvec2{x, y0 + r.dip * (1.0 - xc * xc) + 0.005 * fbm1(x * 6.0, ws)};
        });
        g.depth = r.depth * rng.range(0.95, 1.05);
        g.width = r.width;
        g.endFade = r.fade;
        g.depthVar = r.var;
        g.varFreq = 5.0;
        g.seed = rng.sub();
        gs.push_back(std::move(g));
    }
    return renderGrooves(n, gs, 0.07);
}

// --- bulges --------------------------------------------------------------------------------

/// (1 − r²)³ for r < 1, 0 outside: C² everywhere, curved top (no plateau), no rings.
double dome(double r2) {
    if (r2 >= 1.0) return 0.0;
    double q = 1.0 - r2;
    return q * q * q;
}

/// Biceps: a round dome of radius 0.45, peak 1.0 at the centre; symmetric in x and y.
HeightImage roundBulge(int n) {
    HeightImage img(n, n);
    const double radius = 0.45;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            double x = centredCoord(i, n) / radius, y = centredCoord(j, n) / radius;
            img.at(i, j) = static_cast<float>(dome(x * x + y * y));
        }
    return img;
}

/// Thigh: an elongated dome along y (0.44 half-length), slightly wider toward the top (the hip
/// end), peak 1.0 near the centre; symmetric in x.
HeightImage elongatedBulge(int n) {
    HeightImage img(n, n);
    const double ry = 0.44;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            double x = centredCoord(i, n), y = centredCoord(j, n);
            double rx = 0.26 * (1.0 - 0.35 * y); // 0.30 at the top, 0.22 at the bottom
            double u = x / rx, v = y / ry;
            img.at(i, j) = static_cast<float>(dome(u * u + v * v));
        }
    return img;
}

// --- bones ---------------------------------------------------------------------------------

/// Clavicle: an S-curved ridge from the sternal end (left, a rounded knob) to the acromial end
/// (right, higher, broader and flatter). The crest (1.0) is on the medial half.
HeightImage clavicle(int n) {
    std::uint32_t ws = 0xc1a71c01u;
    Ridge r;
    r.curve = Curve::sample([=](double s) {
        double x = 0.12 + 0.76 * s;
        double y = 0.56 - 0.11 * s + 0.045 * std::sin(2.0 * kPi * s) + 0.004 * noise1(s * 4.0, ws);
        return glm::dvec2{x, y};
    });
    r.height = [](double s) {
        double ends = smootherstep(0.0, 0.12, s) * smootherstep(0.0, 0.22, 1.0 - s);
        double crest = 0.72 + 0.28 * std::exp(-((s - 0.3) / 0.2) * ((s - 0.3) / 0.2));
        double knob = 0.12 * std::exp(-((s - 0.07) / 0.06) * ((s - 0.07) / 0.06));
        double lateral = 1.0 - 0.3 * smoothstep(0.55, 1.0, s);
        return ends * (crest + knob) * lateral;
    };
    r.width = [](double s) {
        return 0.05 + 0.02 * std::exp(-((s - 0.05) / 0.1) * ((s - 0.05) / 0.1)) +
               0.03 * smoothstep(0.6, 1.0, s);
    };
    r.maxWidth = 0.1;
    return finishBone(n, [&](glm::dvec2 p) { return ridgeAt(r, p); }, 0.07);
}

/// Ribs on the side of the chest: five curved ridges descending from the back (right) toward the
/// front, curving up again toward the sternum (left), where they fade; the lower ribs are
/// shorter and fainter.
HeightImage ribs(int n) {
    Rng rng(0x81b5c001u);
    const double amp[] = {0.9, 1.0, 0.95, 0.82, 0.66};
    std::vector<Ridge> rs;
    for (int k = 0; k < 5; ++k) {
        double y0 = 0.09 + 0.152 * k + rng.range(-0.01, 0.01);
        double xs = 0.94 - 0.015 * k, xe = 0.12 + 0.07 * k;
        double drop = 0.32 + 0.03 * k + rng.range(-0.02, 0.02);
        double lift = 0.29 + 0.02 * k + rng.range(-0.02, 0.02);
        std::uint32_t ws = rng.sub();
        double a = amp[k];
        Ridge r;
        r.curve = Curve::sample([=](double s) {
            return glm::dvec2{xs + (xe - xs) * s,
                              y0 + drop * s - lift * s * s + 0.004 * noise1(s * 4.0, ws)};
        });
        r.height = [a](double s) {
            return a * smootherstep(0.0, 0.15, s) * smootherstep(0.0, 0.12, 1.0 - s) *
                   (1.0 - 0.8 * smoothstep(0.3, 1.0, s));
        };
        r.width = [](double s) { return 0.03 + 0.012 * (1.0 - s); };
        r.maxWidth = 0.05;
        rs.push_back(std::move(r));
    }
    return finishBone(
        n,
        [&](glm::dvec2 p) {
            double v = 0.0;
            for (const Ridge& r : rs) v = screen(v, ridgeAt(r, p));
            return v;
        },
        0.07);
}

/// Signed distance from p to the line through a and b, positive on the side of `inside`.
double lineDistance(glm::dvec2 p, glm::dvec2 a, glm::dvec2 b, glm::dvec2 inside) {
    glm::dvec2 e = glm::normalize(b - a);
    glm::dvec2 nrm{-e.y, e.x};
    double d = glm::dot(p - a, nrm);
    return glm::dot(inside - a, nrm) >= 0.0 ? d : -d;
}

/// Right scapula seen from the back: a low triangular plate with a raised medial border (left),
/// a prominent inferior angle, and the spine of the scapula rising toward the acromion (the
/// crest, 1.0).
HeightImage scapula(int n) {
    const glm::dvec2 sup{0.27, 0.15}, inf{0.36, 0.87}, lat{0.83, 0.3};
    Ridge medial;
    medial.curve = Curve::sample([=](double s) {
        glm::dvec2 p = sup + (inf - sup) * s;
        p.x -= 0.035 * std::sin(kPi * s);
        return p;
    });
    medial.height = [](double s) {
        return smootherstep(0.0, 0.2, s) * smootherstep(0.0, 0.08, 1.0 - s) *
               (0.5 + 0.28 * smoothstep(0.55, 0.95, s));
    };
    medial.width = [](double s) { return 0.035 + 0.015 * smoothstep(0.7, 1.0, s); };
    medial.maxWidth = 0.05;

    Ridge lateral; // the thick lateral border, faint under the muscles
    lateral.curve = Curve::sample([=](double s) {
        glm::dvec2 a{0.76, 0.36}, b{0.39, 0.84};
        glm::dvec2 p = a + (b - a) * s;
        p.x += 0.02 * std::sin(kPi * s);
        return p;
    });
    lateral.height = [](double s) {
        return 0.22 * smootherstep(0.0, 0.3, s) * smootherstep(0.0, 0.25, 1.0 - s);
    };
    lateral.width = [](double) { return 0.035; };
    lateral.maxWidth = 0.04;

    Ridge spine;
    const glm::dvec2 root{0.27, 0.33}, acromion{0.88, 0.17};
    spine.curve = Curve::sample([=](double s) {
        glm::dvec2 p = root + (acromion - root) * s;
        p.y += 0.025 * std::sin(kPi * s);
        return p;
    });
    spine.height = [](double s) {
        return smootherstep(0.0, 0.25, s) * smootherstep(0.0, 0.1, 1.0 - s) *
               (0.55 + 0.45 * smoothstep(0.1, 0.65, s));
    };
    spine.width = [](double s) { return 0.03 + 0.025 * smoothstep(0.6, 1.0, s); };
    spine.maxWidth = 0.06;

    return finishBone(
        n,
        [&](glm::dvec2 p) {
            // A soft triangular plate: the product of three smooth half-planes has no creases
            // along the triangle's bisectors (a min of distances would).
            glm::dvec2 mid = (sup + inf + lat) / 3.0;
            double plate = 0.32 * smootherstep(-0.02, 0.16, lineDistance(p, sup, inf, mid)) *
                           smootherstep(-0.02, 0.16, lineDistance(p, inf, lat, mid)) *
                           smootherstep(-0.02, 0.16, lineDistance(p, lat, sup, mid));
            double v = screen(plate, ridgeAt(lateral, p));
            return screen(screen(v, ridgeAt(medial, p)), ridgeAt(spine, p));
        },
        0.07);
}

PatternInfo info(const char* id, PatternKind kind, const char* joint, const char* axis,
                 double thetaMin, double thetaMax, const char* description) {
    PatternInfo p;
    p.id = id;
    p.file = std::string(id) + ".png";
    p.kind = kind;
    p.model = defaultModel(kind);
    p.target = defaultTarget(kind);
    p.joint = joint;
    p.axis = axis;
    p.thetaMin = thetaMin;
    p.thetaMax = thetaMax;
    p.description = description;
    return p;
}

} // namespace

std::vector<PatternInfo> libraryInfo() {
    using K = PatternKind;
    return {
        info("stomach_wrinkles", K::Wrinkle, "spine", "x", 0, 45,
             "Horizontal stomach folds of unequal depth that deepen as the spine bends forward."),
        info("waist_twist", K::Wrinkle, "spine", "y", 0, 40,
             "Diagonal folds on the side of the waist as the torso twists; mirror for the other "
             "side."),
        info("crease", K::Wrinkle, "elbow", "x", 0, 120,
             "Inner elbow or back-of-knee crease: one deep curved fold with finer arcs beside it."),
        info("neck_rings", K::Wrinkle, "neck", "x", 0, 30,
             "Thin horizontal neck rings that appear as the head tilts forward."),
        info("round_bulge", K::Bulge, "elbow", "x", 0, 120,
             "Round muscle bulge (biceps) that swells as the elbow flexes."),
        info("elongated_bulge", K::Bulge, "hip", "x", 0, 90,
             "Elongated bulge along the thigh, wider toward the hip, as the hip flexes."),
        info("clavicle", K::Bone, "shoulder", "z", 0, 90,
             "S-curved clavicle ridge that shows from the crest outward as the arm rises."),
        info("ribs", K::Bone, "chest", "x", 0, 30,
             "Five curved rib ridges, fading toward the sternum, revealed as the chest arches."),
        info("scapula", K::Bone, "shoulder", "y", 0, 60,
             "Scapula: spine and medial border ridges over a low plate, as the arm swings back."),
    };
}

HeightImage generatePattern(const std::string& id, int size) {
    assert(size >= 16);
    if (id == "stomach_wrinkles") return stomachWrinkles(size);
    if (id == "waist_twist") return waistTwist(size);
    if (id == "crease") return crease(size);
    if (id == "neck_rings") return neckRings(size);
    if (id == "round_bulge") return roundBulge(size);
    if (id == "elongated_bulge") return elongatedBulge(size);
    if (id == "clavicle") return clavicle(size);
    if (id == "ribs") return ribs(size);
    if (id == "scapula") return scapula(size);
    assert(false && "unknown pattern id");
    return {};
}

std::vector<GeneratedPattern> generateLibrary(int size) {
    std::vector<GeneratedPattern> out;
    for (PatternInfo& p : libraryInfo()) {
        HeightImage img = generatePattern(p.id, size);
        out.push_back({std::move(p), std::move(img)});
    }
    return out;
}

} // namespace dermis::patterngen
