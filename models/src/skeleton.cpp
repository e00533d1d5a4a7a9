// The default character's skeleton: joint table, rest positions and frames (see skeleton.hpp).
#include "skeleton.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace dermis::chargen {
namespace {

constexpr float kPi = 3.14159265358979323846f;

glm::vec3 mirrorX(const glm::vec3& p) {
    return {-p.x, p.y, p.z};
}

struct Builder {
    Skeleton s;
    int add(const std::string& name, const std::string& parent, glm::vec3 head, glm::vec3 tail,
            glm::vec3 flex) {
        Joint j;
        j.name = name;
        j.parent = parent.empty() ? -1 : s.at(parent);
        j.head = head;
        j.tail = tail;
        j.frame = boneFrame(tail - head, flex);
        s.joints.push_back(j);
        return static_cast<int>(s.joints.size()) - 1;
    }
};

} // namespace

int Skeleton::find(const std::string& name) const {
    for (std::size_t i = 0; i < joints.size(); ++i)
        if (joints[i].name == name) return static_cast<int>(i);
    return -1;
}

int Skeleton::at(const std::string& name) const {
    const int j = find(name);
    if (j < 0) {
        std::fprintf(stderr, "dermis-charactergen: internal error: no joint '%s'\n", name.c_str());
        std::abort();
    }
    return j;
}

glm::quat Skeleton::restLocalRotation(int j) const {
    const Joint& jt = joints[static_cast<std::size_t>(j)];
    glm::mat3 local = jt.frame;
    if (jt.parent >= 0)
        local = glm::transpose(joints[static_cast<std::size_t>(jt.parent)].frame) * jt.frame;
    return glm::normalize(glm::quat_cast(local));
}

glm::vec3 Skeleton::restLocalTranslation(int j) const {
    const Joint& jt = joints[static_cast<std::size_t>(j)];
    if (jt.parent < 0) return jt.head;
    const Joint& p = joints[static_cast<std::size_t>(jt.parent)];
    return glm::transpose(p.frame) * (jt.head - p.head);
}

glm::mat3 boneFrame(const glm::vec3& along, const glm::vec3& flex) {
    const glm::vec3 y = glm::normalize(along);
    const glm::vec3 x = glm::normalize(glm::cross(y, flex));
    const glm::vec3 z = glm::cross(x, y);
    return glm::mat3(x, y, z);
}

