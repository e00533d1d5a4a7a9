#include "render_settings.hpp"

#include "scene.hpp" // the document's bounds (kMaxTurnAngle, …)

#include <algorithm>
#include <cmath>
#include <sstream>

namespace dermis {
namespace {

std::string fmt(double d) {
    std::ostringstream s;
    s << d;
    return s.str();
}

} // namespace

std::string_view toString(DisplacementMode m) {
    return m == DisplacementMode::Tessellated ? "tessellated" : "vertex";
}

std::optional<DisplacementMode> displacementModeFromString(std::string_view s) {
    if (s == "vertex") return DisplacementMode::Vertex;
    if (s == "tessellated") return DisplacementMode::Tessellated;
    return std::nullopt;
}

std::string_view toString(AntiAliasing a) {
    switch (a) {
    case AntiAliasing::Msaa: return "msaa";
    case AntiAliasing::Post: return "post";
    case AntiAliasing::None: return "none";
    case AntiAliasing::Auto: break;
    }
    return "auto";
}

std::optional<AntiAliasing> antiAliasingFromString(std::string_view s) {
    if (s == "auto") return AntiAliasing::Auto;
    if (s == "msaa") return AntiAliasing::Msaa;
    if (s == "post") return AntiAliasing::Post;
    if (s == "none") return AntiAliasing::None;
    return std::nullopt;
}

std::string_view toString(Shading s) {
    switch (s) {
    case Shading::Pbr: return "pbr";
    case Shading::Skin: return "skin";
    case Shading::Legacy: break;
    }
    return "legacy";
}

std::optional<Shading> shadingFromString(std::string_view s) {
    if (s == "legacy") return Shading::Legacy;
    if (s == "pbr") return Shading::Pbr;
    if (s == "skin") return Shading::Skin;
    return std::nullopt;
}

std::string_view toString(ToneMapping t) {
    switch (t) {
    case ToneMapping::None: return "none";
    case ToneMapping::Aces: return "aces";
    case ToneMapping::Neutral: break;
    }
    return "neutral";
}

std::optional<ToneMapping> toneMappingFromString(std::string_view s) {
    if (s == "none") return ToneMapping::None;
    if (s == "neutral") return ToneMapping::Neutral;
    if (s == "aces") return ToneMapping::Aces;
    return std::nullopt;
}

std::string_view toString(FrameView v) {
    switch (v) {
    case FrameView::Shaded: return "shaded";
    case FrameView::Bump: return "bump";
    case FrameView::Displacement: return "displacement";
    case FrameView::Normal: return "normal";
    case FrameView::BaseColor: return "basecolor";
    case FrameView::Lighting: return "lighting";
    }
    return "shaded";
}

std::optional<FrameView> frameViewFromString(std::string_view s) {
    for (FrameView v : {FrameView::Shaded, FrameView::Bump, FrameView::Displacement, FrameView::Normal,
                        FrameView::BaseColor, FrameView::Lighting})
        if (toString(v) == s) return v;
    return std::nullopt;
}

std::string ResolvedAntiAliasing::label() const {
    if (mode == AntiAliasing::Post) return "post";
    if (mode == AntiAliasing::None || samples <= 1) return "none";
    return "msaa" + std::to_string(samples);
}

ResolvedAntiAliasing resolveAntiAliasing(const RenderSettings& render, bool softwareRasterizer,
                                         int maxSamples) {
    AntiAliasing mode = render.aa;
    if (mode == AntiAliasing::Auto) mode = softwareRasterizer ? AntiAliasing::Post : AntiAliasing::Msaa;
    if (mode != AntiAliasing::Msaa) return {mode, 1};
    return {mode, std::max(1, std::min(render.msaa, maxSamples))};
}

Status validateRenderSettings(const RenderSettings& r, const RenderLimits& limits, const char* where) {
    auto bad = [&](const std::string& field, const std::string& what) {
        return makeError(ErrorCode::InvalidArgument, where, field, what);
    };
    for (std::size_t k = 0; k < 2; ++k) {
        const std::string field = "/render/size/" + std::to_string(k);
        const int side = r.size[k];
        if (side < 1 || side > kMaxRenderSize)
            return bad(field, "must be in [1, " + std::to_string(kMaxRenderSize) + "], got " +
                                  std::to_string(side));
        if (side > limits.maxSide)
            return makeError(ErrorCode::TooLarge, where, field,
                             std::to_string(side) + " exceeds the server's limit " +
                                 std::to_string(limits.maxSide));
    }
    const Camera& c = r.camera;
    if (!std::isfinite(c.yaw)) return bad("/render/camera/yaw", "must be a finite number");
    if (!(std::abs(c.yaw) <= kMaxTurnAngle))
        return bad("/render/camera/yaw", "must be in [" + fmt(-kMaxTurnAngle) + ", " + fmt(kMaxTurnAngle) +
                                             "], got " + fmt(c.yaw));
    if (!(c.pitch >= -90.0 && c.pitch <= 90.0))
        return bad("/render/camera/pitch", "must be in [-90, 90], got " + fmt(c.pitch));
    if (c.distance && !(std::isfinite(*c.distance) && *c.distance > 0.0 && *c.distance <= kMaxCameraDistance))
        return bad("/render/camera/distance", "must be in (0, " + fmt(kMaxCameraDistance) +
                                                  "] (or \"auto\"), got " + fmt(*c.distance));
    if (c.target)
        for (double x : *c.target)
            if (!(std::isfinite(x) && std::abs(x) <= kMaxCameraTarget))
                return bad("/render/camera/target", "each coordinate must be a finite number in [" +
                                                        fmt(-kMaxCameraTarget) + ", " + fmt(kMaxCameraTarget) +
                                                        "], got " + fmt(x));
    if (r.displacementScale &&
        !(std::isfinite(*r.displacementScale) && *r.displacementScale >= 0.0 &&
          *r.displacementScale <= kMaxDisplacementScale))
        return bad("/render/displacement_scale", "must be in [0, " + fmt(kMaxDisplacementScale) +
                                                     "] (or \"auto\"), got " + fmt(*r.displacementScale));
    if (!(std::isfinite(r.bumpStrength) && r.bumpStrength >= 0.0 && r.bumpStrength <= kMaxBumpStrength))
        return bad("/render/bump_strength",
                   "must be in [0, " + fmt(kMaxBumpStrength) + "], got " + fmt(r.bumpStrength));
    if (r.msaa != 1 && r.msaa != 2 && r.msaa != 4)
        return bad("/render/msaa", "must be 1, 2 or 4, got " + std::to_string(r.msaa));
    if (!(std::isfinite(r.exposure) && r.exposure >= 0.0 && r.exposure <= kMaxExposure))
        return bad("/render/exposure", "must be in [0, " + fmt(kMaxExposure) + "], got " + fmt(r.exposure));
    if (!(std::isfinite(r.environmentRotation) && std::abs(r.environmentRotation) <= kMaxTurnAngle))
        return bad("/render/environment_rotation", "must be in [" + fmt(-kMaxTurnAngle) + ", " +
                                                       fmt(kMaxTurnAngle) + "], got " +
                                                       fmt(r.environmentRotation));
    if (r.keyLight) {
        const KeyLight& k = *r.keyLight;
        double length2 = 0.0;
        for (double x : k.direction) {
            if (!(std::isfinite(x) && std::abs(x) <= 1e6))
                return bad("/render/key_light/direction", "each component must be a finite number in [-1e6, 1e6], got " + fmt(x));
            length2 += x * x;
        }
        if (!(length2 > 1e-18)) return bad("/render/key_light/direction", "must not be the zero vector");
        if (!(std::isfinite(k.intensity) && k.intensity >= 0.0 && k.intensity <= kMaxKeyLightIntensity))
            return bad("/render/key_light/intensity",
                       "must be in [0, " + fmt(kMaxKeyLightIntensity) + "], got " + fmt(k.intensity));
        for (double channel : k.color)
            if (!(std::isfinite(channel) && channel >= 0.0 && channel <= 1.0))
                return bad("/render/key_light/color", "each component must be in [0, 1], got " + fmt(channel));
    }
    return Ok{};
}

} // namespace dermis
