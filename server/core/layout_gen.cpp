// Dermis core — the generated height-map layout (layout_gen.hpp): checks the input, runs the steps
// (layout_charts.cpp, layout_flatten.cpp, layout_pack.cpp), builds each part's layout vertices
// (one per chart vertex and part vertex, first use first) and verifies the result
// (layout_check.cpp). A triangle that float rounding collapses (a sliver far below a texel) is
// moved to a degenerate cell and the layout made again (at most three times).
#include "layout_gen.hpp"

#include "layout_gen_internal.hpp"
#include "uv_diagnosis.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

namespace dermis {

using namespace layout_detail;

namespace {

constexpr const char* kWhere = "dermis::generateTextureLayout";

Error invalid(const std::string& field, const std::string& what) {
    return makeError(ErrorCode::InvalidArgument, kWhere, field, what);
}

std::optional<Error> checkInput(const Model& model, const LayoutGenOptions& o) {
    if (o.resolution < 64 || o.resolution > kMaxHeightmapSize)
        return invalid("resolution", "must be in [64, " + std::to_string(kMaxHeightmapSize) +
                                         "], got " + std::to_string(o.resolution));
    if (o.gutterTexels < 2 || o.gutterTexels > o.resolution / 16)
        return invalid("gutterTexels",
                       "must be in [2, resolution/16], got " + std::to_string(o.gutterTexels));
    if (!(o.creaseDegrees > 0 && o.creaseDegrees <= 180))
        return invalid("creaseDegrees", "must be in (0, 180]");
    if (!(o.coneDegrees > 0 && o.coneDegrees <= 85))
        return invalid("coneDegrees", "must be in (0, 85]");
    if (!(o.maxAreaStretch >= 1.5 && o.maxAreaStretch <= 100))
        return invalid("maxAreaStretch", "must be in [1.5, 100]");
    for (std::size_t k = 0; k < model.parts.size(); ++k) {
        const MeshPart& p = model.parts[k];
        const std::string field = "parts[" + std::to_string(k) + "].indices";
        if (p.indices.size() % 3 != 0) return invalid(field, "count is not a multiple of 3");
        for (std::uint32_t i : p.indices)
            if (i >= p.positions.size())
                return invalid(field, "index " + std::to_string(i) + " out of range (" +
                                          std::to_string(p.positions.size()) + " positions)");
    }
    if (model.triangleCount() == 0) return invalid("parts", "the model has no triangles");
    return std::nullopt;
}

/// One attempt; `forced[k][t]` marks triangles to treat as degenerate. Fills `collapsed` with
/// the (part, triangle) pairs whose float UVs came out collapsed or flipped.
Result<GeneratedLayout> attempt(const Model& model, const LayoutGenOptions& options,
                                const std::vector<std::vector<char>>& forced,
                                std::vector<std::pair<std::size_t, std::uint32_t>>& collapsed) {
    GeneratedLayout out;
    std::vector<FlatChart> charts;
    std::vector<std::pair<std::size_t, std::uint32_t>> degenerate; // (part, triangle)
    int splits = 0;
    for (std::size_t k = 0; k < model.parts.size(); ++k) {
        if (model.parts[k].indices.empty()) continue;
        PartMesh mesh = buildPartMesh(model.parts[k], options);
        for (std::size_t t = 0; t < forced[k].size(); ++t)
            if (forced[k][t] && !mesh.degenerate[t]) {
                mesh.degenerate[t] = 1;
                for (int c = 0; c < 3; ++c) {
                    const int o = mesh.adj[t][static_cast<std::size_t>(c)];
                    if (o < 0) continue;
                    for (int& back : mesh.adj[static_cast<std::size_t>(o)])
                        if (back == static_cast<int>(t)) back = -1;
                    mesh.adj[t][static_cast<std::size_t>(c)] = -1;
                }
            }
        for (std::size_t t = 0; t < mesh.tris.size(); ++t)
            if (mesh.degenerate[t]) degenerate.push_back({k, static_cast<std::uint32_t>(t)});
        flattenCharts(mesh, static_cast<int>(k), growCharts(mesh, options), options, charts,
                      splits);
    }
    Packing packing;
    if (!packCharts(charts, degenerate.size(), options, packing))
        return makeError(ErrorCode::Unsupported, kWhere, "",
                         std::to_string(charts.size()) + " charts do not fit a " +
                             std::to_string(options.resolution) + "² map with " +
                             std::to_string(options.gutterTexels) + "-texel gutters");

    // Per part: every corner's UV point (a chart vertex, or a degenerate cell's corner) and the
    // part vertex it copies; layout vertices are the distinct pairs, numbered by first use.
    out.layout.kind = "generated";
    out.layout.parts.resize(model.parts.size());
    std::vector<std::vector<std::uint32_t>> cornerPoint(model.parts.size());
    std::vector<std::vector<glm::dvec2>> pointUv(model.parts.size());
    for (std::size_t k = 0; k < model.parts.size(); ++k)
        cornerPoint[k].assign(model.parts[k].indices.size(), 0);
    for (std::size_t c = 0; c < charts.size(); ++c) {
        const FlatChart& fc = charts[c];
        const auto k = static_cast<std::size_t>(fc.part);
        const auto base = static_cast<std::uint32_t>(pointUv[k].size());
        for (const glm::dvec2& p : fc.uv)
            pointUv[k].push_back(packing.charts[c].origin + packing.charts[c].linear * p);
        for (std::size_t i = 0; i < fc.chart.tris.size(); ++i)
            for (int j = 0; j < 3; ++j)
                cornerPoint[k][3 * fc.chart.tris[i] + static_cast<std::size_t>(j)] =
                    base + fc.chart.local[i][j];
    }
    out.chartOf.resize(model.parts.size());
    for (std::size_t k = 0; k < model.parts.size(); ++k)
        out.chartOf[k].assign(model.parts[k].indices.size() / 3,
                              static_cast<std::uint32_t>(charts.size()));
    for (std::size_t c = 0; c < charts.size(); ++c)
        for (std::uint32_t t : charts[c].chart.tris)
            out.chartOf[static_cast<std::size_t>(charts[c].part)][t] =
                static_cast<std::uint32_t>(c);
    for (std::size_t d = 0; d < degenerate.size(); ++d) {
        const auto [k, t] = degenerate[d];
        for (int j = 0; j < 3; ++j) {
            cornerPoint[k][3 * t + static_cast<std::size_t>(j)] =
                static_cast<std::uint32_t>(pointUv[k].size());
            pointUv[k].push_back(degenerateUv(packing, options, d, j));
        }
    }
    for (std::size_t k = 0; k < model.parts.size(); ++k) {
        const MeshPart& part = model.parts[k];
        if (part.indices.empty()) continue;
        PartLayout& pl = out.layout.parts[k];
        std::vector<std::pair<std::uint64_t, std::uint32_t>> keys(part.indices.size());
        for (std::size_t i = 0; i < keys.size(); ++i)
            keys[i] = {(static_cast<std::uint64_t>(cornerPoint[k][i]) << 32) | part.indices[i],
                       static_cast<std::uint32_t>(i)};
        std::sort(keys.begin(), keys.end());
        // Equal keys share a layout vertex, numbered in the order of their first corner.
        std::vector<std::uint32_t> firstCorner(keys.size()); // corner → first corner of its key
        for (std::size_t i = 0; i < keys.size();) {
            std::size_t j = i;
            while (j < keys.size() && keys[j].first == keys[i].first) {
                firstCorner[keys[j].second] = keys[i].second;
                ++j;
            }
            i = j;
        }
        pl.indices.resize(part.indices.size());
        std::vector<std::int64_t> vertexOfCorner(part.indices.size(), -1);
        for (std::size_t i = 0; i < part.indices.size(); ++i) {
            const std::uint32_t f = firstCorner[i];
            if (vertexOfCorner[f] < 0) {
                vertexOfCorner[f] = static_cast<std::int64_t>(pl.source.size());
                pl.source.push_back(part.indices[i]);
                const glm::dvec2 uv = pointUv[k][cornerPoint[k][i]];
                pl.uvs.emplace_back(static_cast<float>(uv.x), static_cast<float>(uv.y));
            }
            pl.indices[i] = static_cast<std::uint32_t>(vertexOfCorner[f]);
        }
        for (std::size_t t = 0; t < part.indices.size() / 3; ++t) {
            const glm::dvec2 a(pl.uvs[pl.indices[3 * t]]), b(pl.uvs[pl.indices[3 * t + 1]]),
                c(pl.uvs[pl.indices[3 * t + 2]]);
            if (!((b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y) < 0))
                collapsed.push_back({k, static_cast<std::uint32_t>(t)});
        }
    }
    out.charts = charts.size();
    out.splits = static_cast<std::size_t>(splits);
    out.degenerate = degenerate.size();
    out.texelsPerMetre = packing.texelsPerMetre;
    return out;
}

} // namespace

Result<GeneratedLayout> generateTextureLayoutWithReport(const Model& model,
                                                        const LayoutGenOptions& options) {
    if (auto e = checkInput(model, options)) return *e;
    std::vector<std::vector<char>> forced(model.parts.size());
    for (std::size_t k = 0; k < model.parts.size(); ++k)
        forced[k].assign(model.parts[k].indices.size() / 3, 0);
    for (int round = 0;; ++round) {
        std::vector<std::pair<std::size_t, std::uint32_t>> collapsed;
        auto made = attempt(model, options, forced, collapsed);
        if (!made) return made.error();
        if (!collapsed.empty() && round < 3) {
            for (const auto& [k, t] : collapsed)
                forced[k][t] = 1;
            continue;
        }
        GeneratedLayout& g = *made;
        g.check = checkTextureLayout(model, g.layout, options.resolution, options.gutterTexels);
        const LayoutCheck& c = g.check;
        std::string failed;
        if (c.malformed)
            failed = std::to_string(c.malformed) + " malformed triangles";
        else if (c.outside)
            failed = std::to_string(c.outside) + " triangles outside [0,1]²";
        else if (c.flipped)
            failed = std::to_string(c.flipped) + " flipped triangles";
        else if (c.overlapTexels)
            failed = std::to_string(c.overlapTexels) + " overlapping texels";
        else if (c.minGutterTexels < options.gutterTexels)
            failed = "a gutter of " + std::to_string(c.minGutterTexels) + " texels";
        if (!failed.empty())
            return makeError(ErrorCode::Internal, kWhere, "", "the generated layout has " + failed);
        return made;
    }
}

Result<TextureLayout> generateTextureLayout(const Model& model, const LayoutGenOptions& options) {
    auto made = generateTextureLayoutWithReport(model, options);
    if (!made) return made.error();
    return std::move(made->layout);
}

Result<TextureLayout> textureLayoutFor(const Model& model, UvLayoutMode mode) {
    if (mode == UvLayoutMode::Model || (mode == UvLayoutMode::Auto && modelUvsHoldHeightmaps(mode, diagnoseUvs(model))))
        return modelTextureLayout(model);
    return generateTextureLayout(model);
}

} // namespace dermis
