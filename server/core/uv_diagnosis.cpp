// UV diagnosis. See uv_diagnosis.hpp.
#include "uv_diagnosis.hpp"

#include "disjoint_sets.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <numeric>

namespace dermis {

namespace {

constexpr std::int64_t kSub = 256;          ///< fixed-point steps per texel
constexpr double kMaxUvExtent = 16.0;       ///< a triangle wider than this (UV units) is not rasterized
constexpr double kMaxUvMagnitude = 1.0e6;   ///< UVs beyond this count as missing
constexpr double kMirrorMinTexels = 16.0;   ///< islands smaller than this (UV area, texels) pair with none
constexpr double kMirrorIoU = 0.75;
constexpr double kMirrorAreaRatio = 0.75;
constexpr double kMirrorDistance = 0.05;    ///< of the rest bounds' diagonal

std::int64_t floorDiv(std::int64_t a, std::int64_t b) {
    const std::int64_t q = a / b;
    return (a % b != 0 && (a < 0) != (b < 0)) ? q - 1 : q;
}
std::int64_t ceilDiv(std::int64_t a, std::int64_t b) { return -floorDiv(-a, b); }
std::int64_t wrap(std::int64_t a, std::int64_t n) {
    const std::int64_t r = a % n;
    return r < 0 ? r + n : r;
}


/// One triangle with UVs.
struct Tri {
    int part = 0, index = 0, island = 0, region = 0;
    bool strong = false; ///< holds at least one texel centre
};

struct Island {
    int part = -1;
    std::size_t triangles = 0;
    double uvArea = 0.0, surfaceArea = 0.0;
    glm::dvec2 lo{1e300}, hi{-1e300};
    glm::dvec3 centroid{0.0}; ///< area-weighted sum, then divided
    std::map<int, std::size_t> regionTriangles;
    int region = -1;
};

/// The label people know a part by.
std::string partLabel(const Model& model, std::size_t pi) {
    const MeshPart& p = model.parts[pi];
    if (!p.node.empty()) return p.node;
    if (!p.name.empty()) return p.name;
    return "part " + std::to_string(pi);
}

/// The node whose skin weight dominates triangle t (summed over its corners; ties: the lower
/// node index), or −1. A rigid part (no per-vertex skin) follows influence 0; a node that is not
/// a joint stands for the nearest joint above it.
int dominantNode(const Model& model, const MeshPart& p, std::size_t t, std::vector<float>& scratch) {
    int node = -1;
    const bool skinned = p.joints.size() == p.positions.size() && p.weights.size() == p.positions.size();
    if (!skinned || p.influences.size() <= 1) {
        node = p.influences.empty() ? -1 : p.influences[0].node;
    } else {
        std::fill(scratch.begin(), scratch.end(), 0.0f);
        if (scratch.size() < p.influences.size()) scratch.resize(p.influences.size(), 0.0f);
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t v = p.indices[3 * t + k];
            for (int c = 0; c < 4; ++c) {
                const std::size_t inf = p.joints[v][c];
                if (inf < p.influences.size()) scratch[inf] += p.weights[v][c];
            }
        }
        float best = 0.0f;
        for (std::size_t inf = 0; inf < p.influences.size(); ++inf) {
            const int n = p.influences[inf].node;
            if (scratch[inf] > best || (scratch[inf] == best && best > 0.0f && n < node)) {
                best = scratch[inf];
                node = n;
            }
        }
    }
    if (node < 0 || static_cast<std::size_t>(node) >= model.nodes.size()) return -1;
    if (std::find(model.joints.begin(), model.joints.end(), node) == model.joints.end()) {
        const int above = model.parentJoint(node);
        if (above >= 0) return above;
    }
    return node;
}

bool topLeft(std::int64_t dx, std::int64_t dy) { return dy < 0 || (dy == 0 && dx > 0); }

} // namespace

std::span<const int> UvDiagnosis::regionsAt(glm::dvec2 uv, bool* overlapped) const {
    if (overlapped) *overlapped = false;
    if (resolution <= 0 || texelSets.empty() || !std::isfinite(uv.x) || !std::isfinite(uv.y) ||
        std::abs(uv.x) > kMaxUvMagnitude || std::abs(uv.y) > kMaxUvMagnitude)
        return {};
    const std::int64_t n = resolution;
    const std::int64_t i = wrap(static_cast<std::int64_t>(std::floor(uv.x * static_cast<double>(n))), n);
    const std::int64_t j = wrap(static_cast<std::int64_t>(std::floor(uv.y * static_cast<double>(n))), n);
    const std::uint32_t v = texelSets[static_cast<std::size_t>(j * n + i)];
    if (v == 0) return {};
    if (overlapped) *overlapped = (v & kOverlappedTexel) != 0;
    const std::vector<int>& set = regionSets[(v & ~kOverlappedTexel) - 1];
    return {set.data(), set.size()};
}

