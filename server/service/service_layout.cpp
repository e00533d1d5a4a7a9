// The height-map layout a scene uses (SPEC §8 "Height-map layout"): the one seam where
// `uv_layout` is decided for every frame, map, probe, pick and validation of the service, and
// the rest-surface maps surface placements are projected through (cached per model, layout and
// size in the model's ModelDerived).
#include "service/service_state.hpp"

#include <algorithm>

namespace dermis {

using namespace detail;

Result<std::shared_ptr<const TextureLayout>> Service::State::layoutFor(const Scene& scene,
                                                                      const ModelDerived& derived) const {
    switch (scene.uvLayout) {
    case UvLayoutMode::Model:
        return derived.modelLayout();
    case UvLayoutMode::Auto:
        // TODO(lead): SPEC §8 auto = the model's UVs when present and unique (UV diagnosis:
        // overlap below 0.5 % of used texels), else the generated layout. Until UV diagnosis and
        // the generated layout are wired in here, auto is the model's own UVs (the old
        // behaviour; a model without UVs then takes no placement).
        return derived.modelLayout();
    case UvLayoutMode::Generated:
        break;
    }
    // TODO(lead): the generated layout (core generateTextureLayout, cached per model beside
    // ModelDerived::modelLayout).
    return makeError(ErrorCode::Unsupported, "dermis::Service", "/uv_layout",
                     "the generated height-map layout is not available in this build yet; use "
                     "\"model\" or \"auto\"");
}

Status Service::State::withLayout(const Scene& scene, const ModelDerived& derived,
                                  FrameOverrides& o) const {
    auto layout = layoutFor(scene, derived);
    if (!layout) return layout.error();
    o.layout = *layout;
    const bool surface = std::any_of(scene.placements.begin(), scene.placements.end(), [](const Placement& p) {
        return p.enabled && p.projection == Projection::Surface;
    });
    // An empty layout has no texel to bake: planFrame says why (resolvePlacements, "/uv_layout").
    if (surface && o.layout && !o.layout->empty())
        o.rest = derived.restSurface(o.layout, scene.heightmapSize[0], scene.heightmapSize[1]);
    return Ok{};
}

} // namespace dermis
