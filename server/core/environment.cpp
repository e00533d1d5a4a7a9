// Image-based lighting on the CPU. See environment.hpp for the conventions and the methods.
#include "environment.hpp"

#include "row_bands.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

namespace dermis {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr float kPiF = static_cast<float>(kPi);

/// GGX samples per output texel of a specular level ≥ 1: about kLevelLookups lookups per level,
/// at least kMinSamples and at most kMaxSamples per texel (environment.hpp).
constexpr int kLevelLookups = 1 << 18, kMinSamples = 128, kMaxSamples = 2048;

std::size_t texelCount(int w, int h) {
    return static_cast<std::size_t>(w) * h;
}

bool wellFormed(const EnvironmentImage& img) {
    return img.width > 0 && img.height > 0 &&
           img.texels.size() == texelCount(img.width, img.height);
}

EnvironmentImage blank(int w, int h) {
    EnvironmentImage img;
    img.width = w;
    img.height = h;
    img.texels.assign(texelCount(w, h), glm::vec3(0.0f));
    return img;
}

/// Solid angle of one texel of row j in a w × h equirectangular image (exact band area).
double texelSolidAngle(int j, int w, int h) {
    const double top = kPi * (0.5 - static_cast<double>(j) / h);
    const double bottom = kPi * (0.5 - static_cast<double>(j + 1) / h);
    return (2.0 * kPi / w) * (std::sin(top) - std::sin(bottom));
}

/// Direction of the centre of texel (i, j) of a w × h image.
glm::vec3 texelDirection(int i, int j, int w, int h) {
    return equirectDirection(
        glm::vec2((static_cast<float>(i) + 0.5f) / static_cast<float>(w),
                  1.0f - (static_cast<float>(j) + 0.5f) / static_cast<float>(h)));
}

/// Bilinear lookup at (u, v_up) (wrap in u, clamp in rows); `img` well formed.
glm::vec3 bilinear(const EnvironmentImage& img, glm::vec2 uvUp) {
    const float x = uvUp.x * static_cast<float>(img.width) - 0.5f;
    const float y = (1.0f - uvUp.y) * static_cast<float>(img.height) - 0.5f;
    const float x0f = std::floor(x), y0f = std::floor(y);
    const float fx = x - x0f, fy = y - y0f;
    auto wrap = [w = img.width](long i) { return static_cast<int>(((i % w) + w) % w); };
    auto clampRow = [h = img.height](long j) {
        return static_cast<int>(std::clamp<long>(j, 0, h - 1));
    };
    const long x0 = static_cast<long>(x0f), y0 = static_cast<long>(y0f);
    const int i0 = wrap(x0), i1 = wrap(x0 + 1), j0 = clampRow(y0), j1 = clampRow(y0 + 1);
    const glm::vec3 top = glm::mix(img.at(i0, j0), img.at(i1, j0), fx);
    const glm::vec3 bottom = glm::mix(img.at(i0, j1), img.at(i1, j1), fx);
    return glm::mix(top, bottom, fy);
}

/// Overlap weights of a box resampling from n source cells to m ≤ n target cells: target k
/// covers source cells first[k] … first[k] + count[k] − 1, by weight[start[k] + c] of cell
/// first[k] + c (the overlap's length, in source cells).
struct BoxWeights {
    std::vector<int> first, count;
    std::vector<std::size_t> start;
    std::vector<double> weight;
};

BoxWeights boxWeights(int n, int m) {
    BoxWeights b;
    const double step = static_cast<double>(n) / m;
    for (int k = 0; k < m; ++k) {
        const double lo = k * step, hi = (k + 1) * step;
        const int first = static_cast<int>(std::floor(lo));
        const int last = std::min(n - 1, static_cast<int>(std::ceil(hi)) - 1);
        b.first.push_back(first);
        b.count.push_back(last - first + 1);
        b.start.push_back(b.weight.size());
        for (int s = first; s <= last; ++s)
            b.weight.push_back(std::min(hi, s + 1.0) - std::max(lo, static_cast<double>(s)));
    }
    return b;
}

/// `src` box-filtered down to w × h (w ≤ src.width, h ≤ src.height): each target texel is the
/// solid-angle-weighted mean of the source area it covers (partial texels by their overlap).
EnvironmentImage downsample(const EnvironmentImage& src, int w, int h) {
    const BoxWeights bx = boxWeights(src.width, w), by = boxWeights(src.height, h);
    // Horizontal pass: each source row to w columns (plain means: a row has one solid angle).
    std::vector<glm::dvec3> rows(texelCount(w, src.height));
    for (int j = 0; j < src.height; ++j)
        for (int i = 0; i < w; ++i) {
            glm::dvec3 sum(0.0);
            double wsum = 0.0;
            for (int c = 0; c < bx.count[i]; ++c) {
                const double wt = bx.weight[bx.start[i] + c];
                sum += wt * glm::dvec3(src.at(bx.first[i] + c, j));
                wsum += wt;
            }
            rows[texelCount(w, j) + i] = sum / wsum;
        }
    // Vertical pass, weighted by overlap × the source row's solid angle.
    std::vector<double> rowArea(src.height);
    for (int j = 0; j < src.height; ++j)
        rowArea[j] = texelSolidAngle(j, 1, src.height);
    EnvironmentImage out = blank(w, h);
    for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i) {
            glm::dvec3 sum(0.0);
            double wsum = 0.0;
            for (int c = 0; c < by.count[j]; ++c) {
                const int sj = by.first[j] + c;
                const double wt = by.weight[by.start[j] + c] * rowArea[sj];
                sum += wt * rows[texelCount(w, sj) + i];
                wsum += wt;
            }
            out.texels[texelCount(w, j) + i] = glm::vec3(sum / wsum);
        }
    return out;
}