std::string UvDiagnosis::describeSharing(std::size_t maxRegions, std::size_t maxOthers) const {
    std::vector<int> order;
    for (std::size_t r = 0; r < regions.size(); ++r)
        if (regions[r].sharedTexels > 0) order.push_back(static_cast<int>(r));
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
        return regions[static_cast<std::size_t>(a)].sharedTexels > regions[static_cast<std::size_t>(b)].sharedTexels;
    });
    std::string out;
    for (std::size_t k = 0; k < order.size() && k < maxRegions; ++k) {
        const UvRegion& r = regions[static_cast<std::size_t>(order[k])];
        if (!out.empty()) out += "; ";
        out += r.name;
        if (r.sharesWith.empty()) {
            out += " folds onto itself";
            continue;
        }
        out += " shares texels with ";
        for (std::size_t o = 0; o < r.sharesWith.size() && o < maxOthers; ++o) {
            if (o > 0) out += o + 1 == std::min(r.sharesWith.size(), maxOthers) && r.sharesWith.size() <= maxOthers ? " and " : ", ";
            out += regions[static_cast<std::size_t>(r.sharesWith[o].first)].name;
        }
        if (r.sharesWith.size() > maxOthers)
            out += " and " + std::to_string(r.sharesWith.size() - maxOthers) + " more";
        if (r.foldedTexels > 0) out += " (and folds onto itself)";
    }
    if (order.size() > maxRegions)
        out += "; " + std::to_string(order.size() - maxRegions) + " more regions share texels";
    return out;
}

bool modelUvsHoldHeightmaps(UvLayoutMode mode, const UvDiagnosis& diagnosis) {
    switch (mode) {
    case UvLayoutMode::Model: return true;
    case UvLayoutMode::Generated: return false;
    case UvLayoutMode::Auto: return diagnosis.usable();
    }
    return diagnosis.usable();
}

UvDiagnosis diagnoseUvs(const Model& model, const UvDiagnosisOptions& options) {
    const RestSkin rest = restSkin(model);
    return diagnoseUvs(model, rest, symmetryPlane(rest), options);
}

