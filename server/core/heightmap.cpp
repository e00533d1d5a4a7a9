// CPU reference of the height-map stage (paper §4 first stage, SPEC §2 "Height maps").
#include "heightmap.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <thread>

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

    // Per-placement constants; placements at t = 0 contribute nothing and are dropped.
    struct Active {
        const BakePlacement* p;
        TexelRect rect;
        float h, k;
        double cosA, sinA;
        HeightImage* out;
    };
    std::vector<Active> active;
    for (const BakePlacement& p : placements) {
        if (p.t <= 0.0) continue;
        const double a = glm::radians(p.footprint.rotationDeg);
        active.push_back({&p, footprintTexels(p.footprint, W, H), static_cast<float>(p.h),
                          deformConstant(p.model, p.response, p.t), std::cos(a), std::sin(a),
                          p.target == Target::Bump ? &maps.bump : &maps.displacement});
    }

    // Rows [y0, y1): base first, then each placement in document order, so every texel's sum
    // has the same order whatever the split.
    auto bakeRows = [&](int y0, int y1) {
        const std::size_t first = static_cast<std::size_t>(y0) * W,
                          last = static_cast<std::size_t>(y1) * W;
        std::fill(maps.bump.data.begin() + first, maps.bump.data.begin() + last, 0.0f);
        std::fill(maps.displacement.data.begin() + first, maps.displacement.data.begin() + last,
                  0.0f);
        if (base) {
            const bool same = base->width == W && base->height == H;
            for (int j = y0; j < y1; ++j)
                for (int i = 0; i < W; ++i)
                    maps.bump.at(i, j) =
                        same ? base->at(i, j) : sampleBilinear(*base, (i + 0.5) / W, (j + 0.5) / H);
        }
        for (const Active& a : active) {
            const BakePlacement& p = *a.p;
            const glm::dvec2 c = p.footprint.center, sc = p.footprint.scale;
            const int r0 = std::max(y0, a.rect.y0), r1 = std::min(y1, a.rect.y1);
            for (int j = r0; j < r1; ++j) {
                const double dv = (j + 0.5) / H - c.y;
                float* row = &a.out->data[static_cast<std::size_t>(j) * W];
                // Along the row s is linear in i: visit only the span where both coordinates
                // can be in [0, 1] (widened by a texel; the inside test below stays exact).
                const double du0 = 0.5 / W - c.x;
                const double ax = (a.cosA * du0 + a.sinA * dv) / sc.x + 0.5,
                             bx = a.cosA / (W * sc.x);
                const double ay = (-a.sinA * du0 + a.cosA * dv) / sc.y + 0.5,
                             by = -a.sinA / (W * sc.y);
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
                const int i0 = static_cast<int>(lo), i1 = static_cast<int>(std::max(lo, hi));
                for (int i = i0; i < i1; ++i) {
                    const double du = (i + 0.5) / W - c.x;
                    // s = R(−rotation)·(p − c)/scale + 0.5 (same arithmetic as toPattern).
                    const glm::dvec2 s((a.cosA * du + a.sinA * dv) / sc.x + 0.5,
                                       (-a.sinA * du + a.cosA * dv) / sc.y + 0.5);
                    if (!insideUnit(s)) continue;
                    const float L = sampleBilinear(*p.pattern, s.x, s.y);
                    row[i] += applyDeform(p.model, L, a.h, p.t, a.k);
                }
            }
        }
    };

    int threads = settings.threads > 0 ? settings.threads
                                       : static_cast<int>(std::thread::hardware_concurrency());
    threads = std::clamp(threads, 1, std::max(1, H));
    if (threads == 1) {
        bakeRows(0, H);
    } else {
        std::vector<std::thread> pool;
        pool.reserve(threads);
        for (int t = 0; t < threads; ++t) {
            const int y0 = static_cast<int>(static_cast<long long>(H) * t / threads);
            const int y1 = static_cast<int>(static_cast<long long>(H) * (t + 1) / threads);
            pool.emplace_back(bakeRows, y0, y1);
        }
        for (auto& th : pool)
            th.join();
    }
    return Ok{};
}

Result<HeightMaps> bakeHeightMaps(const std::vector<BakePlacement>& placements,
                                  const BakeSettings& settings) {
    HeightMaps maps;
    if (auto s = bakeHeightMapsInto(placements, settings, maps); !s) return s.error();
    return maps;
}

} // namespace dermis
