// The outline of a placement's footprint in the layout in use. See surface_outline.hpp.
//
// Per triangle: the decal's seven conditions as linear functions of the barycentric coordinates
// (their values at the corners, blended), the triangle clipped by them (Sutherland–Hodgman, each
// polygon edge labelled with what it lies on: a triangle edge or a clipping plane), the plane
// edges emitted as segments. Polygon corners between a plane edge and a triangle edge are put at
// that plane's zero on that edge, computed from the edge's corners in a fixed order (by UV, then
// position), so that the two triangles sharing the edge give the same point bit for bit. Along
// the way, the anchor's UV: each triangle's closest point to the anchor (Ericson's), its normal
// interpolated there.
#include "surface_outline.hpp"

#include "bake.hpp"
#include "disjoint_sets.hpp"
#include "heightmap.hpp"
#include "surface_query.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <unordered_map>

namespace dermis {

namespace {

constexpr const char* kWhere = "dermis::surfaceFootprintOutline";

/// The decal's conditions, each "value ≤ 0 inside": x − w/2, −x − w/2, y − h/2, −y − h/2,
/// z − depth, −z − depth, −normal·n (x, y, z: (p − c)·t, ·b, ·n).
constexpr int kPlanes = 7;
/// Polygon edge labels: 0 … kPlanes − 1 a plane; kPlanes + e triangle edge e (corner e → e + 1).
constexpr int kTriangleEdge = kPlanes;

struct PolyVertex {
    glm::dvec3 w;  ///< barycentric weights of the triangle's corners
    int label = 0; ///< of the edge from this vertex to the next
};

using Polygon = std::vector<PolyVertex>;

/// One triangle's corner data: the plane values, UVs and positions (for the fixed edge order).
struct Corners {
    double f[kPlanes][3];
    glm::dvec2 uv[3];
    glm::dvec3 position[3];
};

double planeAt(const Corners& c, int k, const glm::dvec3& w) {
    return w.x * c.f[k][0] + w.y * c.f[k][1] + w.z * c.f[k][2];
}

/// Clips `poly` by plane k (keeps value ≤ 0) into `out`.
void clip(const Polygon& poly, const Corners& c, int k, Polygon& out) {
    out.clear();
    const std::size_t m = poly.size();
    for (std::size_t j = 0; j < m; ++j) {
        const PolyVertex& a = poly[j];
        const PolyVertex& b = poly[(j + 1) % m];
        const double da = planeAt(c, k, a.w), db = planeAt(c, k, b.w);
        const bool inA = da <= 0.0, inB = db <= 0.0;
        if (inA) out.push_back(a);
        if (inA != inB) {
            const double t = da / (da - db);
            PolyVertex i{a.w + t * (b.w - a.w), inA ? k : a.label};
            out.push_back(i);
        }
    }
}

/// Whether corner a comes before corner b in the fixed order of an edge's ends.
bool cornerBefore(const Corners& c, int a, int b) {
    const glm::dvec2 ua = c.uv[a], ub = c.uv[b];
    if (ua.x != ub.x) return ua.x < ub.x;
    if (ua.y != ub.y) return ua.y < ub.y;
    const glm::dvec3 pa = c.position[a], pb = c.position[b];
    if (pa.x != pb.x) return pa.x < pb.x;
    if (pa.y != pb.y) return pa.y < pb.y;
    return pa.z < pb.z;
}

/// The UV where plane k's value is 0 on triangle edge e, from the edge's ends in the fixed order.
glm::dvec2 crossingOnEdge(const Corners& c, int k, int e) {
    int a = e, b = (e + 1) % 3;
    if (cornerBefore(c, b, a)) std::swap(a, b);
    const double fa = c.f[k][a], fb = c.f[k][b];
    double t = fa != fb ? fa / (fa - fb) : 0.0;
    t = std::clamp(t, 0.0, 1.0);
    return c.uv[a] + t * (c.uv[b] - c.uv[a]);
}

/// The UV of polygon vertex j (its edge in is poly[j − 1]'s label, its edge out poly[j]'s).
glm::dvec2 uvOf(const Polygon& poly, std::size_t j, const Corners& c) {
    const int in = poly[(j + poly.size() - 1) % poly.size()].label, out = poly[j].label;
    if (in < kPlanes && out >= kTriangleEdge) return crossingOnEdge(c, in, out - kTriangleEdge);
    if (out < kPlanes && in >= kTriangleEdge) return crossingOnEdge(c, out, in - kTriangleEdge);
    const glm::dvec3& w = poly[j].w;
    return w.x * c.uv[0] + w.y * c.uv[1] + w.z * c.uv[2];
}

/// Twice the signed area of a polygon in barycentric space (weights 1 and 2 as coordinates).
double area2(const Polygon& poly) {
    double a = 0.0;
    for (std::size_t j = 0; j < poly.size(); ++j) {
        const glm::dvec3& p = poly[j].w;
        const glm::dvec3& q = poly[(j + 1) % poly.size()].w;
        a += p.y * q.z - q.y * p.z;
    }
    return a;
}

/// A UV point's key for welding corners (equal floats, −0 as +0).
std::uint64_t uvKey(glm::vec2 uv) {
    const float u = uv.x + 0.0f, v = uv.y + 0.0f;
    std::uint32_t a = 0, b = 0;
    std::memcpy(&a, &u, 4);
    std::memcpy(&b, &v, 4);
    return (std::uint64_t{a} << 32) | b;
}

/// A triangle holding part of the footprint.
struct Touched {
    glm::dvec2 min{0.0}, max{0.0};
    std::size_t firstSegment = 0, segments = 0; ///< into the collected segments
};

bool isFinite(double x) { return std::isfinite(x); }

Result<SurfaceOutline> uvOutline(const Placement& p) {
    if (!isFinite(p.center[0]) || !isFinite(p.center[1]))
        return makeError(ErrorCode::InvalidArgument, kWhere, "center", "must be finite");
    if (!(p.scale[0] > 0.0) || !(p.scale[1] > 0.0) || !isFinite(p.scale[0]) || !isFinite(p.scale[1]))
        return makeError(ErrorCode::InvalidArgument, kWhere, "scale", "must be finite and > 0");
    if (!isFinite(p.rotation)) return makeError(ErrorCode::InvalidArgument, kWhere, "rotation", "must be finite");
    Footprint f;
    f.center = {p.center[0], p.center[1]};
    f.scale = {p.scale[0], p.scale[1]};
    f.rotationDeg = p.rotation;
    const glm::dvec2 corners[4] = {f.toUV({0, 0}), f.toUV({1, 0}), f.toUV({1, 1}), f.toUV({0, 1})};
    SurfaceOutline out;
    out.projection = Projection::Uv;
    for (int k = 0; k < 4; ++k) {
        const glm::dvec2 a = corners[k], b = corners[(k + 1) % 4];
        out.segments.push_back({a.x, a.y, b.x, b.y});
        out.segmentPiece.push_back(0);
    }
    const auto [lo, hi] = f.uvBounds();
    out.pieces.push_back(OutlinePiece{lo, hi, 0});
    out.anchorUv = f.center;
    return out;
}

} // namespace

Result<SurfaceOutline> surfaceFootprintOutline(const Model& model, const Placement& p, std::size_t maxSegments) {
    if (p.projection == Projection::Uv) return uvOutline(p);
    if (!isFinite(p.size[0]) || !isFinite(p.size[1]) || !(p.size[0] > 0.0) || !(p.size[1] > 0.0))
        return makeError(ErrorCode::InvalidArgument, kWhere, "size", "must be finite and > 0");
    if (!isFinite(p.depthOrDefault()) || !(p.depthOrDefault() > 0.0))
        return makeError(ErrorCode::InvalidArgument, kWhere, "depth", "must be finite and > 0");
    BakePlacement b;
    if (!std::all_of(p.anchor.position.begin(), p.anchor.position.end(), isFinite) || !surfaceFrameOf(p, b))
        return makeError(ErrorCode::InvalidArgument, kWhere, "anchor",
                         "needs a finite position, a non-zero normal and a tangent not parallel to it");
    const bool anyUvs = std::any_of(model.parts.begin(), model.parts.end(), [](const MeshPart& part) {
        return !part.positions.empty() && part.uvs.size() >= part.positions.size();
    });
    if (!anyUvs)
        return makeError(ErrorCode::InvalidArgument, kWhere, "uv_layout",
                         "the layout has no UVs: no part of the model has TEXCOORD_0");
    const SurfaceFrame frame(b);
    const double halfW = 0.5 * b.size.x, halfH = 0.5 * b.size.y, depth = b.depth, reach = frame.reach();
    maxSegments = std::max<std::size_t>(maxSegments, 1);

    SurfaceOutline out;
    std::vector<Touched> touched;
    std::vector<std::array<double, 4>> segments; // per touched triangle, in order
    DisjointSets sets;
    std::unordered_map<std::uint64_t, std::uint32_t> weld; // UV corner → id
    std::unordered_map<std::uint64_t, std::size_t> edgeOwner; // welded UV edge → first touched triangle
    auto weldId = [&](glm::vec2 uv) {
        return weld.emplace(uvKey(uv), static_cast<std::uint32_t>(weld.size())).first->second;
    };
    Polygon poly, scratch;
    poly.reserve(16);
    scratch.reserve(16);
    // The anchor's UV: the closest rest-surface point among the triangles within reach whose
    // interpolated normal there faces the anchor normal, else among all triangles.
    double facingDist2 = INFINITY, anyDist2 = INFINITY;
    glm::dvec2 facingUv(0.0), anyUv(0.0);

    for (const MeshPart& part : model.parts) {
        if (part.positions.empty() || part.uvs.size() < part.positions.size()) continue;
        const bool hasNormals = part.normals.size() == part.positions.size();
        const std::size_t tris = part.indices.size() / 3;
        for (std::size_t t = 0; t < tris; ++t) {
            std::uint32_t v[3];
            bool inRange = true;
            for (int k = 0; k < 3; ++k) {
                v[k] = part.indices[3 * t + static_cast<std::size_t>(k)];
                inRange = inRange && v[k] < part.positions.size();
            }
            if (!inRange) continue;
            Corners c;
            glm::dvec3 lo(INFINITY), hi(-INFINITY);
            for (int k = 0; k < 3; ++k) {
                c.position[k] = glm::dvec3(part.positions[v[k]]);
                c.uv[k] = glm::dvec2(part.uvs[v[k]]);
                lo = glm::min(lo, c.position[k]);
                hi = glm::max(hi, c.position[k]);
            }
            const glm::dvec3 gap = frame.c - glm::clamp(frame.c, lo, hi);
            const double gap2 = glm::dot(gap, gap);
            const bool inReach = gap2 <= reach * reach;
            // Neither within reach nor possibly nearer than the nearest triangle so far.
            if (!inReach && gap2 >= anyDist2) continue;
            const glm::dvec2 e1 = c.uv[1] - c.uv[0], e2 = c.uv[2] - c.uv[0];
            if (e1.x * e2.y - e1.y * e2.x == 0.0) continue; // no UV area
            glm::dvec3 face = glm::cross(c.position[1] - c.position[0], c.position[2] - c.position[0]);
            const double faceLen = glm::length(face);
            face = faceLen > 0.0 ? face / faceLen : glm::dvec3(0, 0, 1);
            {
                const glm::dvec3 w = closestBary(frame.c, c.position[0], c.position[1], c.position[2]);
                const glm::dvec3 q = w.x * c.position[0] + w.y * c.position[1] + w.z * c.position[2];
                const double d2 = glm::dot(q - frame.c, q - frame.c);
                const glm::dvec2 uv = w.x * c.uv[0] + w.y * c.uv[1] + w.z * c.uv[2];
                if (d2 < anyDist2) {
                    anyDist2 = d2;
                    anyUv = uv;
                }
                if (d2 <= reach * reach && d2 < facingDist2) {
                    glm::dvec3 normal = face;
                    if (hasNormals)
                        normal = w.x * glm::dvec3(part.normals[v[0]]) + w.y * glm::dvec3(part.normals[v[1]]) +
                                 w.z * glm::dvec3(part.normals[v[2]]);
                    if (glm::dot(normal, frame.n) > 0.0) {
                        facingDist2 = d2;
                        facingUv = uv;
                    }
                }
            }
            // Far from the anchor: nothing of the decal there.
            if (!inReach) continue;
            for (int k = 0; k < 3; ++k) {
                const glm::dvec3 d = c.position[k] - frame.c;
                const double x = glm::dot(d, frame.t), y = glm::dot(d, frame.b), z = glm::dot(d, frame.n);
                const glm::dvec3 normal = hasNormals ? glm::dvec3(part.normals[v[k]]) : face;
                c.f[0][k] = x - halfW;
                c.f[1][k] = -x - halfW;
                c.f[2][k] = y - halfH;
                c.f[3][k] = -y - halfH;
                c.f[4][k] = z - depth;
                c.f[5][k] = -z - depth;
                c.f[6][k] = -glm::dot(normal, frame.n);
            }
            poly.assign({PolyVertex{{1, 0, 0}, kTriangleEdge + 0}, PolyVertex{{0, 1, 0}, kTriangleEdge + 1},
                         PolyVertex{{0, 0, 1}, kTriangleEdge + 2}});
            for (int k = 0; k < kPlanes && poly.size() >= 3; ++k) {
                // A plane every corner satisfies clips nothing.
                if (c.f[k][0] <= 0.0 && c.f[k][1] <= 0.0 && c.f[k][2] <= 0.0) continue;
                clip(poly, c, k, scratch);
                std::swap(poly, scratch);
            }
            if (poly.size() < 3 || !(std::abs(area2(poly)) > 1e-14)) continue;

            const std::size_t id = sets.add();
            Touched tr;
            tr.firstSegment = segments.size();
            glm::dvec2 uvLo(INFINITY), uvHi(-INFINITY);
            std::vector<glm::dvec2> uvs(poly.size());
            for (std::size_t j = 0; j < poly.size(); ++j) {
                uvs[j] = uvOf(poly, j, c);
                uvLo = glm::min(uvLo, uvs[j]);
                uvHi = glm::max(uvHi, uvs[j]);
            }
            tr.min = uvLo;
            tr.max = uvHi;
            for (std::size_t j = 0; j < poly.size(); ++j) {
                const std::size_t n = (j + 1) % poly.size();
                const int label = poly[j].label;
                if (label < kPlanes) { // the decal's border
                    if (uvs[j] == uvs[n]) continue;
                    if (out.truncated || segments.size() >= maxSegments) {
                        out.truncated = true;
                        continue;
                    }
                    segments.push_back({uvs[j].x, uvs[j].y, uvs[n].x, uvs[n].y});
                    ++tr.segments;
                } else if (glm::length(poly[n].w - poly[j].w) > 1e-12) {
                    // The footprint runs along this triangle edge: the triangle across it (in UV)
                    // holds the same piece.
                    const int e = label - kTriangleEdge;
                    std::uint64_t a = weldId(part.uvs[v[e]]), bb = weldId(part.uvs[v[(e + 1) % 3]]);
                    if (a > bb) std::swap(a, bb);
                    const auto [it, fresh] = edgeOwner.emplace((a << 32) | bb, id);
                    if (!fresh) sets.join(id, it->second);
                }
            }
            touched.push_back(tr);
        }
    }

    if (facingDist2 < INFINITY) out.anchorUv = facingUv;
    else if (anyDist2 < INFINITY) out.anchorUv = anyUv;

    // Pieces, ordered by their first triangle.
    std::unordered_map<std::size_t, std::size_t> pieceOfRoot;
    std::vector<std::size_t> pieceOf(touched.size());
    for (std::size_t i = 0; i < touched.size(); ++i) {
        const std::size_t root = sets.root(i);
        auto [it, fresh] = pieceOfRoot.emplace(root, out.pieces.size());
        if (fresh) out.pieces.push_back(OutlinePiece{touched[i].min, touched[i].max, 0});
        OutlinePiece& piece = out.pieces[it->second];
        piece.min = glm::min(piece.min, touched[i].min);
        piece.max = glm::max(piece.max, touched[i].max);
        ++piece.triangles;
        pieceOf[i] = it->second;
    }
    out.segments = std::move(segments);
    out.segmentPiece.reserve(out.segments.size());
    for (std::size_t i = 0; i < touched.size(); ++i)
        out.segmentPiece.insert(out.segmentPiece.end(), touched[i].segments, pieceOf[i]);
    return out;
}

bool footprintContains(const Model& model, const UvLookup& lookup, const Placement& p, glm::dvec2 uv) {
    if (p.projection == Projection::Uv) {
        Footprint f;
        f.center = {p.center[0], p.center[1]};
        f.scale = {p.scale[0], p.scale[1]};
        f.rotationDeg = p.rotation;
        const glm::dvec2 s = f.toPattern(uv);
        return s.x >= 0.0 && s.x <= 1.0 && s.y >= 0.0 && s.y <= 1.0;
    }
    BakePlacement b;
    if (!surfaceFrameOf(p, b)) return false;
    const SurfaceFrame frame(b);
    for (const UvLookup::Hit& h : lookup.findAll(uv)) {
        if (h.part < 0 || static_cast<std::size_t>(h.part) >= model.parts.size()) continue;
        const MeshPart& part = model.parts[static_cast<std::size_t>(h.part)];
        const std::size_t base = 3 * static_cast<std::size_t>(h.triangle);
        if (base + 2 >= part.indices.size()) continue;
        const bool hasNormals = part.normals.size() == part.positions.size();
        glm::dvec3 pos(0.0), nrm(0.0), corner[3];
        bool inRange = true;
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t v = part.indices[base + static_cast<std::size_t>(k)];
            inRange = inRange && v < part.positions.size();
            if (inRange) corner[k] = glm::dvec3(part.positions[v]);
        }
        if (!inRange) continue;
        glm::dvec3 face = glm::cross(corner[1] - corner[0], corner[2] - corner[0]);
        const double faceLen = glm::length(face);
        face = faceLen > 0.0 ? face / faceLen : glm::dvec3(0, 0, 1);
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t v = part.indices[base + static_cast<std::size_t>(k)];
            pos += static_cast<double>(h.bary[k]) * corner[k];
            nrm += static_cast<double>(h.bary[k]) * (hasNormals ? glm::dvec3(part.normals[v]) : face);
        }
        const double len = glm::length(nrm);
        nrm = len > 1e-12 ? nrm / len : face;
        glm::dvec2 s;
        if (frame.toPattern(pos, nrm, s)) return true;
    }
    return false;
}

} // namespace dermis