UvDiagnosis diagnoseUvs(const Model& model, const RestSkin& rest, const SymmetryPlane& plane,
                        const UvDiagnosisOptions& options) {
    UvDiagnosis d;
    d.hasUVs = model.hasUVs();
    const int res = std::clamp(options.resolution, 16, 4096);
    d.resolution = res;
    const std::int64_t n = res, period = n * kSub;
    const std::size_t texelCount = static_cast<std::size_t>(n * n);
    d.triangleRegion.resize(model.parts.size());

    // --- triangles, islands, regions --------------------------------------------------------
    std::vector<Tri> tris;
    std::vector<Island> islands;
    std::map<std::pair<int, int>, int> regionOf; // (part, node) → region
    std::vector<float> scratch;
    for (std::size_t pi = 0; pi < model.parts.size(); ++pi) {
        const MeshPart& p = model.parts[pi];
        const std::size_t count = p.indices.size() / 3;
        d.triangleRegion[pi].assign(count, -1);
        if (p.uvs.empty()) {
            ++d.partsWithoutUvs;
            d.missingTriangles += count;
            continue;
        }
        auto valid = [&](std::size_t t) {
            for (int k = 0; k < 3; ++k) {
                const std::uint32_t v = p.indices[3 * t + k];
                if (v >= p.uvs.size() || v >= p.positions.size()) return false;
                const glm::vec2 uv = p.uvs[v];
                if (!std::isfinite(uv.x) || !std::isfinite(uv.y) || std::abs(uv.x) > kMaxUvMagnitude ||
                    std::abs(uv.y) > kMaxUvMagnitude)
                    return false;
            }
            return true;
        };
        DisjointSets comp(p.uvs.size());
        for (std::size_t t = 0; t < count; ++t)
            if (valid(t)) {
                comp.join(p.indices[3 * t], p.indices[3 * t + 1]);
                comp.join(p.indices[3 * t], p.indices[3 * t + 2]);
            }
        std::vector<int> islandOfRoot(p.uvs.size(), -1);
        std::vector<bool> outside(p.uvs.size(), false), counted(p.uvs.size(), false);
        for (std::size_t t = 0; t < count; ++t) {
            if (!valid(t)) {
                ++d.missingTriangles;
                continue;
            }
            const auto r = static_cast<std::uint32_t>(comp.root(p.indices[3 * t]));
            if (islandOfRoot[r] < 0) {
                islandOfRoot[r] = static_cast<int>(islands.size());
                islands.emplace_back();
                islands.back().part = static_cast<int>(pi);
            }
            const int node = dominantNode(model, p, t, scratch);
            auto [it, added] = regionOf.emplace(std::make_pair(static_cast<int>(pi), node),
                                                static_cast<int>(d.regions.size()));
            if (added) {
                UvRegion region;
                region.part = partLabel(model, pi);
                region.partIndex = static_cast<int>(pi);
                region.jointNode = node;
                region.joint = node >= 0 ? model.nodes[static_cast<std::size_t>(node)].name : "";
                region.name = region.joint.empty() ? region.part : region.part + " (" + region.joint + ")";
                d.regions.push_back(std::move(region));
            }
            ++d.regions[static_cast<std::size_t>(it->second)].triangles;
            d.triangleRegion[pi][t] = it->second;
            tris.push_back({static_cast<int>(pi), static_cast<int>(t), islandOfRoot[r], it->second, false});
            bool out = false;
            for (int k = 0; k < 3; ++k) {
                const std::uint32_t v = p.indices[3 * t + k];
                const glm::vec2 uv = p.uvs[v];
                const bool o = uv.x < 0.0f || uv.y < 0.0f || uv.x > 1.0f || uv.y > 1.0f;
                out = out || o;
                if (o && !counted[v]) {
                    counted[v] = true;
                    ++d.outOfRangeVertices;
                }
            }
            if (out) ++d.outOfRangeTriangles;
        }
    }
    d.triangles = tris.size();
    d.islands = islands.size();
    // Region names are unique: two parts with one label get "#k" after the later ones.
    {
        std::map<std::string, int> seen;
        for (UvRegion& r : d.regions) {
            const int k = seen[r.name]++;
            if (k > 0) r.name += " #" + std::to_string(k + 1);
        }
    }

    // --- rasterization: claims per texel ----------------------------------------------------
    // Per texel its first claim; further claims in a list per texel (extraHead → extra).
    std::vector<std::int32_t> first(texelCount, -1), extraHead(texelCount, -1);
    std::vector<std::pair<std::int32_t, std::int32_t>> extra; // (triangle, next claim or −1)
    auto claim = [&](std::int64_t i, std::int64_t j, std::int32_t tri) {
        const std::size_t texel = static_cast<std::size_t>(wrap(j, n) * n + wrap(i, n));
        if (first[texel] < 0) {
            first[texel] = tri;
        } else {
            extra.emplace_back(tri, extraHead[texel]);
            extraHead[texel] = static_cast<std::int32_t>(extra.size() - 1);
        }
    };
    const double scale = static_cast<double>(period);
    for (std::size_t ti = 0; ti < tris.size(); ++ti) {
        Tri& tri = tris[ti];
        const MeshPart& p = model.parts[static_cast<std::size_t>(tri.part)];
        const std::size_t base = 3 * static_cast<std::size_t>(tri.index);
        std::int64_t x[3], y[3];
        for (int k = 0; k < 3; ++k) {
            const glm::vec2 uv = p.uvs[p.indices[base + k]];
            x[k] = std::llround(static_cast<double>(uv.x) * scale);
            y[k] = std::llround(static_cast<double>(uv.y) * scale);
        }
        // Wrap: the triangle moves by whole periods so that its lower corner lies in [0, 1)².
        const std::int64_t sx = floorDiv(std::min({x[0], x[1], x[2]}), period) * period;
        const std::int64_t sy = floorDiv(std::min({y[0], y[1], y[2]}), period) * period;
        for (int k = 0; k < 3; ++k) {
            x[k] -= sx;
            y[k] -= sy;
        }
        const std::int64_t maxX = std::max({x[0], x[1], x[2]}), maxY = std::max({y[0], y[1], y[2]});
        const std::int64_t minX = std::min({x[0], x[1], x[2]}), minY = std::min({y[0], y[1], y[2]});
        std::int64_t area2 = (x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0]);
        const bool rasterizable = maxX <= static_cast<std::int64_t>(kMaxUvExtent * scale) &&
                                  maxY <= static_cast<std::int64_t>(kMaxUvExtent * scale);
        if (area2 != 0 && rasterizable) {
            if (area2 < 0) {
                std::swap(x[1], x[2]);
                std::swap(y[1], y[2]);
                area2 = -area2;
            }
            const std::int64_t half = kSub / 2;
            const std::int64_t i0 = ceilDiv(minX - half, kSub), i1 = std::min(floorDiv(maxX - half, kSub), i0 + n - 1);
            const std::int64_t j0 = ceilDiv(minY - half, kSub), j1 = std::min(floorDiv(maxY - half, kSub), j0 + n - 1);
            for (std::int64_t j = j0; j <= j1; ++j) {
                const std::int64_t py = j * kSub + half;
                for (std::int64_t i = i0; i <= i1; ++i) {
                    const std::int64_t px = i * kSub + half;
                    bool inside = true;
                    for (int e = 0; e < 3 && inside; ++e) {
                        const int a = e, b = (e + 1) % 3;
                        const std::int64_t dx = x[b] - x[a], dy = y[b] - y[a];
                        const std::int64_t f = dx * (py - y[a]) - dy * (px - x[a]);
                        inside = f > 0 || (f == 0 && topLeft(dx, dy));
                    }
                    if (!inside) continue;
                    claim(i, j, static_cast<std::int32_t>(ti));
                    tri.strong = true;
                }
            }
        }
        if (!tri.strong) {
            ++d.subTexelTriangles;
            const std::int64_t cx = (x[0] + x[1] + x[2]) / 3, cy = (y[0] + y[1] + y[2]) / 3;
            claim(floorDiv(cx, kSub), floorDiv(cy, kSub), static_cast<std::int32_t>(ti));
        }
    }

    // --- per texel: the regions claiming it, overlapped or not ------------------------------
    d.texelSets.assign(texelCount, 0);
    d.regionSets.resize(d.regions.size());
    std::map<std::vector<int>, std::uint32_t> setIndex;
    for (std::size_t r = 0; r < d.regions.size(); ++r) {
        d.regionSets[r] = {static_cast<int>(r)};
        setIndex.emplace(d.regionSets[r], static_cast<std::uint32_t>(r));
    }
    std::vector<std::size_t> setTexels(d.regions.size(), 0), setOverlaps(d.regions.size(), 0);
    std::vector<std::int32_t> claims;
    std::vector<int> islandsHere, regionsHere, lastRegions;
    std::uint32_t lastSet = 0;
    for (std::size_t texel = 0; texel < texelCount; ++texel) {
        if (first[texel] < 0) continue;
        ++d.usedTexels;
        claims.assign(1, first[texel]);
        for (std::int32_t e = extraHead[texel]; e >= 0; e = extra[static_cast<std::size_t>(e)].second)
            claims.push_back(extra[static_cast<std::size_t>(e)].first);
        std::uint32_t set = static_cast<std::uint32_t>(tris[static_cast<std::size_t>(claims[0])].region);
        bool overlapped = false;
        if (claims.size() > 1) {
            islandsHere.clear();
            regionsHere.clear();
            int strong = 0;
            for (std::int32_t c : claims) {
                const Tri& t = tris[static_cast<std::size_t>(c)];
                islandsHere.push_back(t.island);
                regionsHere.push_back(t.region);
                strong += t.strong ? 1 : 0;
            }
            std::sort(islandsHere.begin(), islandsHere.end());
            const bool islandsDiffer = islandsHere.front() != islandsHere.back();
            // One island: overlapped only where two of its triangles hold the texel centre (a
            // fold); a sub-texel triangle's claim beside its neighbours is no overlap.
            overlapped = islandsDiffer || strong >= 2;
            std::sort(regionsHere.begin(), regionsHere.end());
            regionsHere.erase(std::unique(regionsHere.begin(), regionsHere.end()), regionsHere.end());
            if (regionsHere.size() > 1) {
                // Neighbouring texels mostly have the same regions: the last set first.
                if (regionsHere != lastRegions) {
                    auto it = setIndex.find(regionsHere);
                    if (it == setIndex.end()) {
                        it = setIndex.emplace(regionsHere, static_cast<std::uint32_t>(d.regionSets.size())).first;
                        d.regionSets.push_back(regionsHere);
                        setTexels.push_back(0);
                        setOverlaps.push_back(0);
                    }
                    lastRegions = regionsHere;
                    lastSet = it->second;
                }
                set = lastSet;
            }
        }
        ++setTexels[set];
        if (overlapped) {
            ++setOverlaps[set];
            ++d.overlapTexels;
        }
        d.texelSets[texel] = (set + 1) | (overlapped ? UvDiagnosis::kOverlappedTexel : 0u);
    }
    d.usedFraction = static_cast<double>(d.usedTexels) / static_cast<double>(texelCount);
    d.overlapFraction = d.usedTexels ? static_cast<double>(d.overlapTexels) / static_cast<double>(d.usedTexels) : 0.0;

    // --- per region: texels, shared texels, who with ----------------------------------------
    std::map<std::pair<int, int>, std::size_t> pairs;
    for (std::size_t s = 0; s < d.regionSets.size(); ++s) {
        const std::vector<int>& set = d.regionSets[s];
        for (int r : set) {
            UvRegion& region = d.regions[static_cast<std::size_t>(r)];
            region.texels += setTexels[s];
            region.sharedTexels += setOverlaps[s];
            if (set.size() == 1) region.foldedTexels += setOverlaps[s];
        }
        if (setOverlaps[s] == 0) continue;
        for (std::size_t a = 0; a < set.size(); ++a)
            for (std::size_t b = a + 1; b < set.size(); ++b) pairs[{set[a], set[b]}] += setOverlaps[s];
    }
    for (const auto& [ab, texels] : pairs) {
        d.regions[static_cast<std::size_t>(ab.first)].sharesWith.emplace_back(ab.second, texels);
        d.regions[static_cast<std::size_t>(ab.second)].sharesWith.emplace_back(ab.first, texels);
    }
    for (UvRegion& r : d.regions)
        std::stable_sort(r.sharesWith.begin(), r.sharesWith.end(),
                         [](const auto& a, const auto& b) { return a.second > b.second; });

    // --- islands: areas, bounds, rest-pose centroids; density per joint ---------------------
    std::map<int, UvJointDensity> density;
    for (const Tri& t : tris) {
        const MeshPart& p = model.parts[static_cast<std::size_t>(t.part)];
        const std::size_t base = 3 * static_cast<std::size_t>(t.index);
        glm::dvec2 uv[3];
        glm::dvec3 pos[3];
        const SkinnedPart* sp = static_cast<std::size_t>(t.part) < rest.parts.size()
                                    ? &rest.parts[static_cast<std::size_t>(t.part)]
                                    : nullptr;
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t v = p.indices[base + k];
            uv[k] = glm::dvec2(p.uvs[v]);
            pos[k] = glm::dvec3(sp && v < sp->positions.size() ? sp->positions[v] : p.positions[v]);
        }
        const double uvArea = 0.5 * std::abs((uv[1].x - uv[0].x) * (uv[2].y - uv[0].y) -
                                             (uv[2].x - uv[0].x) * (uv[1].y - uv[0].y));
        double area = 0.5 * glm::length(glm::cross(pos[1] - pos[0], pos[2] - pos[0]));
        if (!std::isfinite(area)) area = 0.0;
        Island& is = islands[static_cast<std::size_t>(t.island)];
        ++is.triangles;
        is.uvArea += uvArea;
        is.surfaceArea += area;
        is.centroid += area * (pos[0] + pos[1] + pos[2]) / 3.0;
        for (int k = 0; k < 3; ++k) {
            is.lo = glm::min(is.lo, uv[k]);
            is.hi = glm::max(is.hi, uv[k]);
        }
        ++is.regionTriangles[t.region];
        const int node = d.regions[static_cast<std::size_t>(t.region)].jointNode;
        if (node < 0) continue;
        UvJointDensity& jd = density[node];
        jd.node = node;
        ++jd.triangles;
        jd.surfaceArea += area;
        jd.uvArea += uvArea;
    }
    for (auto& [node, jd] : density) {
        jd.joint = model.nodes[static_cast<std::size_t>(node)].name;
        jd.texelsPerUnit = jd.surfaceArea > 0.0 ? res * std::sqrt(jd.uvArea / jd.surfaceArea) : 0.0;
        d.density.push_back(jd);
    }

    // --- mirrored island pairs --------------------------------------------------------------
    const double texelArea = 1.0 / (static_cast<double>(res) * res);
    std::vector<int> candidates;
    for (std::size_t k = 0; k < islands.size(); ++k) {
        Island& is = islands[k];
        if (is.surfaceArea > 0.0) is.centroid /= is.surfaceArea;
        std::size_t most = 0;
        for (const auto& [region, count] : is.regionTriangles)
            if (count > most) {
                most = count;
                is.region = region;
            }
        if (is.uvArea >= kMirrorMinTexels * texelArea && is.surfaceArea > 0.0)
            candidates.push_back(static_cast<int>(k));
    }
    const glm::dvec3 diag = glm::dvec3(rest.bounds.max) - glm::dvec3(rest.bounds.min);
    const double tolerance = kMirrorDistance * glm::length(diag);
    const int axis = std::clamp(plane.axis, 0, 2);
    auto reflect = [&](glm::dvec3 c) {
        c[axis] = 2.0 * static_cast<double>(plane.offset) - c[axis];
        return c;
    };
    auto iou = [](const Island& a, const Island& b) {
        const glm::dvec2 lo = glm::max(a.lo, b.lo), hi = glm::min(a.hi, b.hi);
        if (hi.x <= lo.x || hi.y <= lo.y) return 0.0;
        const double inter = (hi.x - lo.x) * (hi.y - lo.y);
        const double ua = (a.hi.x - a.lo.x) * (a.hi.y - a.lo.y), ub = (b.hi.x - b.lo.x) * (b.hi.y - b.lo.y);
        return inter / (ua + ub - inter);
    };
    auto ratio = [](double a, double b) { return std::min(a, b) / std::max(a, b); };
    // Candidates sorted by the centre of their UV bounds, so that each looks only at those near.
    std::vector<int> byU = candidates;
    auto centreU = [&](int k) { return 0.5 * (islands[static_cast<std::size_t>(k)].lo.x + islands[static_cast<std::size_t>(k)].hi.x); };
    std::stable_sort(byU.begin(), byU.end(), [&](int a, int b) { return centreU(a) < centreU(b); });
    std::vector<bool> paired(islands.size(), false);
    std::map<std::pair<int, int>, UvMirroredPair> mirrored;
    for (int a : candidates) {
        if (paired[static_cast<std::size_t>(a)]) continue;
        const Island& A = islands[static_cast<std::size_t>(a)];
        if (std::abs(A.centroid[axis] - static_cast<double>(plane.offset)) <= tolerance) continue;
        const glm::dvec3 image = reflect(A.centroid);
        // Coinciding bounds (IoU ≥ 0.75) have centres closer than their widths.
        const double reach = A.hi.x - A.lo.x;
        const double cu = centreU(a);
        auto it = std::lower_bound(byU.begin(), byU.end(), cu - reach, [&](int k, double u) { return centreU(k) < u; });
        int best = -1;
        double bestDistance = tolerance;
        for (; it != byU.end() && centreU(*it) <= cu + reach; ++it) {
            const int b = *it;
            if (b == a || paired[static_cast<std::size_t>(b)]) continue;
            const Island& B = islands[static_cast<std::size_t>(b)];
            if (iou(A, B) < kMirrorIoU || ratio(A.uvArea, B.uvArea) < kMirrorAreaRatio ||
                ratio(A.surfaceArea, B.surfaceArea) < kMirrorAreaRatio)
                continue;
            const double dist = glm::length(image - B.centroid);
            if (dist <= tolerance && (best < 0 || dist < bestDistance || (dist == bestDistance && b < best))) {
                bestDistance = dist;
                best = b;
            }
        }
        if (best < 0) continue;
        paired[static_cast<std::size_t>(a)] = paired[static_cast<std::size_t>(best)] = true;
        const Island& B = islands[static_cast<std::size_t>(best)];
        const bool swap = B.region < A.region;
        UvMirroredPair& pair = mirrored[{std::min(A.region, B.region), std::max(A.region, B.region)}];
        pair.regionA = std::min(A.region, B.region);
        pair.regionB = std::max(A.region, B.region);
        ++pair.islandPairs;
        pair.trianglesA += swap ? B.triangles : A.triangles;
        pair.trianglesB += swap ? A.triangles : B.triangles;
    }
    for (const auto& [regions, pair] : mirrored) d.mirroredPairs.push_back(pair);
    return d;
}

} // namespace dermis