/// `src` at w × h: box-filtered when that shrinks both sides, else bilinear at texel centres.
EnvironmentImage resample(const EnvironmentImage& src, int w, int h) {
    if (w == src.width && h == src.height) return src;
    if (w <= src.width && h <= src.height) return downsample(src, w, h);
    EnvironmentImage out = blank(w, h);
    for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i)
            out.texels[texelCount(w, j) + i] = sampleEquirect(src, texelDirection(i, j, w, h));
    return out;
}

/// Van der Corput radical inverse in base 2 (the second Hammersley coordinate).
float radicalInverse(std::uint32_t bits) {
    bits = (bits << 16u) | (bits >> 16u);
    bits = ((bits & 0x55555555u) << 1u) | ((bits & 0xAAAAAAAAu) >> 1u);
    bits = ((bits & 0x33333333u) << 2u) | ((bits & 0xCCCCCCCCu) >> 2u);
    bits = ((bits & 0x0F0F0F0Fu) << 4u) | ((bits & 0xF0F0F0F0u) >> 4u);
    bits = ((bits & 0x00FF00FFu) << 8u) | ((bits & 0xFF00FF00u) >> 8u);
    return static_cast<float>(static_cast<double>(bits) * 2.3283064365386963e-10);
}

/// GGX half vector around +Z for Hammersley point k of n, α = roughness² (the Khronos sample
/// viewer's importanceSample): φ = 2π·k/n, cos θ = √((1 − ξ)/(1 + (α² − 1)ξ)).
glm::vec3 ggxHalfVector(int k, int n, float alpha) {
    const float phi = 2.0f * kPiF * static_cast<float>(k) / static_cast<float>(n);
    const float xi = radicalInverse(static_cast<std::uint32_t>(k));
    const float cosTheta =
        std::clamp(std::sqrt((1.0f - xi) / (1.0f + (alpha * alpha - 1.0f) * xi)), 0.0f, 1.0f);
    const float sinTheta = std::sqrt(std::max(0.0f, 1.0f - cosTheta * cosTheta));
    return {sinTheta * std::cos(phi), sinTheta * std::sin(phi), cosTheta};
}

