// Dermis core — the scene document `dermis.scene/1` (SPEC §2b) and the pattern manifest
// `dermis.patterns/1` (SPEC §3).
//
// Parsing validates every field and applies defaults; errors name the offending field by JSON
// pointer (RFC 6901, e.g. "/placements/3/theta_max") in Error::field and in the message.
// Serialising a parsed Scene writes every field explicitly, so parse → serialise → parse →
// serialise is byte-stable. Unknown fields are kept nowhere (they are ignored).
// No file access: paths (model, patterns, base map) stay strings, resolved by a shell.
#pragma once

#include "deform.hpp"
#include "heightmap.hpp"
#include "render_settings.hpp"
#include "result.hpp"
#include "texture_layout.hpp"

#include <nlohmann/json_fwd.hpp>

#include <array>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace dermis {

/// One entry of the built-in pattern library.
struct PatternInfo {
    std::string id;          ///< [a-z0-9_]+
    std::string file;        ///< image file name, relative to the manifest
    PatternKind kind = PatternKind::Wrinkle;
    DeformModel model = DeformModel::Scale;
    Target target = Target::Bump;
    std::string joint;       ///< suggested joint role ("elbow", "spine", …)
    std::string axis = "x";  ///< suggested axis
    double thetaMin = 0.0, thetaMax = 90.0;
    std::string description;
};

struct PatternManifest {
    std::vector<PatternInfo> patterns;
    const PatternInfo* find(const std::string& id) const;
};

/// Parses a `dermis.patterns/1` manifest: {"format": "dermis.patterns/1", "patterns": [ … ]}.
Result<PatternManifest> parsePatternManifest(const nlohmann::json& doc);
nlohmann::json toJson(const PatternManifest& manifest);

/// A placement's `projection` (SPEC §8): "uv" (the paper's: a footprint in texture space) or
/// "surface" (a decal anchored on the rest surface, projected into the layout in use).
enum class Projection { Uv, Surface };
std::string_view toString(Projection p);
std::optional<Projection> projectionFromString(std::string_view s);

/// Where a surface placement sits, in bind (rest-pose model) space: MeshPart positions' space.
/// In the document: "anchor": {"position": [x, y, z], "normal": [x, y, z], "tangent": [x, y, z]},
/// all three required for a surface placement.
struct SurfaceAnchor {
    std::array<double, 3> position{0, 0, 0}; ///< each coordinate in [−kMaxAnchorCoordinate, kMaxAnchorCoordinate]
    std::array<double, 3> normal{0, 0, 1};  ///< unit (normalised on parse)
    /// The pattern's u direction; made ⟂ normal and unit on parse (Gram–Schmidt; a tangent already
    /// orthonormal to within 1e-12 is kept bit for bit, so parse → serialise is stable). A tangent
    /// parallel to the normal is an error.
    std::array<double, 3> tangent{1, 0, 0};
};

struct Placement {
    std::string id;                      ///< unique within the scene
    std::string pattern;                 ///< key of Scene::patterns, or a built-in pattern id
    std::array<double, 2> center{0.5, 0.5}; ///< UV, each in [−kMaxPlacementCenter, kMaxPlacementCenter]
    std::array<double, 2> scale{0.1, 0.1};  ///< UV size of the footprint, in (0, kMaxPlacementScale]
    double rotation = 0.0;               ///< degrees, counter-clockwise in (u, v) per SPEC; |r| ≤ kMaxTurnAngle
    std::string joint;                   ///< joint name in the model
    std::string axisName = "x";          ///< "x", "y", "z", or "" when `axis` was a vector
    std::array<double, 3> axis{1, 0, 0}; ///< unit vector (normalised on parse)
    double thetaMin = 0.0, thetaMax = 90.0, h = 1.0; ///< θ in [−kMaxAngle, kMaxAngle], h in [0, kMaxPlacementHeight]
    DeformModel model = DeformModel::Scale;
    Target target = Target::Bump;
    Response response = Response::Log2;
    bool enabled = true; ///< false: kept in the document, contributes nothing (SPEC §6)
    std::string label;   ///< free text for people, ≤ kMaxLabelLength bytes of UTF-8
    // SPEC §8: center/scale/rotation are used by projection Uv; anchor/size/depth by Surface
    // (rotation turns the pattern about the anchor normal there too).
    Projection projection = Projection::Uv;
    SurfaceAnchor anchor;
    std::array<double, 2> size{0.1, 0.1}; ///< model units (w along tangent, h along normal × tangent), each in (0, kMaxSurfaceSize]
    std::optional<double> depth;          ///< model units in (0, kMaxSurfaceSize]; absent ("auto") = max(w, h) / 2

