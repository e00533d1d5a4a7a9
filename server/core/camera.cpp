#include "camera.hpp"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>

namespace dermis {

Bounds framingBounds(const std::vector<SkinnedPart>& parts) {
    glm::vec3 lo(INFINITY), hi(-INFINITY);
    for (const SkinnedPart& p : parts)
        for (const glm::vec3& v : p.positions)
            if (std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z)) {
                lo = glm::min(lo, v);
                hi = glm::max(hi, v);
            }
    if (!(lo.x <= hi.x)) return {glm::vec3(-1.0f), glm::vec3(1.0f)};
    return {lo, hi};
}

// Every expression below is the one the renderer used before this module existed, in the same
// order and precision: the reference images depend on the matrices bit for bit.
FrameCamera frameCamera(glm::vec3 boundsMin, glm::vec3 boundsMax, double displacementScale,
                        const Camera& camera, int width, int height) {
    FrameCamera c;
    c.width = width;
    c.height = height;
    const glm::vec3 lo = boundsMin, hi = boundsMax;
    const glm::vec3 boundsCentre = 0.5f * (lo + hi);
    const glm::vec3 centre =
        camera.target ? glm::vec3(static_cast<float>((*camera.target)[0]),
                                  static_cast<float>((*camera.target)[1]),
                                  static_cast<float>((*camera.target)[2]))
                      : boundsCentre;
    const float radius =
        std::max(0.5f * glm::length(hi - lo) + static_cast<float>(displacementScale), 1e-4f);
    const float fovY = glm::radians(30.0f);
    const float aspect = static_cast<float>(width) / static_cast<float>(height);
    const float fovX = 2.0f * std::atan(std::tan(fovY * 0.5f) * aspect);
    const float distance = camera.distance ? static_cast<float>(*camera.distance)
                                           : radius / std::sin(0.5f * std::min(fovX, fovY)) * 1.02f;
    const float yaw = glm::radians(static_cast<float>(camera.yaw));
    const float pitch = glm::radians(static_cast<float>(camera.pitch));
    // From the target towards the eye.
    const glm::vec3 dir(std::sin(yaw) * std::cos(pitch), std::sin(pitch),
                        std::cos(yaw) * std::cos(pitch));
    const glm::vec3 eye = centre + dir * distance;
    const glm::vec3 worldUp =
        std::abs(dir.y) > 0.999f ? glm::vec3(0, 0, -dir.y) : glm::vec3(0, 1, 0);
    // A target away from the bounds centre: the depth range grows by that offset, so that the
    // whole character stays between the planes (without a target the offset is 0: unchanged).
    const float reach = camera.target ? radius + glm::length(centre - boundsCentre) : radius;
    const float zNear = std::max({distance - reach * 1.5f, distance * 0.01f, 1e-4f});
    const float zFar = distance + reach * 1.5f;

    c.view = glm::lookAt(eye, centre, worldUp);
    // Flip y so that GL's first row (bottom) holds the top of the picture: readback is row 0 first.
    c.proj = glm::scale(glm::mat4(1.0f), glm::vec3(1.0f, -1.0f, 1.0f)) *
             glm::perspective(fovY, aspect, zNear, zFar);
    c.viewProj = c.proj * c.view;
    c.eye = eye;
    c.target = centre;
    c.forward = -dir;
    c.right = glm::normalize(glm::cross(-dir, worldUp));
    c.up = glm::cross(c.right, -dir);
    c.lightDir = glm::normalize(-0.45f * c.right + 0.65f * c.up + 0.6f * dir);
    c.fovY = fovY;
    c.aspect = aspect;
    c.radius = radius;
    c.distance = distance;
    c.zNear = zNear;
    c.zFar = zFar;
    return c;
}

std::optional<glm::dvec2> projectToPixel(const FrameCamera& camera, glm::vec3 world) {
    const glm::dvec4 clip = glm::dmat4(camera.viewProj) * glm::dvec4(glm::dvec3(world), 1.0);
    if (!(clip.w > 0.0)) return std::nullopt;
    // With the flipped projection, NDC y = −1 is row 0 (the top of the picture).
    const double ndcX = clip.x / clip.w, ndcY = clip.y / clip.w;
    return glm::dvec2((ndcX + 1.0) * 0.5 * camera.width, (ndcY + 1.0) * 0.5 * camera.height);
}

Ray pixelRay(const FrameCamera& camera, glm::dvec2 pixel) {
    // Back through viewProj (in double): the pixel on the far plane, seen from the eye. Using the
    // matrix itself keeps the ray consistent with projectToPixel and with the rasterised frame.
    const double ndcX = 2.0 * pixel.x / camera.width - 1.0;
    const double ndcY = 2.0 * pixel.y / camera.height - 1.0; // row 0 = −1 (flipped projection)
    const glm::dvec4 far =
        glm::inverse(glm::dmat4(camera.viewProj)) * glm::dvec4(ndcX, ndcY, 1.0, 1.0);
    const glm::dvec3 origin(camera.eye);
    return {origin, glm::normalize(glm::dvec3(far) / far.w - origin)};
}

double autoDisplacementScale(const Model& model) {
    const Bounds b = framingBounds(skin(model, worldMatrices(model, restPose(model))));
    const glm::vec3 ext = b.max - b.min;
    const double m = std::max({ext.x, ext.y, ext.z});
    return m > 0.0 && std::isfinite(m) ? 0.01 * m : 0.01;
}

} // namespace dermis
