// The height-map layout a scene uses (SPEC §8 "Height-map layout"): the one seam where
// `uv_layout` is decided for every frame, map, probe, pick and validation of the service (the
// model's own UVs when `auto` finds them usable, else the generated layout, cached per model
// content in memory and <data>/cache/layouts), the rest-surface maps surface placements are
// projected through (cached per model, layout and size in the model's ModelDerived), and the
// layout route (`GET /models/{id}/uv-layout`).
#include "service_state.hpp"

#include "core/layout_gen.hpp"
#include "core/uv_diagnosis.hpp"
#include "core/uv_layout.hpp"
#include "io/frame_io.hpp"

#include <algorithm>
#include <cmath>

namespace dermis {

using namespace detail;

// Part of every cached layout's key: bump the version when generateTextureLayout's output changes,
// so that no data folder serves a layout of an older generator.
constexpr const char* kLayoutSalt = "dermis-layout-gen/1 r1024 g4";

std::unique_ptr<LayoutCache> makeLayoutCache(const std::string& folder) {
    return std::make_unique<LayoutCache>(folder, kLayoutSalt, [](const Model& model) {
        return generateTextureLayout(model);
    });
}


Result<std::shared_ptr<const TextureLayout>> Service::State::layoutOf(const ModelDerived& derived, UvLayoutMode mode,
                                                                      const std::string& field) const {
    const Model& model = derived.model();
    // The diagnosis is read (built once per model) only when auto needs it.
    const bool own = mode == UvLayoutMode::Model ||
                     (mode == UvLayoutMode::Auto && modelUvsHoldHeightmaps(mode, derived.uvDiagnosis()));
    if (own) {
        if (!model.hasUVs())
            return bad(field, "the model has no TEXCOORD_0: use uv_layout \"auto\" or \"generated\"");
        return derived.modelLayout();
    }
    return layouts->generated(derived.modelPtr());
}

Result<std::shared_ptr<const TextureLayout>> Service::State::layoutFor(const Scene& scene,
                                                                      const ModelDerived& derived) const {
    return layoutOf(derived, scene.uvLayout, "/uv_layout");
}

std::shared_ptr<const ModelDerived> Service::State::derivedInLayout(const Snapshot& snap) const {
    auto derived = derivedOf(snap);
    auto layout = layoutFor(snap.scene, *derived);
    if (!layout || *layout == derived->modelLayout()) return derived;
    return derived->throughLayout(*layout);
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

namespace {

struct ModelLayout {
    std::shared_ptr<const Model> model;
    std::shared_ptr<const TextureLayout> layout;
};

Result<ModelLayout> modelLayout(const Service::State& st, const std::string& id, UvLayoutMode mode) {
    std::shared_ptr<const ModelDerived> derived;
    {
        std::shared_lock<std::shared_mutex> lock(st.mutex);
        auto it = st.models.find(id);
        if (it == st.models.end()) return notFound("id", "no model \"" + id + "\"");
        derived = it->second.derived->get(it->second.model); // kept alive without the lock
    }
    auto layout = st.layoutOf(*derived, mode, "layout");
    if (!layout) return layout.error();
    return ModelLayout{derived->modelPtr(), std::move(*layout)};
}

} // namespace

Result<nlohmann::json> Service::uvLayout(const std::string& id, UvLayoutMode mode) const {
    auto ml = modelLayout(*state_, id, mode);
    if (!ml) return ml.error();
    const std::vector<UvEdge> edges = uvEdges(*ml->layout);
    nlohmann::json flat = nlohmann::json::array();
    auto r5 = [](float v) { return std::round(double(v) * 1e5) / 1e5; };
    for (const UvEdge& e : edges)
        for (float v : {e.a.x, e.a.y, e.b.x, e.b.y})
            flat.push_back(r5(v));
    return nlohmann::json{{"id", id},
                          {"layout", ml->layout->kind},
                          {"edge_count", edges.size()},
                          {"edges", std::move(flat)},
                          {"convention", "u right, v down; each edge is u0, v0, u1, v1"}};
}

Result<EncodedImage> Service::uvLayoutPng(const std::string& id, int size, UvLayoutMode mode) const {
    if (size < 16 || size > limits_.maxRenderSide)
        return bad("size", "must be in [16, " + std::to_string(limits_.maxRenderSide) + "]");
    auto ml = modelLayout(*state_, id, mode);
    if (!ml) return ml.error();
    auto png = encodePng(rasterizeUvEdges(uvEdges(*ml->layout), size), true);
    if (!png) return png.error();
    return EncodedImage{std::move(*png), "image/png", ""};
}

} // namespace dermis