/// GGX normal distribution D(N·H) for α.
float ggxD(float nDotH, float alpha) {
    const float a2 = alpha * alpha;
    const float f = nDotH * nDotH * (a2 - 1.0f) + 1.0f;
    return a2 / (kPiF * f * f);
}

/// The source and its box-filtered mips (each half the previous, down to 4 × 2).
struct MipChain {
    std::vector<EnvironmentImage> mips;

    explicit MipChain(const EnvironmentImage& src) {
        mips.push_back(src);
        while (mips.back().width > 4 && mips.back().height > 2) {
            const EnvironmentImage& last = mips.back();
            mips.push_back(
                downsample(last, std::max(1, last.width / 2), std::max(1, last.height / 2)));
        }
    }

    /// Trilinear lookup at (u, v_up) and fractional mip level `lod` (clamped to the chain).
    glm::vec3 lookup(glm::vec2 uvUp, float lod) const {
        const float top = static_cast<float>(mips.size() - 1);
        lod = std::clamp(lod, 0.0f, top);
        const int m0 = static_cast<int>(lod);
        const float t = lod - static_cast<float>(m0);
        const glm::vec3 a = bilinear(mips[m0], uvUp);
        if (t <= 0.0f || m0 + 1 >= static_cast<int>(mips.size())) return a;
        return glm::mix(a, bilinear(mips[m0 + 1], uvUp), t);
    }
};

/// One GGX sample of a level in the frame of N: L's components along (T, B, N), its weight N·L
/// and its lookup lod.
struct SpecularSample {
    glm::vec3 l;
    float weight, lod;
};

std::vector<SpecularSample> specularSamples(float roughness, int count, int srcWidth,
                                            int srcHeight) {
    const float alpha = roughness * roughness;
    const double texelAngle = (2.0 * kPi / srcWidth) * (kPi / srcHeight); // Ωp
    std::vector<SpecularSample> out;
    for (int k = 0; k < count; ++k) {
        const glm::vec3 h = ggxHalfVector(k, count, alpha);
        // L = reflect(−N, H) = 2(N·H)H − N with N = +Z.
        const glm::vec3 l(2.0f * h.z * h.x, 2.0f * h.z * h.y, 2.0f * h.z * h.z - 1.0f);
        if (l.z <= 0.0f) continue;
        const double pdf = ggxD(h.z, alpha) / 4.0;      // D·(N·H)/(4·V·H) with V = N
        const double sampleAngle = 1.0 / (count * pdf); // Ωs
        const double lod = std::max(0.0, 0.5 * std::log2(sampleAngle / texelAngle));
        out.push_back({glm::normalize(l), l.z, static_cast<float>(lod)});
    }
    return out;
}

/// Level of roughness `roughness` at w × h, filtered from `chain`.
EnvironmentImage specularLevel(const MipChain& chain, float roughness, int w, int h) {
    const std::vector<SpecularSample> samples =
        specularSamples(roughness, std::clamp(kLevelLookups / (w * h), kMinSamples, kMaxSamples),
                        chain.mips[0].width, chain.mips[0].height);
    EnvironmentImage out = blank(w, h);
    const auto rows = [&](int j0, int j1) {
        for (int j = j0; j < j1; ++j)
            for (int i = 0; i < w; ++i) {
                const glm::vec3 n = texelDirection(i, j, w, h);
                // Texel centres are never at a pole, so Y up gives a frame.
                const glm::vec3 t = glm::normalize(glm::cross(glm::vec3(0.0f, 1.0f, 0.0f), n));
                const glm::vec3 b = glm::cross(n, t);
                glm::vec3 sum(0.0f);
                float wsum = 0.0f;
                for (const SpecularSample& s : samples) {
                    const glm::vec3 l = s.l.x * t + s.l.y * b + s.l.z * n;
                    sum += s.weight * chain.lookup(equirectUv(l), s.lod);
                    wsum += s.weight;
                }
                out.texels[texelCount(w, j) + i] = wsum > 0.0f ? sum / wsum : glm::vec3(0.0f);
            }
    };
    // Rows are independent: bands of them on up to 8 threads (the same texels as one thread).
    forRowBands(h, std::min(8, automaticThreadCount()), [&](int, int y0, int y1) { rows(y0, y1); });
    return out;
}

