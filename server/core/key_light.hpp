// Dermis core — the key light's shadow camera (`render.key_light`, core/render_settings.hpp
// KeyLight): the orthographic view from a directional light that the renderer draws the shadow
// map with, and what a texel of that map spans.
//
//   framing: the same sphere as the frame camera's (core/camera.hpp): centre = the middle of the
//            posed bounds, radius = half their diagonal + the displacement scale (at least
//            1e-4), so that everything the frame can show casts into the map;
//   view:    the eye at centre + 2·radius·l (l the unit direction towards the light), looking at
//            the centre; up +y, or +z when l is within ~2.6° of ±y;
//   volume:  x, y in [−radius, radius], depth from radius to 3·radius in front of the eye
//            (clip z −1 … 1 = nearest … farthest from the light).
//
// Pure single-precision math, like camera.hpp. Preconditions: finite bounds with min ≤ max, a
// finite non-negative displacement scale, a direction that is not zero (validateRenderSettings
// checks the key light); outside them the results may be non-finite, nothing throws.
#pragma once

#include "render_settings.hpp"

#include <glm/glm.hpp>

namespace dermis {

struct ShadowCamera {
    glm::mat4 viewProj{1.0f};            ///< world → the shadow map's clip space
    glm::vec3 towardsLight{0.0f, 1.0f, 0.0f}; ///< unit, from the surface towards the light
    float radius = 0.0f;                 ///< of the framed sphere (world units)
    float texelWorld = 0.0f;             ///< world units one texel of a mapSize² map spans
    float depthRange = 0.0f;             ///< world units between clip z −1 and 1
};

/// The unit direction towards `light` (its direction normalised in double precision).
glm::vec3 keyLightDirection(const KeyLight& light);

/// The shadow camera of a directional light towards `towardsLight` (unit) for a character with
/// posed bounds [boundsMin, boundsMax] displaced by at most `displacementScale`, for a map of
/// mapSize² texels (≥ 1).
ShadowCamera shadowCamera(glm::vec3 boundsMin, glm::vec3 boundsMax, double displacementScale,
                          glm::vec3 towardsLight, int mapSize);

} // namespace dermis
