// Dermis core — image-based lighting on the CPU: the default studio environment, its split-sum
// prefiltering (Karis 2013, "Real Shading in Unreal Engine 4", as the Khronos glTF-Sample-Viewer's
// IBL does it), the DFG table, and CPU mirrors of the shader's lookups and tone mappers.
//
// Pure and deterministic (no random numbers: the sample sets are Hammersley points); no GL, no
// image library, no file I/O. Loading an environment from a file is the io layer's job; uploading
// it is the renderer's (server/gl/pbr_pass.cpp, shaders/pbr.glsl).
//
// Conventions:
//   * An environment is an equirectangular image of linear-RGB radiance, row 0 first (row 0 at
//     the top: straight up), width columns around the horizon.
//   * World directions are Y up. The mapping is three.js's (its GLSL `equirectUv`), so that a
//     side-by-side render with three.js and the same image lines up: for a unit direction d,
//         u    = atan2(d.z, d.x) / (2π) + 0.5          (∈ [0, 1]; wraps at −X)
//         v_up = asin(clamp(d.y, −1, 1)) / π + 0.5    (0 straight down, 1 straight up)
//         column = u·width,  row = (1 − v_up)·height   (texel centres at +0.5)
//     so +X is the middle column (u = 0.5), +Z is u = 0.75, −Z is u = 0.25, −X the left and right
//     edges, and straight up is row 0. A GL texture uploaded row 0 first is sampled at
//     (u, 1 − v_up), which is what shaders/pbr.glsl does.
//   * Solid angles are exact per texel row: a texel of row j covers
//     (2π/width)·(sin θ_top − sin θ_bottom) steradians, θ the latitude of the row's edges.
#pragma once

#include "result.hpp"

#include <glm/glm.hpp>

#include <array>
#include <cstddef>
#include <vector>

namespace dermis {

/// An equirectangular linear-RGB radiance image (conventions above).
struct EnvironmentImage {
    int width = 0, height = 0;
    std::vector<glm::vec3> texels; ///< width·height values, row 0 (the top) first