/// The 9 real SH basis functions at unit direction d (order of PrefilteredEnvironment).
std::array<double, 9> shBasis(glm::dvec3 d) {
    const double c0 = 0.5 / std::sqrt(kPi), c1 = std::sqrt(3.0) * c0, c2 = std::sqrt(15.0) * c0,
                 c3 = 0.25 * std::sqrt(5.0 / kPi), c4 = 0.5 * c2;
    const double x = d.x, y = d.y, z = d.z;
    return {c0,
            c1 * y,
            c1 * z,
            c1 * x,
            c2 * x * y,
            c2 * y * z,
            c3 * (3.0 * z * z - 1.0),
            c2 * x * z,
            c4 * (x * x - y * y)};
}

std::array<glm::vec3, 9> irradianceSh(const EnvironmentImage& env) {
    std::array<glm::dvec3, 9> acc{};
    for (int j = 0; j < env.height; ++j) {
        const double area = texelSolidAngle(j, env.width, env.height);
        for (int i = 0; i < env.width; ++i) {
            const std::array<double, 9> y =
                shBasis(glm::dvec3(texelDirection(i, j, env.width, env.height)));
            const glm::dvec3 radiance = area * glm::dvec3(env.at(i, j));
            for (int k = 0; k < 9; ++k)
                acc[k] += y[k] * radiance;
        }
    }
    // Clamped-cosine convolution Â_l = π, 2π/3, π/4, then / π.
    const double band[9] = {1.0, 2.0 / 3.0, 2.0 / 3.0, 2.0 / 3.0, 0.25, 0.25, 0.25, 0.25, 0.25};
    std::array<glm::vec3, 9> sh{};
    for (int k = 0; k < 9; ++k)
        sh[k] = glm::vec3(acc[k] * band[k]);
    return sh;
}

/// A soft rectangle facing the origin, centred on unit `c`, half-extents (a, b) in tangents of
/// the half-angles along (right, up) of c: its coverage ∈ [0, 1] in direction d.
float softRect(glm::vec3 d, glm::vec3 c, float a, float b) {
    constexpr float kSoft = 0.08f;
    const float dc = glm::dot(d, c);
    if (dc <= 0.0f) return 0.0f;
    const glm::vec3 right = glm::normalize(glm::cross(c, glm::vec3(0.0f, 1.0f, 0.0f)));
    const glm::vec3 up = glm::cross(right, c);
    const glm::vec3 p = d / dc - c; // point on the plane tangent at c, in tangent units
    auto edge = [](float t, float half) {
        return 1.0f - glm::smoothstep(half - kSoft, half + kSoft, std::abs(t));
    };
    return edge(glm::dot(p, right), a) * edge(glm::dot(p, up), b);
}

float studioRadiance(glm::vec3 d) {
    const float sky = glm::mix(0.55f, 0.85f, std::max(d.y, 0.0f));
    const float ground = glm::mix(0.20f, 0.12f, std::max(-d.y, 0.0f));
    float l = glm::mix(ground, sky, glm::smoothstep(-0.1f, 0.1f, d.y));
    struct Light {
        glm::vec3 centre;
        float a, b, radiance;
    };
    static const Light lights[3] = {
        {glm::normalize(glm::vec3(-0.5f, 0.6f, 0.6f)), 0.45f, 0.35f, 6.0f},    // key
        {glm::normalize(glm::vec3(1.0f, 0.15f, 0.35f)), 0.35f, 0.35f, 1.5f},   // fill
        {glm::normalize(glm::vec3(0.25f, 0.45f, -0.85f)), 0.20f, 0.40f, 3.0f}, // rim
    };
    for (const Light& light : lights)
        l = glm::mix(l, light.radiance, softRect(d, light.centre, light.a, light.b));
    return l;
}

} // namespace

