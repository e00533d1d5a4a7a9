// Dermis core — parsing of the scene document `dermis.scene/1` (SPEC §2b): JSON → Scene, one
// parser per field group (heightmap, patterns, placements and their id / pattern / footprint /
// driver / model / projection fields, pose, render), defaults applied, ranges checked; and text → JSON that
// reports a number too large for a double at its JSON pointer (parseSceneText).
//
// Every reader below takes the value and the RFC 6901 pointer of where it sits in the document,
// so that whatever fails can name the field ("/placements/3/theta_max") in Error::field.
// Unknown fields are ignored (SPEC §2b: "more fields may be added"). The reader and the shared
// predicates live in scene_json.hpp; serialisation is in scene.cpp.
#include "scene.hpp"

#include "render_settings.hpp"
#include "scene_json.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <string_view>
#include <utility>

namespace dermis {

using namespace scene_detail;

namespace {

constexpr const char* kSceneWhere = "dermis::parseScene";
constexpr const char* kSceneTextWhere = "dermis::parseSceneText";
constexpr const char* kBuiltinPrefix = "builtin:";

// The numeric ranges (kMaxPlacementHeight, kMaxAngle, …) are public, in scene.hpp. A footprint
// may cover the UV square many times over, but not absurdly: a scale of 1e300 would make every
// texel of the map sample one pattern texel and is surely a typo.

// --- small predicates -------------------------------------------------------------------------

bool isAlnum(char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9');
}

/// Scene-level ids (custom patterns, placements): [A-Za-z0-9_.-]+ starting with a letter, digit
/// or underscore, so that "." and ".." can never be an id (they are URL path segments).
bool isSceneId(std::string_view s) {
    if (s.empty() || s.size() > kMaxIdLength) return false;
    if (!isAlnum(s.front()) && s.front() != '_') return false;
    return std::all_of(s.begin(), s.end(),
                       [](char c) { return isAlnum(c) || c == '_' || c == '.' || c == '-'; });
}

/// Names after "builtin:" select a file in the data folder: [A-Za-z0-9_-]+ only, no path tricks.
bool isBuiltinName(std::string_view s) {
    if (s.empty() || s.size() > kMaxIdLength) return false;
    return std::all_of(s.begin(), s.end(),
                       [](char c) { return isAlnum(c) || c == '_' || c == '-'; });
}

/// Makes `v` unit length. Returns false for a zero vector. A vector that is already unit (to
/// within 1e-12 in squared length) is kept bit for bit, so that parse → serialise → parse does not
/// drift by an ulp.
template <std::size_t N> bool normalizeInPlace(std::array<double, N>& v) {
    double m = 0.0;
    for (double c : v)
        m = std::max(m, std::abs(c));
    if (!(m > 0.0)) return false;
    double sq = 0.0;
    for (double c : v)
        sq += c * c;
    // The tolerance is far above the rounding error of one normalisation (a few ulps) and far
    // below anything that matters to an axis or a rotation.
    if (std::abs(sq - 1.0) <= 1e-12) return true;
    // Scale by the largest component first so that tiny or huge inputs neither underflow nor
    // overflow.
    double sqScaled = 0.0;
    for (double c : v)
        sqScaled += (c / m) * (c / m);
    const double len = std::sqrt(sqScaled);
    for (double& c : v)
        c = (c / m) / len;
    return true;
}

// --- scene sections -----------------------------------------------------------------------------

Status parseHeightmap(const Reader& rd, const json& v, Scene& scene) {
    const std::string ptr = "/heightmap";
    if (auto s = rd.object(v, ptr); !s) return s;
    if (const json* size = Reader::find(v, "size")) {
        auto wh = rd.size(*size, ptr + "/size", 1, kMaxHeightmapSize);
        if (!wh) return wh.error();
        scene.heightmapSize = *wh;
    }
    if (const json* base = Reader::find(v, "base")) {
        auto p = rd.path(*base, ptr + "/base");
        if (!p) return p.error();
        scene.heightmapBase = *p;
    }
    return Ok{};
}

Status parsePatterns(const Reader& rd, const json& v, const PatternManifest& manifest,
                     Scene& scene) {
    const std::string ptr = "/patterns";
    if (auto s = rd.object(v, ptr); !s) return s;
    for (const auto& [id, value] : v.items()) {
        const std::string p = member(ptr, id);
        if (!isSceneId(id))
            return rd.bad(p, "pattern id '" + id +
                                 "' must match [A-Za-z0-9_][A-Za-z0-9_.-]* (at "
                                 "most " +
                                 std::to_string(kMaxIdLength) + " characters)");
        if (manifest.find(id))
            return rd.bad(p, "pattern id '" + id + "' collides with a built-in pattern");
        auto path = rd.path(value, p);
        if (!path) return path.error();
        scene.patterns.emplace(id, *path);
    }
    return Ok{};
}

/// A placement's id: explicit (validated, unique) or generated "p<index>" (suffixed if that is
/// taken). `reservedIds` holds every explicit id of the document (so generated ids avoid them);
/// `seenIds` the ids of the placements before this one.
Status parsePlacementId(const Reader& rd, const json& v, const std::string& ptr, std::size_t index,
                        const std::set<std::string>& reservedIds, std::set<std::string>& seenIds,
                        Placement& out) {
    if (const json* id = Reader::find(v, "id")) {
        auto s = rd.string(*id, ptr + "/id");
        if (!s) return s.error();
        if (!isSceneId(*s))
            return rd.bad(ptr + "/id", "placement id '" + *s +
                                           "' must match [A-Za-z0-9_][A-Za-z0-9_.-]* (at most " +
                                           std::to_string(kMaxIdLength) + " characters)");
        if (seenIds.count(*s)) return rd.bad(ptr + "/id", "duplicate placement id '" + *s + "'");
        out.id = *s;
    } else {
        std::string generated = "p" + std::to_string(index);
        for (int k = 1; reservedIds.count(generated) || seenIds.count(generated); ++k)
            generated = "p" + std::to_string(index) + "_" + std::to_string(k);
        out.id = generated;
    }
    seenIds.insert(out.id);
    return Ok{};
}

/// The pattern (required): a custom pattern of this scene or a built-in one, whose manifest entry
/// supplies the defaults that the placement's own fields may then override.
Status parsePlacementPattern(const Reader& rd, const json& v, const std::string& ptr,
                             const Scene& scene, const PatternManifest& manifest, Placement& out) {
    const json* pattern = Reader::find(v, "pattern");
    if (!pattern) return rd.bad(ptr + "/pattern", "is required");
    auto patternId = rd.string(*pattern, ptr + "/pattern");
    if (!patternId) return patternId.error();
    out.pattern = *patternId;
    if (scene.patterns.count(out.pattern)) {
        // Custom patterns carry no kind: scale model on the bump map, the most common case.
        out.model = DeformModel::Scale;
        out.target = Target::Bump;
    } else if (const PatternInfo* info = manifest.find(out.pattern)) {
        // Built-in ones suggest model, target, axis and theta range through the manifest.
        out.model = info->model;
        out.target = info->target;
        out.thetaMin = info->thetaMin;
        out.thetaMax = info->thetaMax;
        if (auto a = namedAxis(info->axis)) {
            out.axisName = info->axis;
            out.axis = *a;
        }
    } else {
        return rd.bad(ptr + "/pattern",
                      "unknown pattern '" + out.pattern +
                          "': neither a key of \"patterns\" nor a built-in pattern id",
                      ErrorCode::NotFound);
    }
    return Ok{};
}

/// Where the footprint sits in texture space: center, scale, rotation.
Status parsePlacementFootprint(const Reader& rd, const json& v, const std::string& ptr, Placement& out) {
    if (const json* c = Reader::find(v, "center")) {
        auto uv = rd.numbers<2>(*c, ptr + "/center");
        if (!uv) return uv.error();
        for (std::size_t i = 0; i < 2; ++i)
            if (std::abs((*uv)[i]) > kMaxPlacementCenter)
                return rd.bad(member(ptr + "/center", i),
                              "must be in [" + Reader::fmt(-kMaxPlacementCenter) + ", " +
                                  Reader::fmt(kMaxPlacementCenter) + "], got " + Reader::fmt((*uv)[i]));
        out.center = *uv;
    }
    if (const json* s = Reader::find(v, "scale")) {
        auto su = rd.numbers<2>(*s, ptr + "/scale");
        if (!su) return su.error();
        for (std::size_t i = 0; i < 2; ++i)
            if ((*su)[i] <= 0.0 || (*su)[i] > kMaxPlacementScale)
                return rd.bad(member(ptr + "/scale", i), "must be in (0, " +
                                                             Reader::fmt(kMaxPlacementScale) +
                                                             "], got " + Reader::fmt((*su)[i]));
        out.scale = *su;
    }
    if (const json* r = Reader::find(v, "rotation")) {
        auto d = rd.numberIn(*r, ptr + "/rotation", -kMaxTurnAngle, kMaxTurnAngle);
        if (!d) return d.error();
        out.rotation = *d;
    }
    return Ok{};
}

/// What drives it (paper eq. 1–2 inputs): joint (required), axis, theta range, h.
Status parsePlacementDriver(const Reader& rd, const json& v, const std::string& ptr, Placement& out) {
    const json* joint = Reader::find(v, "joint");
    if (!joint) return rd.bad(ptr + "/joint", "is required");
    auto jointName = rd.string(*joint, ptr + "/joint");
    if (!jointName) return jointName.error();
    out.joint = *jointName;

    if (const json* a = Reader::find(v, "axis")) {
        const std::string p = ptr + "/axis";
        if (a->is_string()) {
            auto named = namedAxis(a->get_ref<const std::string&>());
            if (!named) return rd.bad(p, "must be \"x\", \"y\", \"z\" or a 3-vector");
            out.axisName = a->get<std::string>();
            out.axis = *named;
        } else if (a->is_array()) {
            auto vec = rd.numbers<3>(*a, p);
            if (!vec) return vec.error();
            if (!normalizeInPlace(*vec)) return rd.bad(p, "must have a non-zero length");
            out.axisName.clear();
            out.axis = *vec;
        } else {
            return rd.bad(p, "expected \"x\", \"y\", \"z\" or a 3-vector, got " + describeType(*a));
        }
    }

    if (const json* t = Reader::find(v, "theta_min")) {
        auto d = rd.numberIn(*t, ptr + "/theta_min", -kMaxAngle, kMaxAngle);
        if (!d) return d.error();
        out.thetaMin = *d;
    }
    if (const json* t = Reader::find(v, "theta_max")) {
        auto d = rd.numberIn(*t, ptr + "/theta_max", -kMaxAngle, kMaxAngle);
        if (!d) return d.error();
        out.thetaMax = *d;
    }
    if (out.thetaMin == out.thetaMax)
        return rd.bad(ptr + "/theta_max",
                      "must differ from theta_min (" + Reader::fmt(out.thetaMin) + ")");
    if (const json* h = Reader::find(v, "h")) {
        auto d = rd.numberIn(*h, ptr + "/h", 0.0, kMaxPlacementHeight);
        if (!d) return d.error();
        out.h = *d;
    }
    return Ok{};
}

/// How it deforms: model, target map, response curve.
Status parsePlacementModel(const Reader& rd, const json& v, const std::string& ptr, Placement& out) {
    if (const json* m = Reader::find(v, "model")) {
        auto e = rd.enumeration(*m, ptr + "/model", deformModelFromString, "\"scale\" or \"bias\"");
        if (!e) return e.error();
        out.model = *e;
    }
    if (const json* t = Reader::find(v, "target")) {
        auto e =
            rd.enumeration(*t, ptr + "/target", targetFromString, "\"bump\" or \"displacement\"");
        if (!e) return e.error();
        out.target = *e;
    }
    if (const json* r = Reader::find(v, "response")) {
        auto e = rd.enumeration(*r, ptr + "/response", responseFromString,
                                "\"log2\", \"ln\", \"linear\" or \"smoothstep\"");
        if (!e) return e.error();
        out.response = *e;
    }
    return Ok{};
}

/// How the pattern reaches the map (SPEC §8): projection ("uv" default | "surface"), and for a
/// surface placement its anchor {position, normal, tangent} (required), size [w, h] (required)
/// and depth (number or "auto"). The members are checked whenever they are given, so a
/// placement switched back to "uv" keeps valid ones; only "surface" requires them.
Status parsePlacementProjection(const Reader& rd, const json& v, const std::string& ptr,
                                Placement& out) {
    if (const json* p = Reader::find(v, "projection")) {
        auto e = rd.enumeration(*p, ptr + "/projection", projectionFromString,
                                "\"uv\" or \"surface\"");
        if (!e) return e.error();
        out.projection = *e;
    }
    const bool surface = out.projection == Projection::Surface;
    const json* anchor = Reader::find(v, "anchor");
    if (!anchor && surface)
        return rd.bad(ptr + "/anchor",
                      "is required for a surface placement ({\"position\", \"normal\", "
                      "\"tangent\"} in bind space)");
    if (anchor) {
        const std::string ap = ptr + "/anchor";
        if (auto s = rd.object(*anchor, ap); !s) return s;
        for (const char* key : {"position", "normal", "tangent"})
            if (!Reader::find(*anchor, key))
                return rd.bad(ap + "/" + key, "is required (a 3-vector in bind space)");
        auto pos = rd.numbers<3>(*Reader::find(*anchor, "position"), ap + "/position");
        if (!pos) return pos.error();
        for (std::size_t i = 0; i < 3; ++i)
            if (std::abs((*pos)[i]) > kMaxAnchorCoordinate)
                return rd.bad(member(ap + "/position", i),
                              "must be in [" + Reader::fmt(-kMaxAnchorCoordinate) + ", " +
                                  Reader::fmt(kMaxAnchorCoordinate) + "], got " +
                                  Reader::fmt((*pos)[i]));
        auto normal = rd.numbers<3>(*Reader::find(*anchor, "normal"), ap + "/normal");
        if (!normal) return normal.error();
        if (!normalizeInPlace(*normal)) return rd.bad(ap + "/normal", "must have a non-zero length");
        auto tangent = rd.numbers<3>(*Reader::find(*anchor, "tangent"), ap + "/tangent");
        if (!tangent) return tangent.error();
        if (!normalizeInPlace(*tangent))
            return rd.bad(ap + "/tangent", "must have a non-zero length");
        // Gram–Schmidt against the normal, only where it is not already orthogonal (to within
        // the tolerance of normalizeInPlace): a canonical tangent reads back bit for bit.
        double dot = 0.0;
        for (std::size_t i = 0; i < 3; ++i)
            dot += (*tangent)[i] * (*normal)[i];
        if (std::abs(dot) > 1e-12) {
            for (std::size_t i = 0; i < 3; ++i)
                (*tangent)[i] -= dot * (*normal)[i];
            double len = 0.0;
            for (double c : *tangent)
                len += c * c;
            if (!(std::sqrt(len) > 1e-6) || !normalizeInPlace(*tangent))
                return rd.bad(ap + "/tangent", "must not be parallel to the normal");
        }
        out.anchor.position = *pos;
        out.anchor.normal = *normal;
        out.anchor.tangent = *tangent;
    }
    const json* size = Reader::find(v, "size");
    if (!size && surface)
        return rd.bad(ptr + "/size", "is required for a surface placement ([w, h] in model units)");
    if (size) {
        auto wh = rd.numbers<2>(*size, ptr + "/size");
        if (!wh) return wh.error();
        for (std::size_t i = 0; i < 2; ++i)
            if ((*wh)[i] <= 0.0 || (*wh)[i] > kMaxSurfaceSize)
                return rd.bad(member(ptr + "/size", i), "must be in (0, " +
                                                            Reader::fmt(kMaxSurfaceSize) +
                                                            "], got " + Reader::fmt((*wh)[i]));
        out.size = *wh;
    }
    if (const json* d = Reader::find(v, "depth")) {
        const std::string dp = ptr + "/depth";
        if (d->is_string()) {
            if (d->get_ref<const std::string&>() != "auto")
                return rd.bad(dp, "must be \"auto\" or a number");
            out.depth.reset();
        } else {
            if (!d->is_number())
                return rd.bad(dp, "expected \"auto\" or a number, got " + describeType(*d));
            auto n = rd.number(*d, dp);
            if (!n) return n.error();
            if (*n <= 0.0 || *n > kMaxSurfaceSize)
                return rd.bad(dp, "must be in (0, " + Reader::fmt(kMaxSurfaceSize) +
                                      "] (or \"auto\"), got " + Reader::fmt(*n));
            out.depth = *n;
        }
    }
    return Ok{};
}

/// For people and the editor: enabled (default true), label (≤ kMaxLabelLength bytes).
Status parsePlacementMeta(const Reader& rd, const json& v, const std::string& ptr, Placement& out) {
    if (const json* e = Reader::find(v, "enabled")) {
        if (!e->is_boolean())
            return rd.bad(ptr + "/enabled", "expected true or false, got " + describeType(*e));
        out.enabled = e->get<bool>();
    }
    if (const json* l = Reader::find(v, "label")) {
        auto text = rd.string(*l, ptr + "/label", false);
        if (!text) return text.error();
        if (text->size() > kMaxLabelLength)
            return rd.bad(ptr + "/label", "is " + std::to_string(text->size()) +
                                              " bytes, longer than " +
                                              std::to_string(kMaxLabelLength));
        out.label = *text;
    }
    return Ok{};
}

/// One placement, field groups in document order of precedence (the pattern's defaults first).
Status parsePlacement(const Reader& rd, const json& v, std::size_t index, const Scene& scene,
                      const PatternManifest& manifest, const std::set<std::string>& reservedIds,
                      std::set<std::string>& seenIds, Placement& out) {
    const std::string ptr = member("/placements", index);
    if (auto s = rd.object(v, ptr); !s) return s;
    if (auto s = parsePlacementId(rd, v, ptr, index, reservedIds, seenIds, out); !s) return s;
    if (auto s = parsePlacementPattern(rd, v, ptr, scene, manifest, out); !s) return s;
    if (auto s = parsePlacementFootprint(rd, v, ptr, out); !s) return s;
    if (auto s = parsePlacementProjection(rd, v, ptr, out); !s) return s;
    if (auto s = parsePlacementDriver(rd, v, ptr, out); !s) return s;
    if (auto s = parsePlacementMeta(rd, v, ptr, out); !s) return s;
    return parsePlacementModel(rd, v, ptr, out);
}

Status parsePlacements(const Reader& rd, const json& v, const PatternManifest& manifest,
                       Scene& scene) {
    if (auto s = rd.array(v, "/placements"); !s) return s;
    // Explicit ids first, so that a generated "p0" never takes an id that a later placement
    // names explicitly.
    std::set<std::string> reserved;
    for (const json& p : v)
        if (p.is_object())
            if (auto it = p.find("id"); it != p.end() && it->is_string())
                reserved.insert(it->get<std::string>());
    std::set<std::string> seen;
    scene.placements.reserve(v.size());
    for (std::size_t i = 0; i < v.size(); ++i) {
        Placement p;
        if (auto s = parsePlacement(rd, v[i], i, scene, manifest, reserved, seen, p); !s) return s;
        scene.placements.push_back(std::move(p));
    }
    return Ok{};
}

Status parseJointPose(const Reader& rd, const json& v, const std::string& ptr, JointPose& out) {
    if (auto s = rd.object(v, ptr); !s) return s;
    const json* rotation = Reader::find(v, "rotation");
    const json* axisAngles = Reader::find(v, "axis_angles");
    if ((rotation == nullptr) == (axisAngles == nullptr))
        return rd.bad(ptr, "must have exactly one of \"rotation\" and \"axis_angles\"");
    if (rotation) {
        auto q = rd.numbers<4>(*rotation, ptr + "/rotation");
        if (!q) return q.error();
        if (!normalizeInPlace(*q))
            return rd.bad(ptr + "/rotation", "quaternion [x, y, z, w] must have a non-zero length");
        out.rotation = *q;
    } else {
        const std::string p = ptr + "/axis_angles";
        if (auto s = rd.object(*axisAngles, p); !s) return s;
        std::array<double, 3> angles{0, 0, 0};
        static constexpr const char* kNames[3] = {"x", "y", "z"};
        for (auto e = axisAngles->begin(); e != axisAngles->end(); ++e)
            if (e.key() != "x" && e.key() != "y" && e.key() != "z")
                return rd.bad(p + "/" + e.key(), "not an axis: the angles are about x, y and z");
        for (std::size_t i = 0; i < 3; ++i) {
            if (const json* a = Reader::find(*axisAngles, kNames[i])) {
                auto d = rd.numberIn(*a, p + "/" + kNames[i], -kMaxAngle, kMaxAngle);
                if (!d) return d.error();
                angles[i] = *d;
            }
        }
        out.axisAngles = angles;
    }
    return Ok{};
}

Status parsePose(const Reader& rd, const json& v, Pose& pose) {
    const std::string ptr = "/pose";
    if (auto s = rd.object(v, ptr); !s) return s;
    if (const json* a = Reader::find(v, "animation")) {
        auto s = rd.string(*a, ptr + "/animation");
        if (!s) return s.error();
        pose.animation = *s;
    }
    if (const json* t = Reader::find(v, "time")) {
        auto d = rd.numberIn(*t, ptr + "/time", 0.0, kMaxPoseTime);
        if (!d) return d.error();
        pose.time = *d;
    }
    if (const json* joints = Reader::find(v, "joints")) {
        if (auto s = rd.object(*joints, ptr + "/joints"); !s) return s;
        for (const auto& [name, jv] : joints->items()) {
            const std::string p = member(ptr + "/joints", name);
            if (name.empty()) return rd.bad(p, "joint name must not be empty");
            if (!validUtf8(name)) return rd.bad(p, "joint name must be valid UTF-8");
            JointPose jp;
            if (auto s = parseJointPose(rd, jv, p, jp); !s) return s;
            pose.joints.emplace(name, jp);
        }
    }
    if (const json* morphs = Reader::find(v, "morphs")) {
        if (auto s = rd.object(*morphs, ptr + "/morphs"); !s) return s;
        for (const auto& [name, mv] : morphs->items()) {
            const std::string p = member(ptr + "/morphs", name);
            if (name.empty()) return rd.bad(p, "morph target name must not be empty");
            if (!validUtf8(name)) return rd.bad(p, "morph target name must be valid UTF-8");
            auto w = rd.numberIn(mv, p, -kMaxMorphWeight, kMaxMorphWeight);
            if (!w) return w.error();
            pose.morphs.emplace(name, *w);
        }
    }
    return Ok{};
}

/// "auto" (→ nullopt) or a finite number ≥ lo (> lo when `exclusive`).
Result<std::optional<double>> autoOrNumber(const Reader& rd, const json& v, const std::string& ptr,
                                           double lo, bool exclusive) {
    if (v.is_string()) {
        if (v.get_ref<const std::string&>() == "auto") return std::optional<double>{};
        return rd.bad(ptr, "must be \"auto\" or a number");
    }
    if (!v.is_number()) return rd.bad(ptr, "expected \"auto\" or a number, got " + describeType(v));
    auto d = rd.number(v, ptr);
    if (!d) return d.error();
    if (exclusive ? *d <= lo : *d < lo)
        return rd.bad(ptr, std::string(exclusive ? "must be > " : "must be >= ") + Reader::fmt(lo) +
                               " (or \"auto\"), got " + Reader::fmt(*d));
    return std::optional<double>{*d};
}

/// Types only: ranges are checked once, by validateRenderSettings (core/render_settings.hpp).
Status parseRender(const Reader& rd, const json& v, RenderSettings& render) {
    constexpr int kAnyInt = std::numeric_limits<int>::max();
    constexpr double kAny = -std::numeric_limits<double>::infinity();
    const std::string ptr = "/render";
    if (auto s = rd.object(v, ptr); !s) return s;
    if (const json* size = Reader::find(v, "size")) {
        auto wh = rd.size(*size, ptr + "/size", -kAnyInt, kAnyInt);
        if (!wh) return wh.error();
        render.size = *wh;
    }
    if (const json* cam = Reader::find(v, "camera")) {
        const std::string p = ptr + "/camera";
        if (auto s = rd.object(*cam, p); !s) return s;
        if (const json* yaw = Reader::find(*cam, "yaw")) {
            auto d = rd.number(*yaw, p + "/yaw");
            if (!d) return d.error();
            render.camera.yaw = *d;
        }
        if (const json* pitch = Reader::find(*cam, "pitch")) {
            auto d = rd.number(*pitch, p + "/pitch");
            if (!d) return d.error();
            render.camera.pitch = *d;
        }
        if (const json* dist = Reader::find(*cam, "distance")) {
            auto d = autoOrNumber(rd, *dist, p + "/distance", kAny, false);
            if (!d) return d.error();
            render.camera.distance = *d;
        }
    }
    if (const json* ds = Reader::find(v, "displacement_scale")) {
        auto d = autoOrNumber(rd, *ds, ptr + "/displacement_scale", kAny, false);
        if (!d) return d.error();
        render.displacementScale = *d;
    }
    if (const json* bs = Reader::find(v, "bump_strength")) {
        auto d = rd.number(*bs, ptr + "/bump_strength");
        if (!d) return d.error();
        render.bumpStrength = *d;
    }
    if (const json* msaa = Reader::find(v, "msaa")) {
        auto n = rd.integer(*msaa, ptr + "/msaa", -kAnyInt, kAnyInt);
        if (!n) return n.error();
        render.msaa = *n;
    }
    if (const json* aa = Reader::find(v, "aa")) {
        auto e = rd.enumeration(*aa, ptr + "/aa", antiAliasingFromString,
                                "\"auto\", \"msaa\", \"post\" or \"none\"");
        if (!e) return e.error();
        render.aa = *e;
    }
    if (const json* dm = Reader::find(v, "displacement")) {
        auto e = rd.enumeration(*dm, ptr + "/displacement", displacementModeFromString,
                                "\"vertex\" or \"tessellated\"");
        if (!e) return e.error();
        render.displacement = *e;
    }
    if (const json* sh = Reader::find(v, "shading")) {
        auto e = rd.enumeration(*sh, ptr + "/shading", shadingFromString, "\"legacy\", \"pbr\" or \"skin\"");
        if (!e) return e.error();
        render.shading = *e;
    }
    if (const json* ex = Reader::find(v, "exposure")) {
        auto d = rd.number(*ex, ptr + "/exposure");
        if (!d) return d.error();
        render.exposure = *d;
    }
    if (const json* tm = Reader::find(v, "tone_mapping")) {
        auto e = rd.enumeration(*tm, ptr + "/tone_mapping", toneMappingFromString,
                                "\"neutral\", \"aces\" or \"none\"");
        if (!e) return e.error();
        render.toneMapping = *e;
    }
    if (const json* er = Reader::find(v, "environment_rotation")) {
        auto d = rd.number(*er, ptr + "/environment_rotation");
        if (!d) return d.error();
        render.environmentRotation = *d;
    }
    if (const json* en = Reader::find(v, "environment")) {
        auto s = rd.path(*en, ptr + "/environment");
        if (!s) return s.error();
        if (s->rfind(kBuiltinPrefix, 0) == 0 && *s != kBuiltinStudioEnvironment)
            return rd.bad(ptr + "/environment", "the built-in environment is \"" +
                                                   std::string(kBuiltinStudioEnvironment) + "\", got '" + *s + "'");
        render.environment = *s;
    }
    if (const json* kl = Reader::find(v, "key_light")) {
        // null: no key light (what an absent member means), so that a PUT can remove it.
        const std::string p = ptr + "/key_light";
        if (kl->is_null()) {
            render.keyLight.reset();
        } else {
            if (auto s = rd.object(*kl, p); !s) return s;
            KeyLight k;
            if (const json* d = Reader::find(*kl, "direction")) {
                auto a = rd.numbers<3>(*d, p + "/direction");
                if (!a) return a.error();
                k.direction = *a;
            }
            if (const json* in = Reader::find(*kl, "intensity")) {
                auto d = rd.number(*in, p + "/intensity");
                if (!d) return d.error();
                k.intensity = *d;
            }
            if (const json* c = Reader::find(*kl, "color")) {
                auto a = rd.numbers<3>(*c, p + "/color");
                if (!a) return a.error();
                k.color = *a;
            }
            if (const json* sh = Reader::find(*kl, "shadow")) {
                if (!sh->is_boolean())
                    return rd.bad(p + "/shadow", "expected a boolean, got " + describeType(*sh));
                k.shadow = sh->get<bool>();
            }
            render.keyLight = k;
        }
    }
    return validateRenderSettings(render, {}, kSceneWhere);
}

// --- text → json with the pointer of an out-of-range number -------------------------------------

/// Builds the DOM like nlohmann's own SAX DOM parser, but keeps track of where it is, so that a
/// number that overflows a double (1e999 — nlohmann refuses it rather than yield inf) is reported
/// at its JSON pointer like any other non-finite value, not as a bare syntax error.
class TrackingSax final : public json::json_sax_t {
  public:
    explicit TrackingSax(json& root) : root_(root) {}

