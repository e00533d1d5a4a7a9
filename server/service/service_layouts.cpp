// Dermis service — height-map layouts (SPEC §8 "Height-map layout"): which layout a model or scene
// uses (the model's own UVs, or the generated one when they are missing or shared), the cache of
// generated layouts, and the layout route (`GET /models/{id}/uv-layout`).
#include "service/service_state.hpp"

#include "core/layout_gen.hpp"
#include "core/uv_layout.hpp"
#include "io/frame_io.hpp"

#include <cmath>

namespace dermis {

using namespace detail;

namespace detail {

// Part of every cached layout's key: bump the version when generateTextureLayout's output changes,
// so that no data folder serves a layout of an older generator.
constexpr const char* kLayoutSalt = "dermis-layout-gen/1 r1024 g4";

std::unique_ptr<LayoutCache> makeLayoutCache(const std::string& folder) {
    return std::make_unique<LayoutCache>(folder, kLayoutSalt, [](const Model& model) {
        return generateTextureLayout(model);
    });
}

} // namespace detail

Result<std::shared_ptr<const TextureLayout>> Service::State::layoutOf(const std::shared_ptr<const Model>& model,
                                                                      UvLayoutMode mode,
                                                                      const std::string& field) const {
    if (mode == UvLayoutMode::Auto) mode = model->hasUVs() ? UvLayoutMode::Model : UvLayoutMode::Generated;
    if (mode == UvLayoutMode::Model) {
        if (!model->hasUVs())
            return bad(field, "the model has no TEXCOORD_0: use uv_layout \"auto\" or \"generated\"");
        return layouts->own(model);
    }
    return layouts->generated(model);
}

namespace {

struct ModelLayout {
    std::shared_ptr<const Model> model;
    std::shared_ptr<const TextureLayout> layout;
};

Result<ModelLayout> modelLayout(const Service::State& st, const std::string& id, UvLayoutMode mode) {
    std::shared_ptr<const Model> model;
    {
        std::shared_lock<std::shared_mutex> lock(st.mutex);
        auto it = st.models.find(id);
        if (it == st.models.end()) return notFound("id", "no model \"" + id + "\"");
        model = it->second.model; // kept alive without the lock (a layout may take a while)
    }
    auto layout = st.layoutOf(model, mode, "layout");
    if (!layout) return layout.error();
    return ModelLayout{std::move(model), std::move(*layout)};
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