glm::vec2 equirectUv(glm::vec3 d) {
    return {std::atan2(d.z, d.x) / (2.0f * kPiF) + 0.5f,
            std::asin(std::clamp(d.y, -1.0f, 1.0f)) / kPiF + 0.5f};
}

glm::vec3 equirectDirection(glm::vec2 uvUp) {
    const float phi = 2.0f * kPiF * (uvUp.x - 0.5f);
    const float theta = kPiF * (std::clamp(uvUp.y, 0.0f, 1.0f) - 0.5f);
    const float c = std::cos(theta);
    return {c * std::cos(phi), std::sin(theta), c * std::sin(phi)};
}

EnvironmentImage studioEnvironment(int width) {
    const int w = std::clamp(width, 8, 8192), h = w / 2;
    EnvironmentImage env = blank(w, h);
    for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i)
            env.texels[texelCount(w, j) + i] =
                glm::vec3(studioRadiance(texelDirection(i, j, w, h)));
    return env;
}

Status validateEnvironment(const EnvironmentImage& env) {
    const char* where = "dermis::validateEnvironment";
    if (env.width < 2)
        return makeError(ErrorCode::InvalidArgument, where, "width",
                         "must be >= 2, got " + std::to_string(env.width));
    if (env.height < 2)
        return makeError(ErrorCode::InvalidArgument, where, "height",
                         "must be >= 2, got " + std::to_string(env.height));
    const std::size_t n = texelCount(env.width, env.height);
    if (env.texels.size() != n)
        return makeError(ErrorCode::InvalidArgument, where, "texels",
                         "has " + std::to_string(env.texels.size()) +
                             " texels, expected width*height = " + std::to_string(n));
    for (std::size_t k = 0; k < n; ++k) {
        const glm::vec3& t = env.texels[k];
        for (int c = 0; c < 3; ++c)
            if (!std::isfinite(t[c]) || t[c] < 0.0f)
                return makeError(ErrorCode::InvalidArgument, where,
                                 "texels[" + std::to_string(k) + "]",
                                 "radiance must be finite and >= 0, got " + std::to_string(t[c]));
    }
    return Ok{};
}

PrefilteredEnvironment prefilterEnvironment(const EnvironmentImage& env, int levels,
                                            int baseWidth) {
    PrefilteredEnvironment out;
    if (!validateEnvironment(env).ok()) return out;
    levels = std::clamp(levels, 1, 16);
    baseWidth = std::clamp(baseWidth, 8, 16384);
    out.irradianceSh = irradianceSh(env);
    const MipChain chain(env);
    for (int k = 0; k < levels; ++k) {
        const int w = std::max(8, baseWidth >> k), h = std::max(4, w / 2);
        if (k == 0) {
            out.specular.push_back(resample(env, w, h));
            continue;
        }
        const float roughness = static_cast<float>(k) / static_cast<float>(levels - 1);
        out.specular.push_back(specularLevel(chain, roughness, w, h));
    }
    return out;
}

glm::vec3 evalIrradiance(const std::array<glm::vec3, 9>& sh, glm::vec3 n) {
    const std::array<double, 9> y = shBasis(glm::dvec3(n));
    glm::dvec3 e(0.0);
    for (int k = 0; k < 9; ++k)
        e += y[k] * glm::dvec3(sh[k]);
    return glm::max(glm::vec3(e), glm::vec3(0.0f));
}

