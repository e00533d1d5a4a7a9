// CameraTest — the orbit camera of a frame (core/camera.hpp): framing, the picture's orientation
// (row 0 = top), auto distance, pixel ↔ world mapping for pick, the poles. Pure (no GL).
#include "core/camera.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace dermis;

namespace {

const glm::vec3 kLo(-0.4f, 0.0f, -0.2f), kHi(0.4f, 1.8f, 0.3f); // a standing character

Camera orbit(double yaw, double pitch, std::optional<double> distance = std::nullopt) {
    Camera c;
    c.yaw = yaw;
    c.pitch = pitch;
    c.distance = distance;
    return c;
}

bool finite(const glm::mat4& m) {
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            if (!std::isfinite(m[i][j])) return false;
    return true;
}

/// Distance from point p to the line through the ray.
double distanceToRay(const Ray& r, glm::dvec3 p) {
    const glm::dvec3 d = p - r.origin;
    return glm::length(d - glm::dot(d, r.direction) * r.direction);
}

} // namespace

TEST(CameraTest, FramingBoundsSkipNonFinitePositionsAndDefaultToTheUnitCube) {
    std::vector<SkinnedPart> parts(2);
    parts[0].positions = {{1, 2, 3}, {-1, 0.5f, 4}, {NAN, 100, 100}};
    parts[1].positions = {{0, -2, 3.5f}, {INFINITY, 0, 0}};
    const Bounds b = framingBounds(parts);
    EXPECT_EQ(b.min, glm::vec3(-1, -2, 3));
    EXPECT_EQ(b.max, glm::vec3(1, 2, 4));
    const Bounds none = framingBounds({});
    EXPECT_EQ(none.min, glm::vec3(-1));
    EXPECT_EQ(none.max, glm::vec3(1));
}

TEST(CameraTest, TheBoundsCentreProjectsToTheImageCentre) {
    for (auto [w, h] : {std::pair{256, 256}, std::pair{640, 360}, std::pair{200, 500}})
        for (double yaw : {0.0, 45.0, -120.0, 270.0})
            for (double pitch : {-60.0, 0.0, 10.0, 80.0}) {
                const FrameCamera c = frameCamera(kLo, kHi, 0.02, orbit(yaw, pitch), w, h);
                auto p = projectToPixel(c, 0.5f * (kLo + kHi));
                ASSERT_TRUE(p);
                EXPECT_NEAR(p->x, 0.5 * w, 1e-3 * w) << yaw << " " << pitch;
                EXPECT_NEAR(p->y, 0.5 * h, 1e-3 * h) << yaw << " " << pitch;
            }
}

TEST(CameraTest, AutoDistanceKeepsEveryCornerOfTheBoundsInTheFrame) {
    for (auto [w, h] : {std::pair{256, 256}, std::pair{800, 200}, std::pair{150, 600}})
        for (double yaw : {0.0, 33.0, 90.0, 180.0, -145.0})
            for (double pitch : {-90.0, -45.0, 0.0, 10.0, 70.0, 90.0})
                for (double disp : {0.0, 0.05}) {
                    const FrameCamera c = frameCamera(kLo, kHi, disp, orbit(yaw, pitch), w, h);
                    for (int k = 0; k < 8; ++k) {
                        const glm::vec3 corner(k & 1 ? kHi.x : kLo.x, k & 2 ? kHi.y : kLo.y,
                                               k & 4 ? kHi.z : kLo.z);
                        auto p = projectToPixel(c, corner);
                        ASSERT_TRUE(p) << "corner " << k << " behind the eye";
                        EXPECT_GE(p->x, 0.0)
                            << w << "x" << h << " yaw " << yaw << " pitch " << pitch;
                        EXPECT_LE(p->x, w) << w << "x" << h << " yaw " << yaw << " pitch " << pitch;
                        EXPECT_GE(p->y, 0.0)
                            << w << "x" << h << " yaw " << yaw << " pitch " << pitch;
                        EXPECT_LE(p->y, h) << w << "x" << h << " yaw " << yaw << " pitch " << pitch;
                        // …and between the near and far planes.
                        const glm::vec4 e = c.view * glm::vec4(corner, 1.0f);
                        EXPECT_GT(-e.z, c.zNear);
                        EXPECT_LT(-e.z, c.zFar);
                    }
                }
}