    bool null() override { return put(json(nullptr)) != nullptr; }
    bool boolean(bool b) override { return put(json(b)) != nullptr; }
    bool number_integer(json::number_integer_t n) override { return put(json(n)) != nullptr; }
    bool number_unsigned(json::number_unsigned_t n) override { return put(json(n)) != nullptr; }
    bool number_float(json::number_float_t d, const json::string_t&) override {
        return put(json(d)) != nullptr;
    }
    bool string(json::string_t& s) override { return put(json(std::move(s))) != nullptr; }
    bool binary(json::binary_t& b) override { return put(json::binary(std::move(b))) != nullptr; }
    bool start_object(std::size_t) override { return open(json::object()); }
    bool key(json::string_t& k) override {
        keys_.back() = k;
        return true;
    }
    bool end_object() override { return close(); }
    bool start_array(std::size_t) override { return open(json::array()); }
    bool end_array() override { return close(); }
    bool parse_error(std::size_t position, const std::string&, const json::exception& ex) override {
        errorId = ex.id;
        errorPosition = position;
        errorWhat = ex.what();
        errorPointer = currentPointer();
        return false;
    }

    int errorId = 0;
    std::size_t errorPosition = 0;
    std::string errorWhat, errorPointer;

  private:
    /// Stores `v` where the parser is (root, next array element or current member).
    json* put(json v) {
        if (stack_.empty()) {
            root_ = std::move(v);
            return &root_;
        }
        json& top = *stack_.back();
        if (top.is_array()) {
            top.push_back(std::move(v));
            return &top.back();
        }
        json& slot = top[keys_.back()];
        slot = std::move(v);
        return &slot;
    }
    bool open(json container) {
        // Only the innermost open container is ever modified, so pointers to the outer ones
        // stay valid while they are on the stack.
        stack_.push_back(put(std::move(container)));
        keys_.emplace_back();
        return true;
    }
    bool close() {
        stack_.pop_back();
        keys_.pop_back();
        return true;
    }
    /// Pointer of the value being read: for arrays the element about to be appended (or, below
    /// the innermost level, the one being filled), for objects the current key.
    std::string currentPointer() const {
        std::string p;
        for (std::size_t i = 0; i < stack_.size(); ++i) {
            const json& c = *stack_[i];
            if (c.is_array())
                p += "/" + std::to_string(i + 1 < stack_.size() ? c.size() - 1 : c.size());
            else
                p += "/" + jsonPointerEscape(keys_[i]);
        }
        return p;
    }