Skeleton buildSkeleton() {
    Builder b;
    const glm::vec3 up(0, 1, 0), fwd(0, 0, 1), back(0, 0, -1);

    // Spine chain (centre line), pelvis to head.
    b.add("root", "", {0, 0, 0}, {0, 0.2f, 0}, fwd);
    const glm::vec3 pelvis(0, 0.955f, -0.005f), sp1(0, 1.03f, -0.012f), sp2(0, 1.13f, -0.02f),
        sp3(0, 1.235f, -0.025f), chest(0, 1.34f, -0.03f), neck1(0, 1.475f, -0.038f),
        neck2(0, 1.54f, -0.03f), head(0, 1.605f, -0.015f), headTop(0, 1.75f, -0.01f);
    b.add("pelvis", "root", pelvis, sp1, fwd);
    b.add("spine_01", "pelvis", sp1, sp2, fwd);
    b.add("spine_02", "spine_01", sp2, sp3, fwd);
    b.add("spine_03", "spine_02", sp3, chest, fwd);
    b.add("chest", "spine_03", chest, neck1, fwd);
    b.add("neck_01", "chest", neck1, neck2, fwd);
    b.add("neck_02", "neck_01", neck2, head, fwd);
    b.add("head", "neck_02", head, headTop, fwd);

    // Arms: A-pose, 40° below horizontal, in the frontal plane.
    const float armDown = 40.0f * kPi / 180.0f;
    const glm::vec3 d(std::cos(armDown), -std::sin(armDown), 0);     // left arm direction
    const glm::vec3 palm(-std::sin(armDown), -std::cos(armDown), 0); // left palm normal
    const glm::vec3 across(0, 0, 1); // across the knuckles, toward the thumb
    const glm::vec3 sc(0.025f, 1.445f, 0.035f), shoulder(0.175f, 1.435f, -0.03f);
    const float upperLen = 0.29f, foreLen = 0.255f;
    const glm::vec3 elbow = shoulder + d * upperLen, wrist = elbow + d * foreLen;
    // Hand: palm 0.095 long; index and the mitten (middle, ring, little) 0.085–0.09 long.
    const glm::vec3 indexBase = wrist + d * 0.095f + across * 0.027f + palm * 0.002f;
    const glm::vec3 indexDir = glm::normalize(d + across * 0.12f);
    const glm::vec3 fingBase = wrist + d * 0.092f - across * 0.012f + palm * 0.002f;
    const glm::vec3 fingDir = glm::normalize(d - across * 0.05f);
    const glm::vec3 thumbBase = wrist + d * 0.022f + across * 0.024f + palm * 0.012f;
    const glm::vec3 thumbDir = glm::normalize(d * 0.62f + across * 0.72f + palm * 0.3f);
    // Thumb flexion (opposition) turns it across the palm.
    const glm::vec3 thumbFlex = glm::normalize(palm - across * 0.4f);

    // Legs.
    const glm::vec3 hip(0.088f, 0.925f, -0.005f), knee(0.098f, 0.505f, 0.012f),
        ankle(0.106f, 0.09f, -0.028f), ball(0.112f, 0.028f, 0.118f), toeTip(0.115f, 0.022f, 0.19f);

    for (int side = 0; side < 2; ++side) {
        const std::string s = side == 0 ? ".l" : ".r";
        auto m = [&](const glm::vec3& p) { return side == 0 ? p : mirrorX(p); };
        auto mv = [&](const glm::vec3& v) { return side == 0 ? v : mirrorX(v); };
        b.add("clavicle" + s, "chest", m(sc), m(shoulder), fwd);
        b.add("upper_arm" + s, "clavicle" + s, m(shoulder), m(elbow), fwd);
        b.add("upper_arm_twist" + s, "upper_arm" + s, m(shoulder + d * (0.5f * upperLen)), m(elbow),
              fwd);
        b.add("forearm" + s, "upper_arm" + s, m(elbow), m(wrist), fwd);
        b.add("forearm_twist" + s, "forearm" + s, m(elbow + d * (0.5f * foreLen)), m(wrist), fwd);
        b.add("hand" + s, "forearm" + s, m(wrist), m(wrist + d * 0.095f), mv(palm));
        const float thumbLen[3] = {0.042f, 0.032f, 0.028f};
        glm::vec3 p = thumbBase;
        for (int k = 0; k < 3; ++k) {
            const std::string name = "thumb_0" + std::to_string(k + 1) + s;
            const std::string parent = k == 0 ? "hand" + s : "thumb_0" + std::to_string(k) + s;
            b.add(name, parent, m(p), m(p + thumbDir * thumbLen[k]), mv(thumbFlex));
            p += thumbDir * thumbLen[k];
        }
        const float fingerLen[3] = {0.042f, 0.026f, 0.022f};
        for (int f = 0; f < 2; ++f) {
            const std::string base = f == 0 ? "index_0" : "fingers_0";
            const glm::vec3 dir = f == 0 ? indexDir : fingDir;
            p = f == 0 ? indexBase : fingBase;
            for (int k = 0; k < 3; ++k) {
                const std::string name = base + std::to_string(k + 1) + s;
                const std::string parent = k == 0 ? "hand" + s : base + std::to_string(k) + s;
                const float len = fingerLen[k] * (f == 0 ? 0.95f : 1.0f);
                b.add(name, parent, m(p), m(p + dir * len), mv(palm));
                p += dir * len;
            }
        }
        b.add("thigh" + s, "pelvis", m(hip), m(knee), fwd);
        b.add("thigh_twist" + s, "thigh" + s, m(0.5f * (hip + knee)), m(knee), fwd);
        b.add("shin" + s, "thigh" + s, m(knee), m(ankle), back);
        b.add("shin_twist" + s, "shin" + s, m(0.5f * (knee + ankle)), m(ankle), back);
        b.add("foot" + s, "shin" + s, m(ankle), m(ball), up);
        b.add("toes" + s, "foot" + s, m(ball), m(toeTip), up);
    }
    return b.s;
}

} // namespace dermis::chargen