TEST(CameraTest, RowZeroIsTheTopOfThePicture) {
    // From the front at pitch 0: the head (max y) lands in a lower row than the feet, and +x
    // of the world is on the right when seen from +z.
    const FrameCamera c = frameCamera(kLo, kHi, 0.0, orbit(0.0, 0.0), 300, 300);
    auto head = projectToPixel(c, {0.0f, kHi.y, 0.0f});
    auto feet = projectToPixel(c, {0.0f, kLo.y, 0.0f});
    auto right = projectToPixel(c, {kHi.x, 0.9f, 0.0f});
    ASSERT_TRUE(head && feet && right);
    EXPECT_LT(head->y, feet->y);
    EXPECT_GT(right->x, 150.0);
    EXPECT_GT(c.eye.z, kHi.z); // yaw 0 looks along −z
    EXPECT_NEAR(glm::dot(c.forward, glm::vec3(0, 0, -1)), 1.0f, 1e-6f);
}

TEST(CameraTest, ExplicitDistanceIsTheEyeDistance) {
    const FrameCamera c = frameCamera(kLo, kHi, 0.0, orbit(30.0, 20.0, 7.5), 320, 240);
    EXPECT_FLOAT_EQ(c.distance, 7.5f);
    EXPECT_NEAR(glm::length(c.eye - c.target), 7.5f, 1e-5f);
    const FrameCamera a = frameCamera(kLo, kHi, 0.0, orbit(30.0, 20.0), 320, 240);
    EXPECT_GT(a.distance, a.radius); // auto: outside the bounding sphere
    EXPECT_NEAR(a.fovY, glm::radians(30.0f), 1e-7f);
    EXPECT_FLOAT_EQ(a.aspect, 320.0f / 240.0f);
    // A larger displacement scale widens the framing.
    const FrameCamera b = frameCamera(kLo, kHi, 0.5, orbit(30.0, 20.0), 320, 240);
    EXPECT_GT(b.distance, a.distance);
}

TEST(CameraTest, APixelRayPassesThroughThePointThatProjectedThere) {
    for (auto [w, h] : {std::pair{256, 256}, std::pair{640, 200}})
        for (double yaw : {0.0, 75.0, -150.0})
            for (double pitch : {-30.0, 10.0, 89.0}) {
                const FrameCamera c = frameCamera(kLo, kHi, 0.01, orbit(yaw, pitch), w, h);
                for (glm::vec3 p : {glm::vec3(0.1f, 1.6f, 0.05f), glm::vec3(-0.35f, 0.2f, 0.25f),
                                    glm::vec3(0.0f, 0.9f, 0.0f), kLo, kHi}) {
                    auto px = projectToPixel(c, p);
                    ASSERT_TRUE(px);
                    const Ray r = pixelRay(c, *px);
                    EXPECT_NEAR(glm::length(r.direction), 1.0, 1e-12);
                    EXPECT_LT(distanceToRay(r, glm::dvec3(p)), 1e-5 * c.distance)
                        << yaw << " " << pitch;
                    EXPECT_GT(glm::dot(glm::dvec3(p) - r.origin, r.direction), 0.0); // in front
                }
            }
}

TEST(CameraTest, PointsOnAPixelCentreRayProjectToThatPixel) {
    const FrameCamera c = frameCamera(kLo, kHi, 0.0, orbit(-20.0, 15.0), 160, 120);
    for (auto [col, row] :
         {std::pair{0, 0}, std::pair{159, 0}, std::pair{80, 60}, std::pair{3, 117}}) {
        const glm::dvec2 centre(col + 0.5, row + 0.5);
        const Ray r = pixelRay(c, centre);
        for (double f : {0.5, 1.0, 1.3}) {
            const double s = f * c.distance;
            auto px = projectToPixel(c, glm::vec3(r.origin + s * r.direction));
            ASSERT_TRUE(px);
            EXPECT_NEAR(px->x, centre.x, 1e-2);
            EXPECT_NEAR(px->y, centre.y, 1e-2);
        }
    }
    // The image centre's ray is the view axis.
    const Ray axis = pixelRay(c, {80.0, 60.0});
    EXPECT_NEAR(glm::dot(axis.direction, glm::dvec3(c.forward)), 1.0, 1e-6);
}