    const glm::vec3& at(int i, int j) const {
        return texels[static_cast<std::size_t>(j) * width + i];
    }
};

/// (u, v_up) of a direction, exactly three.js's `equirectUv`: u = atan2(d.z, d.x)/(2π) + 0.5,
/// v_up = asin(clamp(d.y, −1, 1))/π + 0.5. Note v_up counts UP from the bottom row; the texel row
/// is (1 − v_up)·height. `d` should be unit length (v_up reads d.y as a sine, as three.js does;
/// u does not depend on the length); the zero vector gives (0.5, 0.5). Non-finite input gives
/// non-finite output.
glm::vec2 equirectUv(glm::vec3 d);

/// The inverse of equirectUv: the unit direction at (u, v_up), with longitude φ = 2π(u − 0.5)
/// and latitude θ = π(v_up − 0.5): (cos θ cos φ, sin θ, cos θ sin φ). Any finite u works (it
/// wraps); v_up outside [0, 1] is clamped to the poles.
glm::vec3 equirectDirection(glm::vec2 uvUp);

/// The default neutral studio environment: what a frame is lit by when no environment is chosen.
/// Procedural, `width` × width/2 texels (width clamped to [8, 8192]), neutral grey linear
/// radiance (R = G = B everywhere):
///   * a dome: 0.55 at the horizon rising linearly in d.y to 0.85 straight up; a floor of 0.20
///     at the horizon falling to 0.12 straight down; the two blend over |d.y| < 0.1;
///   * a large soft rectangular key light of radiance 6 centred on normalize(−0.5, 0.6, 0.6):
///     above, in front (+Z) and to the left (−X). Seen from a camera on +Z looking towards −Z it
///     comes from the upper left of the picture, so a character facing the camera (+Z) is lit on
///     the picture's left side (the character's right);
///   * a weaker fill of radiance 1.5 from the right: centred on normalize(1, 0.15, 0.35);
///   * a rim light of radiance 3 from behind, raised and a little to the right: centred on
///     normalize(0.25, 0.45, −0.85).
/// Each light is a flat rectangle facing the origin (half-extents given as tangents of the
/// half-angles: key 0.45 × 0.35, fill 0.35 × 0.35, rim 0.2 wide × 0.4 tall) with edges softened
/// over ±0.08 (smoothstep); a light replaces the dome behind it. The mean radiance over the
/// sphere is ≈ 0.75 (0.746 at width 256), so a white Lambert surface facing any way reads
/// mid-bright. Texels are evaluated at their centres (no supersampling: the soft edges are wider
/// than a texel for any width ≥ 64).
EnvironmentImage studioEnvironment(int width = 256);

/// Checks an environment image: width and height ≥ 2 (field "width" / "height"; 2:1 is not
/// required), texels.size() == width·height (field "texels"), every component finite and ≥ 0
/// (field "texels[k]", k the texel index). Fails with InvalidArgument naming
/// "dermis::validateEnvironment". Does not limit the size (the loader that made it does).
Status validateEnvironment(const EnvironmentImage& env);

/// The split-sum image-based light of one environment.
struct PrefilteredEnvironment {
    /// Order-2 real SH coefficients of the cosine-convolved radiance divided by π, so that the
    /// Lambert diffuse radiance of a surface with normal n is albedo · evalIrradiance(sh, n).
    /// Basis order (the constants of evalIrradiance and shaders/pbr.glsl; world x, y, z with Y
    /// up): 0: 0.282095; 1: 0.488603·y; 2: 0.488603·z; 3: 0.488603·x; 4: 1.092548·xy;
    /// 5: 1.092548·yz; 6: 0.315392·(3z² − 1); 7: 1.092548·xz; 8: 0.546274·(x² − y²).
    std::array<glm::vec3, 9> irradianceSh{};
    /// Level k: the GGX-prefiltered radiance for perceptual roughness k/(levels − 1) (α = r²),
    /// under the split-sum's N = V = R assumption; level 0 is the mirror image (the source
    /// area-averaged to the base size). Level k is max(8, baseWidth >> k) × max(4, width/2).
    std::vector<EnvironmentImage> specular;
};

/// Prefilters `env` for the split-sum IBL.
///   * Irradiance: every source texel, weighted by its exact solid angle, is projected onto the
///     9 SH basis functions; band l is then multiplied by the clamped-cosine convolution factor
///     Â_l = π, 2π/3, π/4 (Ramamoorthi & Hanrahan 2001, "An Efficient Representation for
///     Irradiance Environment Maps") and divided by π. Exact (to the texel quadrature) when the
///     radiance has no even band ≥ 4 (Â_l is 0 for odd l ≥ 3): a uniform environment, a sky
///     dome (radiance above the horizon only), any polynomial of degree ≤ 3 in d.
///   * Specular, levels ≥ 1: for each output texel direction N (= V = R), n GGX half vectors H
///     at Hammersley points (the Khronos sample viewer's `importanceSample` for GGX, α = r²),
///     L = reflect(−N, H), weighted by N·L (samples with N·L ≤ 0 dropped), each read with
///     filtered importance sampling (Colbert & Křivánek, GPU Gems 3 ch. 20): a trilinear lookup
///     in a box-filtered mip chain of the source at lod = max(0, ½·log2(Ωs/Ωp)), where
///     Ωs = 1/(n·pdf), pdf = D(N·H)/4 the density of L, and Ωp = (2π/width)(π/height) the solid
///     angle of a source texel at the equator. No lod bias: of 0, ½ and 1 (GPU Gems' +1), 0
///     comes closest to a brute-force convolution. n = clamp(2^18 / (texels of the level), 128,
///     2048), so the small rough levels get many samples. Against a brute-force convolution of
///     the source with the same kernel (D(h)·N·L) the studio environment's levels are within
///     3.5 % per texel at level 1 (r = 0.2), 1.5 % at level 2 and 1 % at levels 3–5. The kernel
///     is the same around every N, so the sphere's mean radiance is kept (to the sampling
///     error: < 0.5 % for the studio).
/// Levels are clamped to [1, 16] and baseWidth to [8, 16384]; `levels` = 1 gives the mirror
/// level only. Cost: O(source texels) for the SH and the mips, plus texels × n trilinear lookups
/// per level ≥ 1 (≈ 2^18; more for a level over 2048 texels, fewer under 128): ≈ 0.1 s on one
/// core for studioEnvironment(256) and the defaults. A level's rows are shared by up to 8
/// threads (hardware_concurrency; one when no thread can start); the result does not depend on
/// their number.
/// Does not fail: an `env` that fails validateEnvironment gives an empty result (all SH zero,
/// no specular levels) — validate first to learn why.
PrefilteredEnvironment prefilterEnvironment(const EnvironmentImage& env, int levels = 6,
                                            int baseWidth = 128);

/// Σ sh[k]·Y_k(n) with the basis of PrefilteredEnvironment::irradianceSh, each component
/// clamped to ≥ 0 (order-2 SH rings below zero opposite a strong light; the shader clamps the
/// same way). `n` unit length. The CPU mirror of shaders/pbr.glsl `irradiance`.
glm::vec3 evalIrradiance(const std::array<glm::vec3, 9>& sh, glm::vec3 n);

/// Bilinear lookup of `img` in direction `d` (equirectUv; texel centres at +0.5), wrapping in u
/// and clamping in rows, as a GL texture with REPEAT in s, CLAMP_TO_EDGE in t and LINEAR filtering
/// samples it — the CPU mirror of the shader's lookup of one specular level. Returns 0 for an
/// image that is empty or whose texels do not match its size, and for a non-finite `d`.
glm::vec3 sampleEquirect(const EnvironmentImage& img, glm::vec3 d);

/// The split-sum DFG table: size × size (scale, bias) pairs, row-major with the row the
/// perceptual-roughness index: entry [j·size + i] is for N·V = (i + 0.5)/size and roughness
/// r = (j + 0.5)/size (texel centres), such that specular = prefiltered · (F0·scale + bias). As
/// the Khronos sample viewer's `LUT` for GGX: `samples` Hammersley GGX half vectors around
/// N = +Z with α = r², V = (√(1 − N·V²), 0, N·V), L = reflect(−V, H), and for N·L > 0
///     Vis = V_SmithGGXCorrelated = 0.5 / (N·L·√(N·V²(1 − α²) + α²) + N·V·√(N·L²(1 − α²) + α²)),
///     w = 4·Vis·V·H·N·L / N·H,  Fc = (1 − V·H)^5,
///     scale = Σ (1 − Fc)·w / samples,  bias = Σ Fc·w / samples.
/// scale + bias is the directional albedo of the specular lobe with F = 1 (≤ 1: single
/// scattering loses energy with roughness). With 256 samples the entries for roughness ≥ 0.2
/// are within ≈ 0.01 of the exact integral (≈ 0.02 towards grazing N·V); ≈ 10 ms for 32².
/// The sheen (`charlie`) part is not made.
/// Returns an empty vector when size is outside [1, 1024] or samples outside [1, 65536].
std::vector<glm::vec2> brdfLut(int size = 32, int samples = 256);

/// Khronos PBR Neutral tone mapping, the published reference algorithm
/// (github.com/KhronosGroup/ToneMapping, PBR_Neutral): startCompression = 0.8 − 0.04,
/// desaturation = 0.15; x = min(r, g, b), offset = x < 0.08 ? x − 6.25x² : 0.04, c −= offset;
/// if peak = max(c) < startCompression return c; else newPeak = 1 − d²/(peak + d −
/// startCompression) with d = 1 − startCompression, c *= newPeak/peak, and c is mixed towards
/// newPeak·(1,1,1) by g = 1 − 1/(desaturation·(peak − newPeak) + 1). So a grey 0.08 ≤ x < 0.8
/// becomes x − 0.04, a grey below 0.08 becomes 6.25x², and everything stays below 1. Input is
/// linear (exposure already applied) and ≥ 0, as the reference assumes; negative input is not
/// clamped. Output is linear (display encoding is the caller's).
glm::vec3 toneMapPbrNeutral(glm::vec3 linear);

/// three.js's ACESFilmicToneMapping (r150+, Stephen Hill's fit of the ACES RRT + ODT), with
/// toneMappingExposure = 1: c = linear / 0.6 (three.js's "brighter viewing environment" scale;
/// pass exposure·linear for another exposure), c = ACESInputMat·c, c = (c(c + 0.0245786) −
/// 0.000090537) / (c(0.983729c + 0.4329510) + 0.238081) per component, c = ACESOutputMat·c,
/// clamped to [0, 1]. The matrices are three.js's (rows of ACESInputMat: (0.59719, 0.35458,
/// 0.04823), (0.07600, 0.90834, 0.01566), (0.02840, 0.13383, 0.83777); rows of ACESOutputMat:
/// (1.60475, −0.53108, −0.07367), (−0.10208, 1.10813, −0.00605), (−0.00327, −0.07276, 1.07602)).
/// A grey 1.0 maps to ≈ 0.7634. Output is linear (display encoding is the caller's).
glm::vec3 toneMapAcesFilmic(glm::vec3 linear);

} // namespace dermis