    /// The depth in use: `depth`, else max(size) / 2 (SPEC §8).
    double depthOrDefault() const;
};

/// Longest placement label, in bytes.
constexpr std::size_t kMaxLabelLength = 120;

// Ranges of the scene document's numbers (docs/scenes.md "Scene documents"; schemas/scene.json agrees).
// parseScene rejects anything outside with InvalidArgument naming the field; the bounds keep every
// sum finite: a texel's height is at most kMaxPlacements·h·|L| ≤ 256·100·1 (L = response ∈ [−1, 1]
// times a pattern value in [−1, 1]), so 1e39 can no longer fill a map with inf.
constexpr double kMaxPlacementHeight = 100.0; ///< h ∈ [0, 100]
constexpr double kMaxPlacementScale = 16.0;   ///< each scale component ∈ (0, 16] UV
constexpr double kMaxPlacementCenter = 16.0;  ///< each center component ∈ [−16, 16] UV
constexpr double kMaxAngle = 360.0;      ///< degrees: theta_min/max, pose axis_angles ∈ [−360, 360]
constexpr double kMaxTurnAngle = 3600.0; ///< degrees: footprint rotation, camera yaw ∈ [−3600, 3600]
                                         ///< (ten turns: editors may accumulate, they are periodic)
constexpr double kMaxPoseTime = 86400.0;        ///< pose time ∈ [0, 86400] s
constexpr double kMaxMorphWeight = 10.0;        ///< pose morph weights ∈ [−10, 10]
constexpr double kMaxCameraDistance = 10000.0;  ///< camera distance ∈ (0, 10000] model units
constexpr double kMaxCameraTarget = 1.0e6;      ///< each camera target coordinate ∈ [−1e6, 1e6]
constexpr double kMaxDisplacementScale = 1000.0; ///< displacement_scale ∈ [0, 1000]
constexpr double kMaxBumpStrength = 100.0;       ///< bump_strength ∈ [0, 100]
constexpr double kMaxAnchorCoordinate = 1.0e6;   ///< each anchor position coordinate ∈ [−1e6, 1e6]
constexpr double kMaxSurfaceSize = 10000.0;      ///< surface size w, h and depth ∈ (0, 10000] model units

/// A joint override of the pose: exactly one of rotation / axisAngles is set.
struct JointPose {
    std::optional<std::array<double, 4>> rotation; ///< [x, y, z, w], normalised on parse
    std::optional<std::array<double, 3>> axisAngles; ///< degrees about x, y, z (absent = 0)
};

struct Pose {
    std::optional<std::string> animation; ///< clip name; absent = the model's first clip
    double time = 0.0;                    ///< seconds, ≥ 0 (clamped to the clip when evaluated)
    std::map<std::string, JointPose> joints;
    /// Morph weights by name (Model::morphWeights' names, glTF mesh.extras.targetNames): each
    /// sets every weight of that name, over the clip's.
    std::map<std::string, double> morphs;
};

struct Scene {
    std::string model = "builtin:default";
    UvLayoutMode uvLayout = UvLayoutMode::Auto; ///< SPEC §8 "Height-map layout"
    std::array<int, 2> heightmapSize{1024, 1024}; ///< each in [1, kMaxHeightmapSize]
    std::optional<std::string> heightmapBase;      ///< static height map path
    std::map<std::string, std::string> patterns;   ///< custom pattern id → path
    std::vector<Placement> placements;
    Pose pose;
    RenderSettings render;
};

/// Parses and validates a scene document. `manifest` supplies the built-in pattern ids (a
/// placement's pattern must be a key of "patterns" or a built-in id) and the per-kind defaults of
/// `model`/`target` when a placement omits them (custom patterns default to scale/bump).
/// Fails with the JSON pointer of the first offending field.
Result<Scene> parseScene(const nlohmann::json& doc, const PatternManifest& manifest);
/// Parses text first (malformed JSON → ErrorCode::Parse, field "").
Result<Scene> parseSceneText(const std::string& text, const PatternManifest& manifest);
/// Serialises with every field explicit ("auto" where optional values are absent).
nlohmann::json toJson(const Scene& scene);

/// RFC 6901 escaping of one JSON-pointer reference token ("~" → "~0", "/" → "~1"), for building
/// Error::field values such as "/pose/joints/" + jsonPointerEscape(jointName).
std::string jsonPointerEscape(const std::string& token);

} // namespace dermis