TEST(CameraTest, PointsBehindTheEyeDoNotProject) {
    const FrameCamera c = frameCamera(kLo, kHi, 0.0, orbit(0.0, 0.0), 100, 100);
    EXPECT_FALSE(projectToPixel(c, c.eye - 2.0f * c.forward));
}

TEST(CameraTest, ThePolesGiveFiniteCameras) {
    for (double pitch : {-90.0, -89.9, 89.9, 90.0})
        for (double yaw : {0.0, 45.0, 180.0}) {
            const FrameCamera c = frameCamera(kLo, kHi, 0.01, orbit(yaw, pitch), 256, 256);
            EXPECT_TRUE(finite(c.view) && finite(c.proj) && finite(c.viewProj))
                << "pitch " << pitch << " yaw " << yaw;
            for (const glm::vec3& v : {c.eye, c.forward, c.right, c.up, c.lightDir})
                EXPECT_TRUE(std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z));
            EXPECT_NEAR(glm::length(c.lightDir), 1.0f, 1e-5f);
            EXPECT_NEAR(std::abs(c.forward.y), 1.0f, 1e-3f);
            auto p = projectToPixel(c, c.target);
            ASSERT_TRUE(p);
            EXPECT_NEAR(p->x, 128.0, 0.1);
            EXPECT_NEAR(p->y, 128.0, 0.1);
            const Ray r = pixelRay(c, {10.5, 200.5});
            EXPECT_TRUE(std::isfinite(r.direction.x) && std::isfinite(r.direction.y) &&
                        std::isfinite(r.direction.z));
        }
}

TEST(CameraTest, TheLightComesFromAboveLeftOfTheEye) {
    const FrameCamera c = frameCamera(kLo, kHi, 0.0, orbit(0.0, 0.0), 200, 200);
    EXPECT_LT(glm::dot(c.lightDir, c.right), 0.0f);
    EXPECT_GT(glm::dot(c.lightDir, c.up), 0.0f);
    EXPECT_LT(glm::dot(c.lightDir, c.forward), 0.0f); // towards the viewer's side
}

TEST(CameraTest, ATargetIsLookedAtAndOrbitedAboutAndTheCharacterStaysInTheDepthRange) {
    const glm::vec3 target(0.35f, 1.6f, 0.1f); // the top-right corner of the character: a hand
    for (double yaw : {0.0, 60.0, -150.0})
        for (double pitch : {-30.0, 10.0, 70.0}) {
            Camera cam = orbit(yaw, pitch, 0.5);
            cam.target = std::array<double, 3>{target.x, target.y, target.z};
            const FrameCamera c = frameCamera(kLo, kHi, 0.02, cam, 320, 240);
            EXPECT_EQ(c.target, target);
            EXPECT_NEAR(glm::length(c.eye - target), 0.5f, 1e-5f); // orbits at `distance` about it
            auto p = projectToPixel(c, target);
            ASSERT_TRUE(p);
            EXPECT_NEAR(p->x, 160.0, 1e-3);
            EXPECT_NEAR(p->y, 120.0, 1e-3);
            // Every corner of the bounds lies in front of the far plane and beyond the near one
            // along the view direction (or behind the eye, which a near plane cannot help).
            for (int k = 0; k < 8; ++k) {
                const glm::vec3 q((k & 1) ? kHi.x : kLo.x, (k & 2) ? kHi.y : kLo.y, (k & 4) ? kHi.z : kLo.z);
                const float depth = glm::dot(q - c.eye, c.forward);
                EXPECT_LT(depth, c.zFar) << k;
            }
        }
    // Without a target: the bounds centre.
    const FrameCamera a = frameCamera(kLo, kHi, 0.02, orbit(30, 20, 3.0), 256, 256);
    EXPECT_EQ(a.target, 0.5f * (kLo + kHi));
}