    json& root_;
    std::vector<json*> stack_;
    std::vector<std::string> keys_;
};

/// "[json.exception.parse_error.101] parse error at …" → "parse error at …".
std::string stripExceptionPrefix(const std::string& what) {
    if (!what.empty() && what.front() == '[')
        if (auto close = what.find("] "); close != std::string::npos) return what.substr(close + 2);
    return what;
}

} // namespace

// --- public API ---------------------------------------------------------------------------------

Result<Scene> parseScene(const json& doc, const PatternManifest& manifest) {
    const Reader rd(kSceneWhere);
    if (auto s = rd.object(doc, ""); !s)
        return rd.bad("", "the scene document must be a JSON object, got " + describeType(doc));

    const json* format = Reader::find(doc, "format");
    if (!format) return rd.bad("/format", std::string("is required (\"") + kSceneFormat + "\")");
    auto f = rd.string(*format, "/format");
    if (!f) return f.error();
    if (*f != kSceneFormat)
        return rd.bad("/format", "must be \"" + std::string(kSceneFormat) + "\", got '" + *f + "'",
                      formatErrorCode(*f, "dermis.scene/"));

    Scene scene;
    if (const json* m = Reader::find(doc, "model")) {
        auto s = rd.path(*m, "/model");
        if (!s) return s.error();
        const std::string_view prefix = kBuiltinPrefix;
        if (s->rfind(prefix, 0) == 0 && !isBuiltinName(std::string_view(*s).substr(prefix.size())))
            return rd.bad("/model", "built-in model name '" + *s +
                                        "' must be \"builtin:\" followed by [A-Za-z0-9_-]+");
        scene.model = *s;
    }
    if (const json* l = Reader::find(doc, "uv_layout")) {
        auto e = rd.enumeration(*l, "/uv_layout", uvLayoutModeFromString,
                                "\"auto\", \"model\" or \"generated\"");
        if (!e) return e.error();
        scene.uvLayout = *e;
    }
    if (const json* h = Reader::find(doc, "heightmap"))
        if (auto s = parseHeightmap(rd, *h, scene); !s) return s.error();
    if (const json* p = Reader::find(doc, "patterns"))
        if (auto s = parsePatterns(rd, *p, manifest, scene); !s) return s.error();
    if (const json* p = Reader::find(doc, "placements"))
        if (auto s = parsePlacements(rd, *p, manifest, scene); !s) return s.error();
    if (const json* p = Reader::find(doc, "pose"))
        if (auto s = parsePose(rd, *p, scene.pose); !s) return s.error();
    if (const json* r = Reader::find(doc, "render"))
        if (auto s = parseRender(rd, *r, scene.render); !s) return s.error();
    return scene;
}

Result<Scene> parseSceneText(const std::string& text, const PatternManifest& manifest) {
    json doc;
    TrackingSax sax(doc);
    bool ok = false;
    try {
        ok = json::sax_parse(text, &sax);
    } catch (const json::exception& e) {
        // The SAX interface reports errors through parse_error(); this is a safety net only.
        return makeError(ErrorCode::Parse, kSceneTextWhere, "",
                         "malformed JSON: " + stripExceptionPrefix(e.what()));
    }
    if (!ok) {
        if (sax.errorId == 406) // out_of_range.406: a number too large for a double
            return makeError(ErrorCode::InvalidArgument, kSceneWhere, sax.errorPointer,
                             "must be a finite number (" + stripExceptionPrefix(sax.errorWhat) +
                                 ")");
        return makeError(ErrorCode::Parse, kSceneTextWhere, "",
                         "malformed JSON: " + stripExceptionPrefix(sax.errorWhat));
    }
    return parseScene(doc, manifest);
}

} // namespace dermis
