// Dermis core — the orbit camera of a frame (SPEC §2b "render.camera"): framing on the posed
// bounds, view and projection matrices, the key light, and the mapping between world points and
// frame pixels that a pick (SPEC §4 "Pick") needs to cast a ray from a pixel of a frame.
//
//   framing:  centre = middle of the posed bounds, or the camera's `target` when it has one (a
//             world point: the editor's pan, frame-selection and orbit-about); radius = half the
//             bounds' diagonal + the displacement scale (the furthest a unit height can push the
//             surface), at least 1e-4;
//   lens:     30° vertical field of view, aspect = width / height;
//   distance: explicit, or "auto": the bounding sphere fits the narrower field of view, + 2%;
//   orbit:    the eye sits at centre + distance · (sin yaw · cos pitch, sin pitch,
//             cos yaw · cos pitch) (degrees; yaw 0 looks along −z from +z); world up is +y,
//             except within ~2.6° of the poles (|pitch| ≈ 90), where it is −z·sign(pitch);
//   depth:    near = max(distance − 1.5·reach, 1% of distance, 1e-4), far = distance + 1.5·reach,
//             reach = radius + |target − bounds centre| (= radius without a target);
//   picture:  the projection is flipped in y so that row 0 of a read-back frame is the top of the
//             picture (GL's first row is its bottom);
//   light:    a key light above-left of the eye, towards the scene, fixed to the camera.
//
// Pixel coordinates: x to the right, y downwards, in pixels of the frame; pixel (col, row)
// covers [col, col+1) × [row, row+1), so its centre is (col + 0.5, row + 0.5).
//
// Pure single-precision math (the renderer uploads these matrices as they are; the frames'
// reference images depend on every bit). Preconditions: what validateRenderSettings accepts
// (width, height ≥ 1; pitch in [−90, 90]; distance finite and > 0 when set; displacement scale
// finite and ≥ 0) and finite bounds with min ≤ max. Outside them the results may be non-finite;
// nothing throws or aborts.
#pragma once

#include "rig.hpp"
#include "render_settings.hpp"

#include <glm/glm.hpp>

#include <optional>
#include <vector>

namespace dermis {

/// An axis-aligned box in world space.
struct Bounds {
    glm::vec3 min{-1.0f}, max{1.0f};
};

/// The bounds a frame is framed on: every finite posed position of every part. Parts without a
/// finite vertex give the cube [−1, 1]³, so that an empty model still gets a camera.
Bounds framingBounds(const std::vector<SkinnedPart>& parts);

/// The displacement scale "auto" resolves to: 1% of the largest extent of the rest-pose bounds
/// (a bulge of L·h = 1 rises 1% of the character's height). Bump mapping uses 0.25 × this ×
/// bump_strength as the height of a bump-map unit.
double autoDisplacementScale(const Model& model);

/// One frame's camera (see the header comment for the conventions).
struct FrameCamera {
    glm::mat4 view{1.0f};                 ///< world → eye (glm::lookAt)
    glm::mat4 proj{1.0f};                 ///< eye → clip, y flipped (row 0 = top)
    glm::mat4 viewProj{1.0f};             ///< proj · view
    glm::vec3 eye{0.0f};                  ///< camera position
    glm::vec3 target{0.0f};               ///< the point looked at: Camera::target or the bounds' centre
    glm::vec3 forward{0.0f, 0.0f, -1.0f}; ///< unit, from the eye towards the target
    glm::vec3 right{1.0f, 0.0f, 0.0f};    ///< unit, the picture's +x in world space
    glm::vec3 up{0.0f, 1.0f, 0.0f};       ///< unit, the picture's up (towards row 0)
    glm::vec3 lightDir{0.0f, 0.0f, 1.0f}; ///< unit, from the surface towards the key light
    float fovY = 0.0f;                    ///< vertical field of view, radians
    float aspect = 1.0f;                  ///< width / height
    float radius = 0.0f;   ///< framing radius (bounds half-diagonal + displacement scale)
    float distance = 0.0f; ///< eye to target
    float zNear = 0.0f, zFar = 0.0f;
    int width = 1, height = 1; ///< frame size in pixels
};

/// The camera of a width × height frame of a character whose posed bounds are
/// [boundsMin, boundsMax], displaced by at most `displacementScale` (world units per unit
/// height), seen from `camera` (yaw, pitch in degrees; distance or auto).
FrameCamera frameCamera(glm::vec3 boundsMin, glm::vec3 boundsMax, double displacementScale,
                        const Camera& camera, int width, int height);

/// Where a world point lands in the frame, in pixel coordinates (row 0 = top; may lie outside
/// [0, width] × [0, height]). nullopt when the point is at or behind the eye's plane. Computed
/// from viewProj in double precision.
std::optional<glm::dvec2> projectToPixel(const FrameCamera& camera, glm::vec3 world);

/// A half-line in world space: origin + s · direction, s ≥ 0; |direction| = 1.
struct Ray {
    glm::dvec3 origin{0.0};
    glm::dvec3 direction{0.0, 0.0, -1.0};
};

/// The ray from the eye through the point `pixel` (pixel coordinates, see above; the centre of
/// pixel (col, row) is (col + 0.5, row + 0.5)): every world point on it projects to `pixel`.
/// Any finite pixel is accepted, also outside the frame.
Ray pixelRay(const FrameCamera& camera, glm::dvec2 pixel);

} // namespace dermis
