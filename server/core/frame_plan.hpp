// Dermis core — the one path from a scene to what a frame needs ("frame plan"): evaluate the pose
// at a time, world matrices, each placement's joint angle and t, the height-map size and base,
// and the render settings with a frame's overrides applied and checked. The CPU bake (bakeScene,
// `bake`) and the GPU frame (renderer, `render`, the server) both start here.
//
// Pure: the caller loads the model and the images. A plan keeps the images it points to alive
// (shared, immutable), so it can be used after the owner's lock is released. It does not render
// and does not bake.
#pragma once

#include "bake.hpp"
#include "heightmap.hpp"
#include "model.hpp"
#include "render_settings.hpp"
#include "result.hpp"
#include "rig.hpp"
#include "scene.hpp"
#include "texture_layout.hpp"

#include <glm/glm.hpp>

#include <memory>
#include <optional>
#include <vector>

namespace dermis {

/// A frame's overrides of the scene (query parameters, --time, --size). Absent = the scene's.
struct FrameOverrides {
    std::optional<double> time; ///< overrides pose.time
    /// `msaa` given without `aa` selects MSAA with that many samples (as before `render.aa`:
    /// `msaa=1` is a frame without anti-aliasing); `aa` given sets the mode.
    std::optional<int> width, height, msaa;
    std::optional<AntiAliasing> aa;
    std::optional<Shading> shading;         ///< render.shading
    std::optional<double> exposure;         ///< render.exposure
    std::optional<ToneMapping> toneMapping; ///< render.tone_mapping
    std::optional<double> yaw, pitch, distance;
    std::optional<std::array<double, 3>> target; ///< the camera's target (Camera::target)
    FrameView view = FrameView::Shaded; ///< what the frame shows (never in the scene)
    /// The height-map layout the scene uses (SPEC §8), chosen by the caller (the service's
    /// layoutFor; the CLI: the model's own). Null = the model's own UVs, as before layouts: the
    /// plan's HeightMapInput::layout stays null then and the renderer uses the model's UVs.
    std::shared_ptr<const TextureLayout> layout;
    /// The rest-surface map of `layout` (of the model's own UVs when null) at the scene's
    /// height-map size, when the caller keeps one (a cache per layout and size): used when a
    /// surface placement needs one and its size matches; otherwise planFrame bakes it.
    std::shared_ptr<const RestSurfaceMap> rest;
};

struct FramePlan {
    LocalPose pose;
    std::vector<glm::mat4> world; ///< worldMatrices(model, pose): one per node
    HeightMapInput heights;
    RenderSettings render;        ///< the scene's, overrides applied, validated
    FrameView view = FrameView::Shaded; ///< FrameOverrides::view
    /// Keep-alive of the images `heights` points to.
    std::vector<std::shared_ptr<const PatternImage>> images;
};

/// Applies `overrides` to the scene's render settings and validates them once
/// (validateRenderSettings with `limits`), then evaluates the pose and resolves the placements.
/// Fails like validateRenderSettings (field "/render/…"), evaluatePose ("/pose/…") and
/// resolvePlacements ("/placements/<i>…"); a time override must be finite and ≥ 0 ("/pose/time").
/// UV placements on a model without UVs (and no layout given) fail at "/placements/<i>", surface
/// placements without a layout that has UVs at "/uv_layout" (resolvePlacements). The plan's
/// heights carry o.layout and, when an enabled surface placement needs it, the rest-surface map
/// (o.rest when it has the map's size, else bakeRestSurface of the layout in use).
Result<FramePlan> planFrame(const Scene& scene, const Model& model, const PatternImages& images,
                            std::shared_ptr<const PatternImage> base,
                            const FrameOverrides& overrides = {}, const RenderLimits& limits = {});

/// CPU reference of the height-map stage on a plan's input (bakeHeightMaps with its size/base).
Result<HeightMaps> bakeHeightMaps(const HeightMapInput& in, int threads = 0);
/// Same, into caller-owned maps (storage reused; see bakeHeightMapsInto).
Status bakeHeightMapsInto(const HeightMapInput& in, HeightMaps& maps, int threads = 0);

} // namespace dermis
