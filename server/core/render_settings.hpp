// Dermis core — a frame's render settings (SPEC §2b "render": size, camera, displacement,
// bump strength, anti-aliasing) and the one check of them: every shell that changes
// them (scene documents, frame query parameters, the command line's --size, the renderer's own
// entry) applies its overrides to a RenderSettings first and then calls this, so a range is
// written once.
//
// Pure. Does not check what only a GL knows (renderbuffer limits: the renderer adds that) and
// does not parse: types are the document parser's job.
#pragma once

#include "result.hpp"

#include <array>

#include <optional>
#include <string>
#include <string_view>

namespace dermis {

/// Largest frame side a scene document, a query or the command line may ask for.
constexpr int kMaxRenderSize = 8192;

struct Camera {
    double yaw = 0.0, pitch = 10.0;
    std::optional<double> distance; ///< absent = "auto"
    /// The world point looked at (and orbited about); absent = the centre of the posed bounds.
    /// Set by a frame's `target` query parameter (the editor's pan, frame-selection and
    /// orbit-about); not a member of the scene document.
    std::optional<std::array<double, 3>> target;
};

enum class DisplacementMode { Vertex, Tessellated };
std::string_view toString(DisplacementMode m);
std::optional<DisplacementMode> displacementModeFromString(std::string_view s);

/// How a frame is anti-aliased (`render.aa`). Auto: MSAA with `msaa` samples on a GPU, Post on a
/// software rasterizer (Mesa llvmpipe / softpipe), where MSAA 4 costs 2–2.6× the skin pass;
/// Msaa: always `msaa` samples (1 = none); Post: one full-screen edge pass (FXAA, shaders/
/// fxaa.frag) over a 1-sample frame; None: 1 sample, no pass. resolveAntiAliasing
/// (render_settings.hpp) is the one place Auto becomes a mode.
enum class AntiAliasing { Auto, Msaa, Post, None };
std::string_view toString(AntiAliasing a);
std::optional<AntiAliasing> antiAliasingFromString(std::string_view s);

/// How the skin pass shades (`render.shading`). Legacy: the base colour under one Blinn-Phong key
/// light and a hemisphere fill (the default until 2026-11-30; kept for comparisons). Pbr, the
/// default: the model's glTF metallic-roughness material (base colour, metallic-roughness,
/// normal, occlusion and emissive textures, alpha modes, vertex colours, KHR_texture_transform,
/// unlit) under image-based light from the default studio environment (core/environment.hpp),
/// with exposure and tone mapping.
/// Skin: pbr for previews of skin (issue #26), so that a wrinkle reads as it would on skin —
/// light scattered under the surface, approximated for image-based light: the irradiance's
/// spherical-harmonic bands 1 and 2 attenuated per channel as a Gaussian diffusion profile of
/// angular width kSkinScatterWidth blurs them (red widest), the diffuse normal of each channel
/// blended from the bumped normal towards the unbumped one by kSkinNormalBlend (red softest),
/// and a second, sharper specular lobe (roughness × kSkinSecondLobeRoughness, weight
/// kSkinSecondLobeWeight) for skin's oily sheen. The same inputs as pbr; a uniform environment
/// shades it as pbr does but for the second lobe (the scattering moves light, it adds none).
enum class Shading { Legacy, Pbr, Skin };

/// The skin shading's constants (shaders/pbr.glsl mirrors them; SkinShadingGLTest): σ per
/// channel (rgb, radians) of the Gaussian blur on the sphere of directions, whose SH band l is
/// attenuated by exp(−l(l+1)σ²/2); how far each channel's diffuse normal goes from the bumped
/// normal towards the unbumped one; the second lobe's roughness scale and weight.
constexpr double kSkinScatterWidth[3] = {0.55, 0.25, 0.12};
constexpr double kSkinNormalBlend[3] = {0.7, 0.35, 0.1};
constexpr double kSkinSecondLobeRoughness = 0.5;
constexpr double kSkinSecondLobeWeight = 0.15;
std::string_view toString(Shading s);
std::optional<Shading> shadingFromString(std::string_view s);

/// The display transform of `pbr` shading (`render.tone_mapping`): None clamps; Neutral is
/// Khronos PBR Neutral; Aces the ACES filmic fit three.js uses (ACESFilmicToneMapping).
enum class ToneMapping { None, Neutral, Aces };
std::string_view toString(ToneMapping t);
std::optional<ToneMapping> toneMappingFromString(std::string_view s);

/// Largest `render.exposure` (a linear scale of the light before tone mapping).
constexpr double kMaxExposure = 64.0;

/// A directional key light added to the image-based light of pbr and skin frames
/// (`render.key_light`, issue #26), with an optional shadow map: the sun or the studio lamp that
/// gives a wrinkle a hard side and a cast shadow, which an environment's soft light cannot.
/// Shades the `shaded` and `lighting` views of the pbr programs; legacy frames keep their own
/// camera-fixed key light and ignore this. Radiance as glTF's KHR_lights_punctual and three.js's
/// DirectionalLight give it: the surface receives intensity × colour × max(n·l, 0) (irradiance
/// in the environment's units; the studio's mean radiance ≈ 0.74 gives an irradiance of ≈ 2.3).
struct KeyLight {
    /// World space, from the surface towards the light (not normalised; not zero). The default
    /// is above, in front (+z) and to the left (−x) of a character facing +z.
    std::array<double, 3> direction{-0.5, 1.0, 0.6};
    double intensity = 3.0;                    ///< [0, kMaxKeyLightIntensity]
    std::array<double, 3> color{1.0, 1.0, 1.0}; ///< linear rgb, each in [0, 1]
    /// Shadows from a depth map of the posed, displaced character seen from the light
    /// (kKeyLightShadowMapSize², fitted to the character's bounding sphere; vertex displacement
    /// even in tessellated frames; glTF BLEND parts cast none, MASK parts by their cutoff).
    bool shadow = true;
    bool operator==(const KeyLight&) const = default;
};

/// Largest `render.key_light.intensity`.
constexpr double kMaxKeyLightIntensity = 100.0;
/// Side of the key light's shadow map (texels).
constexpr int kKeyLightShadowMapSize = 2048;

struct RenderSettings {
    std::array<int, 2> size{1024, 1024};
    Camera camera;
    std::optional<double> displacementScale; ///< absent = "auto"
    double bumpStrength = 1.0;
    int msaa = 4; ///< 1, 2 or 4: the samples when `aa` resolves to MSAA
    AntiAliasing aa = AntiAliasing::Auto;
    /// "vertex": displace the mesh's own vertices (the paper); "tessellated": subdivide each
    /// triangle on the GPU first, so that bulges smaller than a triangle still move the surface.
    DisplacementMode displacement = DisplacementMode::Vertex;
    Shading shading = Shading::Pbr; ///< legacy before 2026-11-30 (issue #26)
    double exposure = 1.0;                        ///< pbr: light × exposure before tone mapping
    ToneMapping toneMapping = ToneMapping::Neutral; ///< pbr only
    double environmentRotation = 0.0; ///< pbr: degrees the environment turns about +Y
    /// pbr and skin: the environment that lights the frame (`render.environment`). Empty or
    /// kBuiltinStudioEnvironment: the default studio (core/environment.hpp). Anything else is a
    /// name the shell resolves: an uploaded environment's id ("e_…") on a server, a file path
    /// relative to the scene document on the command line. Not checked here (a path or an id
    /// of ≤ kMaxPathLength bytes; the parser checks its form, the shell that it exists).
    std::string environment;
    /// pbr and skin: a directional key light with an optional shadow (`render.key_light`);
    /// absent: the environment alone (the default).
    std::optional<KeyLight> keyLight;
};

/// The default studio environment's name in `render.environment`.
inline constexpr const char* kBuiltinStudioEnvironment = "builtin:studio";

/// What a frame shows of the posed, displaced character (a frame's choice, like its camera
/// overrides: not part of scene documents). Shaded is the picture; the others are unlit
/// pictures of the maps on the surface for authoring: Bump and Displacement the height map's
/// channel as grey, byte = 128 + 127·clamp(height, −1, 1) (the inverse of SPEC §2's 8-bit
/// pattern mapping: height 0 is 128, ±1 is 255 / 1); Normal the bump-mapped world normal as
/// rgb, byte = 255·(n·0.5 + 0.5). Sizes, camera, MSAA and displacement are the same in every
/// view; the background is the shaded view's.
/// BaseColor and Lighting (issue #26) take the glTF material apart, lit or not by the pbr
/// shading's light whatever `render.shading` says: BaseColor the base colour (factor × texture ×
/// vertex colour, alpha-masked) as it is, unlit; Lighting the light alone on a white rough
/// dielectric with the model's normal map and the bump. Normal with `render.shading` "pbr" includes
/// the model's normal map.
enum class FrameView { Shaded, Bump, Displacement, Normal, BaseColor, Lighting };

/// "shaded", "bump", "displacement", "normal", "basecolor", "lighting".
std::string_view toString(FrameView v);
/// The view spelled `s` as toString writes it; nullopt for any other string (case-sensitive).
std::optional<FrameView> frameViewFromString(std::string_view s);

/// Limits a caller may tighten below the format's own (kMaxRenderSize).
struct RenderLimits {
    int maxSide = kMaxRenderSize; ///< a server's configured limit (≤ kMaxRenderSize)
};

/// What a frame's anti-aliasing resolves to: the samples of its colour target and whether the
/// post-process edge pass runs after it (never both: Post and None draw one sample).
struct ResolvedAntiAliasing {
    AntiAliasing mode = AntiAliasing::Msaa; ///< never Auto
    int samples = 1;
    /// "msaa4", "msaa2", "post" or "none" (MSAA with one sample is "none"): the frame answer's
    /// X-Dermis-AA header and the benchmarks' label.
    std::string label() const;
};

/// The one place `render.aa: auto` is decided (SPEC §2b "render"): Auto is Post on a software
/// rasterizer and MSAA with `render.msaa` samples elsewhere; Msaa uses min(render.msaa,
/// maxSamples) samples (the GL's limit; ≥ 1); Post and None draw one sample. Pure; does not check
/// ranges (validateRenderSettings does).
ResolvedAntiAliasing resolveAntiAliasing(const RenderSettings& render, bool softwareRasterizer,
                                         int maxSamples);

/// Checks ranges, naming the first offending field by JSON pointer under "/render":
/// size sides in [1, kMaxRenderSize] (InvalidArgument) and ≤ limits.maxSide (TooLarge);
/// camera yaw in [−kMaxTurnAngle, kMaxTurnAngle], pitch in [−90, 90], distance in (0, kMaxCameraDistance]
/// when set; displacement_scale in [0, kMaxDisplacementScale] when set; bump_strength in
/// [0, kMaxBumpStrength] (bounds in scene.hpp); msaa 1, 2 or 4; exposure in [0, kMaxExposure];
/// environment_rotation in [−kMaxTurnAngle, kMaxTurnAngle]; key_light: direction finite, each
/// component in [−1e6, 1e6] and not all zero, intensity in [0, kMaxKeyLightIntensity], colour
/// components in [0, 1].
/// `where` names the calling function in the message.
Status validateRenderSettings(const RenderSettings& render, const RenderLimits& limits = {},
                              const char* where = "dermis::validateRenderSettings");

} // namespace dermis
