// AnglesTest — joint angles (SPEC §2 "Joint angle") and pose rotations (§2b). Pure.
#include "core/rig.hpp"

#include <glm/gtc/quaternion.hpp>
#include <gtest/gtest.h>

using namespace dermis;

namespace {
glm::quat rot(double deg, glm::vec3 axis) {
    return glm::angleAxis(static_cast<float>(glm::radians(deg)), glm::normalize(axis));
}
const glm::vec3 X(1, 0, 0), Y(0, 1, 0), Z(0, 0, 1);
const glm::quat I(1, 0, 0, 0);
} // namespace

TEST(AnglesTest, KnownRotationsAboutEachAxis) {
    EXPECT_NEAR(jointAngle(I, rot(30, X), X), 30.0, 1e-4);
    EXPECT_NEAR(jointAngle(I, rot(30, X), Y), 0.0, 1e-4);
    EXPECT_NEAR(jointAngle(I, rot(30, X), Z), 0.0, 1e-4);
    EXPECT_NEAR(jointAngle(I, rot(-75, Y), Y), -75.0, 1e-4);
    EXPECT_NEAR(jointAngle(I, rot(120, Z), Z), 120.0, 1e-4);
    EXPECT_NEAR(jointAngle(I, I, X), 0.0, 1e-9);
}

TEST(AnglesTest, RelativeToTheRestRotation) {
    const glm::quat rest = rot(45, Z) * rot(10, X);
    EXPECT_NEAR(jointAngle(rest, rest * rot(30, X), X), 30.0, 1e-4);
    EXPECT_NEAR(jointAngle(rest, rest * rot(-50, Y), Y), -50.0, 1e-4);
    EXPECT_NEAR(jointAngle(rest, rest, Y), 0.0, 1e-4);
}

TEST(AnglesTest, ArbitraryAxisVector) {
    const glm::vec3 a = glm::normalize(glm::vec3(1, 1, 0));
    EXPECT_NEAR(jointAngle(I, rot(50, a), a), 50.0, 1e-4);
    EXPECT_NEAR(jointAngle(I, rot(50, a), -a), -50.0, 1e-4);
    // Rotation about a perpendicular axis has no twist about a.
    EXPECT_NEAR(jointAngle(I, rot(40, glm::vec3(1, -1, 0)), a), 0.0, 1e-4);
}

TEST(AnglesTest, QAndMinusQGiveTheSameAngle) {
    for (double deg : {-179.0, -90.0, -1.0, 0.5, 45.0, 135.0, 179.0}) {
        const glm::quat q = rot(deg, X);
        EXPECT_NEAR(jointAngle(I, q, X), jointAngle(I, -q, X), 1e-4) << deg;
        EXPECT_NEAR(jointAngle(-I, q, X), deg, 1e-3) << deg;
    }
}

TEST(AnglesTest, WrapsIntoMinus180To180) {
    EXPECT_NEAR(jointAngle(I, rot(190, X), X), -170.0, 1e-3);
    EXPECT_NEAR(jointAngle(I, rot(-190, X), X), 170.0, 1e-3);
    EXPECT_NEAR(jointAngle(I, rot(270, Y), Y), -90.0, 1e-3);
    EXPECT_DOUBLE_EQ(wrapDegrees(180.0), 180.0);
    EXPECT_DOUBLE_EQ(wrapDegrees(-180.0), 180.0);
    EXPECT_DOUBLE_EQ(wrapDegrees(540.0), 180.0);
    EXPECT_DOUBLE_EQ(wrapDegrees(-190.0), 170.0);
    EXPECT_DOUBLE_EQ(wrapDegrees(359.0), -1.0);
    EXPECT_DOUBLE_EQ(wrapDegrees(0.0), 0.0);
}

TEST(AnglesTest, TwistIgnoresSwing) {
    // q = swing(about y) · twist(about x): the swing–twist split recovers the twist only for the
    // twist-after-swing order; for a pure swing the twist is zero.
    const glm::quat swing = rot(35, Y);
    EXPECT_NEAR(jointAngle(I, swing, X), 0.0, 1e-4);
    // Independent drivers: rotations about x and z of one joint are read separately.
    const glm::quat q = rot(20, X);
    EXPECT_NEAR(jointAngle(I, q, X), 20.0, 1e-4);
    EXPECT_NEAR(jointAngle(I, q, Z), 0.0, 1e-4);
}

TEST(AnglesTest, AxisAnglesComposeInXYZOrderAfterRest) {
    const glm::quat rest = rot(30, Y);
    const glm::quat q = axisAnglesRotation(rest, 20, -10, 5);
    const glm::quat expected = rest * rot(20, X) * rot(-10, Y) * rot(5, Z);
    EXPECT_NEAR(glm::abs(glm::dot(q, expected)), 1.0f, 1e-6f);
    // A single axis angle is read back exactly by the joint angle about that axis.
    EXPECT_NEAR(jointAngle(rest, axisAnglesRotation(rest, 42, 0, 0), X), 42.0, 1e-4);
    EXPECT_NEAR(jointAngle(rest, axisAnglesRotation(rest, 0, 0, -64), Z), -64.0, 1e-4);
}
