// Dermis core — texture layouts (texture_layout.hpp).
#include "texture_layout.hpp"

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

} // namespace dermis