glm::vec3 sampleEquirect(const EnvironmentImage& img, glm::vec3 d) {
    const glm::vec2 uv = equirectUv(d);
    if (!wellFormed(img) || !std::isfinite(uv.x) || !std::isfinite(uv.y)) return glm::vec3(0.0f);
    return bilinear(img, uv);
}

std::vector<glm::vec2> brdfLut(int size, int samples) {
    if (size < 1 || size > 1024 || samples < 1 || samples > 65536) return {};
    std::vector<glm::vec2> lut(texelCount(size, size));
    for (int j = 0; j < size; ++j) {
        const double r = (j + 0.5) / size, alpha = r * r, a2 = alpha * alpha;
        for (int i = 0; i < size; ++i) {
            const double nDotV = (i + 0.5) / size;
            const glm::dvec3 v(std::sqrt(1.0 - nDotV * nDotV), 0.0, nDotV);
            double scale = 0.0, bias = 0.0;
            for (int k = 0; k < samples; ++k) {
                const glm::dvec3 h(ggxHalfVector(k, samples, static_cast<float>(alpha)));
                const double vDotH = glm::dot(v, h);
                const glm::dvec3 l = 2.0 * vDotH * h - v; // reflect(−V, H)
                const double nDotL = std::clamp(l.z, 0.0, 1.0);
                const double nDotH = std::clamp(h.z, 0.0, 1.0);
                if (nDotL <= 0.0 || nDotH <= 0.0) continue;
                const double vis = 0.5 / (nDotL * std::sqrt(nDotV * nDotV * (1.0 - a2) + a2) +
                                          nDotV * std::sqrt(nDotL * nDotL * (1.0 - a2) + a2));
                const double w = 4.0 * vis * std::clamp(vDotH, 0.0, 1.0) * nDotL / nDotH;
                const double fc = std::pow(1.0 - std::clamp(vDotH, 0.0, 1.0), 5.0);
                scale += (1.0 - fc) * w;
                bias += fc * w;
            }
            lut[texelCount(size, j) + i] =
                glm::vec2(static_cast<float>(scale / samples), static_cast<float>(bias / samples));
        }
    }
    return lut;
}

glm::vec3 toneMapPbrNeutral(glm::vec3 color) {
    const float startCompression = 0.8f - 0.04f;
    const float desaturation = 0.15f;
    const float x = std::min(color.r, std::min(color.g, color.b));
    const float offset = x < 0.08f ? x - 6.25f * x * x : 0.04f;
    color -= offset;
    const float peak = std::max(color.r, std::max(color.g, color.b));
    if (peak < startCompression) return color;
    const float d = 1.0f - startCompression;
    const float newPeak = 1.0f - d * d / (peak + d - startCompression);
    color *= newPeak / peak;
    const float g = 1.0f - 1.0f / (desaturation * (peak - newPeak) + 1.0f);
    return glm::mix(color, glm::vec3(newPeak), g);
}

glm::vec3 toneMapAcesFilmic(glm::vec3 linear) {
    // Column-major as GLSL: the same constructors as three.js's tonemapping_pars_fragment.
    const glm::mat3 inputMat(glm::vec3(0.59719f, 0.07600f, 0.02840f),
                             glm::vec3(0.35458f, 0.90834f, 0.13383f),
                             glm::vec3(0.04823f, 0.01566f, 0.83777f));
    const glm::mat3 outputMat(glm::vec3(1.60475f, -0.10208f, -0.00327f),
                              glm::vec3(-0.53108f, 1.10813f, -0.07276f),
                              glm::vec3(-0.07367f, -0.00605f, 1.07602f));
    glm::vec3 c = inputMat * (linear / 0.6f);
    const glm::vec3 a = c * (c + 0.0245786f) - 0.000090537f;
    const glm::vec3 b = c * (0.983729f * c + 0.4329510f) + 0.238081f;
    c = outputMat * (a / b);
    return glm::clamp(c, 0.0f, 1.0f);
}

} // namespace dermis
