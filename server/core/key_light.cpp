#include "key_light.hpp"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>

namespace dermis {

glm::vec3 keyLightDirection(const KeyLight& light) {
    const glm::dvec3 d(light.direction[0], light.direction[1], light.direction[2]);
    const double len = glm::length(d);
    return len > 0.0 ? glm::vec3(d / len) : glm::vec3(0.0f, 1.0f, 0.0f);
}

ShadowCamera shadowCamera(glm::vec3 boundsMin, glm::vec3 boundsMax, double displacementScale,
                          glm::vec3 towardsLight, int mapSize) {
    ShadowCamera sc;
    const glm::vec3 centre = 0.5f * (boundsMin + boundsMax);
    sc.radius = std::max(0.5f * glm::length(boundsMax - boundsMin) + static_cast<float>(displacementScale), 1e-4f);
    sc.towardsLight = glm::normalize(towardsLight);
    const glm::vec3 up = std::abs(sc.towardsLight.y) > 0.999f ? glm::vec3(0.0f, 0.0f, 1.0f) : glm::vec3(0.0f, 1.0f, 0.0f);
    const glm::vec3 eye = centre + 2.0f * sc.radius * sc.towardsLight;
    const glm::mat4 view = glm::lookAt(eye, centre, up);
    const glm::mat4 proj = glm::ortho(-sc.radius, sc.radius, -sc.radius, sc.radius, sc.radius, 3.0f * sc.radius);
    sc.viewProj = proj * view;
    sc.texelWorld = 2.0f * sc.radius / static_cast<float>(std::max(mapSize, 1));
    sc.depthRange = 2.0f * sc.radius;
    return sc;
}

} // namespace dermis
