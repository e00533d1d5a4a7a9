// Dermis core — texture layouts (texture_layout.hpp).
#include "texture_layout.hpp"

#include <type_traits>

namespace dermis {

std::string_view toString(UvLayoutMode m) {
    switch (m) {
    case UvLayoutMode::Model: return "model";
    case UvLayoutMode::Generated: return "generated";
    case UvLayoutMode::Auto: break;
    }
    return "auto";
}

std::optional<UvLayoutMode> uvLayoutModeFromString(std::string_view s) {
    if (s == "auto") return UvLayoutMode::Auto;
    if (s == "model") return UvLayoutMode::Model;
    if (s == "generated") return UvLayoutMode::Generated;
    return std::nullopt;
}

bool TextureLayout::empty() const {
    for (const PartLayout& p : parts)
        if (!p.indices.empty()) return false;
    return true;
}

TextureLayout modelTextureLayout(const Model& model) {
    TextureLayout layout;
    layout.kind = "model";
    layout.parts.resize(model.parts.size());
    for (std::size_t k = 0; k < model.parts.size(); ++k) {
        const MeshPart& part = model.parts[k];
        if (part.uvs.size() < part.positions.size() || part.positions.empty()) continue;
        PartLayout& out = layout.parts[k];
        out.source.resize(part.positions.size());
        for (std::uint32_t v = 0; v < out.source.size(); ++v) out.source[v] = v;
        out.uvs.assign(part.uvs.begin(), part.uvs.begin() + static_cast<long>(part.positions.size()));
        out.indices = part.indices;
    }
    return layout;
}

Model modelThroughLayout(const Model& model, const TextureLayout& layout) {
    Model out = model;
    for (std::size_t k = 0; k < out.parts.size() && k < layout.parts.size(); ++k) {
        const PartLayout& pl = layout.parts[k];
        MeshPart& part = out.parts[k];
        if (pl.indices.empty()) {
            part.uvs.clear();
            continue;
        }
        const MeshPart& src = model.parts[k];
        auto gather = [&pl](const auto& values) {
            std::remove_cvref_t<decltype(values)> picked;
            if (values.empty()) return picked;
            picked.reserve(pl.source.size());
            for (std::uint32_t v : pl.source) picked.push_back(values[v]);
            return picked;
        };
        part.positions = gather(src.positions);
        part.normals = gather(src.normals);
        part.joints = gather(src.joints);
        part.weights = gather(src.weights);
        part.uvs1 = gather(src.uvs1);
        part.tangents = gather(src.tangents);
        part.colors = gather(src.colors);
        for (MorphTarget& t : part.morphs) {
            t.positions = gather(t.positions);
            t.normals = gather(t.normals);
            t.tangents = gather(t.tangents);
        }
        part.uvs = pl.uvs;
        part.indices = pl.indices;
    }
    return out;
}

} // namespace dermis
