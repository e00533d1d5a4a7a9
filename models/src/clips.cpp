// The default character's animation clips (see clips.hpp).
#include "clips.hpp"

#include <glm/gtc/quaternion.hpp>

#include <cmath>
#include <functional>
#include <map>
#include <string>

namespace dermis::chargen {
namespace {

constexpr float kPi = 3.14159265358979323846f;
constexpr int kKeysPerSecond = 15;

float rad(float deg) {
    return deg * kPi / 180.0f;
}
float sin2(float x) {
    return std::sin(x) * std::sin(x);
}

/// Periodic Gaussian bump on the unit circle of phases (width in phase units).
float bump(float phase, float centre, float width) {
    float d = std::fmod(phase - centre + 10.5f, 1.0f) - 0.5f;
    return std::exp(-0.5f * d * d / (width * width));
}

/// Joint angles (degrees, about the rest frame's x, y, z) and pelvis offset at one instant.
struct PoseSample {
    std::map<std::string, glm::vec3> angles;
    glm::vec3 pelvisOffset{0};
    bool movesPelvis = false;
};

using PoseFn = std::function<PoseSample(float t)>;

/// R_x(a.x) · R_y(a.y) · R_z(a.z), degrees.
glm::quat delta(const glm::vec3& a) {
    return glm::angleAxis(rad(a.x), glm::vec3(1, 0, 0)) *
           glm::angleAxis(rad(a.y), glm::vec3(0, 1, 0)) *
           glm::angleAxis(rad(a.z), glm::vec3(0, 0, 1));
}

/// World matrices of every joint for a pose sample (forward kinematics on the rest frames).
std::vector<glm::mat4> forwardKinematics(const Skeleton& sk, const PoseSample& s) {
    std::vector<glm::mat4> w(sk.joints.size());
    for (std::size_t j = 0; j < sk.joints.size(); ++j) {
        const std::string& n = sk.joints[j].name;
        glm::quat q = sk.restLocalRotation(static_cast<int>(j));
        if (auto it = s.angles.find(n); it != s.angles.end()) q = q * delta(it->second);
        glm::vec3 t = sk.restLocalTranslation(static_cast<int>(j));
        if (n == "pelvis") t += s.pelvisOffset;
        glm::mat4 local = glm::mat4_cast(q);
        local[3] = glm::vec4(t, 1.0f);
        const int p = sk.joints[j].parent;
        w[j] = p < 0 ? local : w[static_cast<std::size_t>(p)] * local;
    }
    return w;
}

/// Height of the lowest sole point (heel, ball, toe tip of both feet) in a pose sample.
float lowestSole(const Skeleton& sk, const PoseSample& s) {
    static const PoseSample restSample;
    const auto rest = forwardKinematics(sk, restSample);
    const auto w = forwardKinematics(sk, s);
    float lowest = 1e9f;
    for (int side = 0; side < 2; ++side) {
        const float m = side == 0 ? 1.0f : -1.0f;
        const std::string sfx = side == 0 ? ".l" : ".r";
        const struct {
            const char* bone;
            glm::vec3 p;
        } pts[] = {{"foot", {0.105f * m, 0.0f, -0.065f}},
                   {"foot", {0.112f * m, 0.0f, 0.11f}},
                   {"toes", {0.115f * m, 0.0f, 0.2f}}};
        for (const auto& pt : pts) {
            const auto j = static_cast<std::size_t>(sk.at(pt.bone + sfx));
            const glm::vec4 posed = w[j] * glm::inverse(rest[j]) * glm::vec4(pt.p, 1.0f);
            lowest = std::min(lowest, posed.y);
        }
    }
    return lowest;
}

dermis::Clip sampleClip(const Skeleton& sk, const std::string& name, float duration,
                        const PoseFn& fn) {
    dermis::Clip clip;
    clip.name = name;
    clip.duration = duration;
    const int keys = static_cast<int>(std::lround(duration * kKeysPerSecond)) + 1;
    std::vector<PoseSample> samples;
    std::vector<float> times;
    for (int k = 0; k < keys; ++k) {
        const float t = duration * static_cast<float>(k) / static_cast<float>(keys - 1);
        times.push_back(t);
        samples.push_back(fn(t));
    }
    // One rotation channel per joint that any sample moves, in skeleton order.
    for (std::size_t j = 0; j < sk.joints.size(); ++j) {
        const std::string& jn = sk.joints[j].name;
        if (!samples.front().angles.count(jn)) continue;
        dermis::Channel ch;
        ch.node = static_cast<int>(j);
        ch.path = dermis::ChannelPath::Rotation;
        ch.interpolation = dermis::Interpolation::Linear;
        ch.times = times;
        const glm::quat rest = sk.restLocalRotation(static_cast<int>(j));
        glm::quat prev = rest;
        for (const PoseSample& s : samples) {
            const glm::vec3 a = s.angles.at(jn);
            glm::quat q = glm::normalize(rest * delta(a));
            if (glm::dot(q, prev) < 0) q = -q; // keep neighbouring keys on one hemisphere
            prev = q;
            ch.values.insert(ch.values.end(), {q.x, q.y, q.z, q.w});
        }
        clip.channels.push_back(std::move(ch));
    }
    if (samples.front().movesPelvis) {
        const int pelvis = sk.at("pelvis");
        dermis::Channel ch;
        ch.node = pelvis;
        ch.path = dermis::ChannelPath::Translation;
        ch.interpolation = dermis::Interpolation::Linear;
        ch.times = times;
        const glm::vec3 rest = sk.restLocalTranslation(pelvis);
        for (const PoseSample& s : samples) {
            const glm::vec3 p = rest + s.pelvisOffset; // the pelvis's parent (root) is unrotated
            ch.values.insert(ch.values.end(), {p.x, p.y, p.z});
        }
        clip.channels.push_back(std::move(ch));
    }
    return clip;
}

/// Sets a joint's angles on both sides: the same x (flexion) and mirrored y, z.
void both(PoseSample& s, const std::string& base, glm::vec3 left) {
    s.angles[base + ".l"] = left;
    s.angles[base + ".r"] = glm::vec3(left.x, -left.y, -left.z);
}

/// Hip height above the ankle of a planar two-link leg with hip flexion h and knee flexion k.
struct LegGeometry {
    float thigh, shin;
    float height(float h, float k) const {
        return thigh * std::cos(rad(h)) + shin * std::cos(rad(k - h));
    }
    float forward(float h, float k) const {
        return thigh * std::sin(rad(h)) - shin * std::sin(rad(k - h));
    }
};

} // namespace

std::vector<dermis::Clip> buildClips(const Skeleton& sk) {
    const auto J = [&](const std::string& n) {
        return sk.joints[static_cast<std::size_t>(sk.at(n))];
    };
    const LegGeometry leg{glm::length(J("shin.l").head - J("thigh.l").head),
                          glm::length(J("foot.l").head - J("shin.l").head)};
    const std::vector<std::string> spine{"spine_01", "spine_02", "spine_03", "chest"};
    const float spineShare[4] = {0.3f, 0.3f, 0.25f, 0.15f};
    const std::vector<std::string> neck{"neck_01", "neck_02", "head"};
    const float neckShare[3] = {0.35f, 0.35f, 0.3f};

    std::vector<dermis::Clip> clips;
    clips.push_back(sampleClip(sk, "elbow_curl", 2.0f, [&](float t) {
        PoseSample s;
        const float w = sin2(kPi * t / 2.0f);
        both(s, "forearm", {130.0f * w, 0, 0});
        both(s, "upper_arm", {10.0f * w, 0, 0});
        both(s, "hand", {15.0f * w, 0, 0});
        return s;
    }));
    clips.push_back(sampleClip(sk, "squat", 2.5f, [&](float t) {
        PoseSample s;
        const float w = sin2(kPi * t / 2.5f);
        const float h = 95.0f * w, k = 120.0f * w;
        both(s, "thigh", {h, 0, 0});
        both(s, "shin", {k, 0, 0});
        both(s, "foot", {k - h, 0, 0}); // keeps the soles level
        for (std::size_t i = 0; i < 3; ++i)
            s.angles[spine[i]] = {15.0f * w, 0, 0};
        s.angles["chest"] = {0, 0, 0};
        both(s, "upper_arm", {70.0f * w, 0, 0});
        both(s, "forearm", {10.0f * w, 0, 0});
        s.movesPelvis = true;
        s.pelvisOffset = {0, leg.height(h, k) - leg.height(0, 0), -leg.forward(h, k)};
        return s;
    }));
    clips.push_back(sampleClip(sk, "torso_bend", 3.0f, [&](float t) {
        PoseSample s;
        const float total =
            t < 1.5f ? 75.0f * sin2(kPi * t / 1.5f) : -30.0f * sin2(kPi * (t - 1.5f) / 1.5f);
        for (std::size_t i = 0; i < 4; ++i)
            s.angles[spine[i]] = {total * spineShare[i], 0, 0};
        return s;
    }));
    clips.push_back(sampleClip(sk, "torso_twist", 2.0f, [&](float t) {
        PoseSample s;
        const float total = 45.0f * std::sin(2.0f * kPi * t / 2.0f);
        for (std::size_t i = 0; i < 4; ++i)
            s.angles[spine[i]] = {0, total * spineShare[i], 0};
        return s;
    }));
    clips.push_back(sampleClip(sk, "neck_turn", 3.0f, [&](float t) {
        PoseSample s;
        const float yaw = t < 1.5f ? 60.0f * std::sin(2.0f * kPi * t / 1.5f) : 0.0f;
        const float pitch = t < 1.5f ? 0.0f : 35.0f * std::sin(2.0f * kPi * (t - 1.5f) / 1.5f);
        for (std::size_t i = 0; i < 3; ++i)
            s.angles[neck[i]] = {pitch * neckShare[i], yaw * neckShare[i], 0};
        return s;
    }));
    clips.push_back(sampleClip(sk, "arm_raise", 2.5f, [&](float t) {
        PoseSample s;
        const float up = t < 1.5f ? sin2(kPi * t / 1.5f) : 0.0f;
        const float back = t < 1.5f ? 0.0f : sin2(kPi * (t - 1.5f) / 1.0f);
        both(s, "clavicle", {0, 0, 25.0f * up});
        both(s, "upper_arm", {-40.0f * back, 0, 90.0f * up});
        both(s, "forearm", {10.0f * up, 0, 0});
        return s;
    }));
    clips.push_back(sampleClip(sk, "walk", 1.1f, [&](float t) {
        PoseSample s;
        const float phase = t / 1.1f;
        for (int side = 0; side < 2; ++side) {
            const float p = phase + 0.5f * static_cast<float>(side);
            const float hip = 5.0f + 20.0f * std::cos(2.0f * kPi * p);
            const float knee = 5.0f + 12.0f * bump(p, 0.15f, 0.07f) + 55.0f * bump(p, 0.73f, 0.09f);
            const float ankle = 10.0f * bump(p, 0.42f, 0.1f) - 18.0f * bump(p, 0.62f, 0.06f) -
                                5.0f * bump(p, 0.05f, 0.04f);
            const std::string sfx = side == 0 ? ".l" : ".r";
            const float m = side == 0 ? 1.0f : -1.0f;
            s.angles["thigh" + sfx] = {hip, 0, 0};
            s.angles["shin" + sfx] = {knee, 0, 0};
            s.angles["foot" + sfx] = {ankle, 0, 0};
            // Arms hang and swing against the leg of their side.
            const float swing = -16.0f * std::cos(2.0f * kPi * p);
            s.angles["upper_arm" + sfx] = {swing, 0, -38.0f * m};
            s.angles["forearm" + sfx] = {20.0f + 0.6f * std::max(swing, 0.0f), 0, 0};
        }
        const float c = std::cos(2.0f * kPi * phase);
        s.angles["spine_01"] = {3.0f, 4.0f * c, 0};
        s.angles["spine_03"] = {0, -3.0f * c, 0};
        s.angles["chest"] = {0, -5.0f * c, 0};
        s.angles["neck_01"] = {0, 3.0f * c, 0};
        s.movesPelvis = true;
        s.pelvisOffset = {0, -lowestSole(sk, s), 0}; // the lowest sole point touches the floor
        return s;
    }));
    return clips;
}

} // namespace dermis::chargen
