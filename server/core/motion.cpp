// Range-of-motion analysis. See motion.hpp.
#include "motion.hpp"

#include <glm/gtc/quaternion.hpp>

#include <algorithm>
#include <cmath>

namespace dermis {

glm::dvec3 restJointPosition(const RestSkin& rest, int n) {
    return n >= 0 && static_cast<std::size_t>(n) < rest.world.size() ? glm::dvec3(rest.world[static_cast<std::size_t>(n)][3])
                                                                      : glm::dvec3(0.0);
}

LocalPose samplePose(const Model& model, const MotionSample& s) {
    if (s.clip < 0 || static_cast<std::size_t>(s.clip) >= model.clips.size()) return restPose(model);
    return sampleClip(model, s.clip, s.time);
}

LocalPose bendPose(const Model& model, int node, glm::dvec3 axis, double degrees) {
    LocalPose pose = restPose(model);
    if (node >= 0 && static_cast<std::size_t>(node) < pose.rotation.size())
        pose.rotation[static_cast<std::size_t>(node)] =
            model.nodes[static_cast<std::size_t>(node)].rotation *
            glm::quat(glm::angleAxis(glm::radians(static_cast<float>(degrees)), glm::vec3(glm::normalize(axis))));
    return pose;
}

namespace {

/// log of a unit quaternion as a rotation vector in degrees (the short way round).
glm::dvec3 rotationVector(glm::dquat q) {
    if (q.w < 0.0) q = -q;
    const glm::dvec3 v(q.x, q.y, q.z);
    const double s = glm::length(v);
    if (s < 1e-12) return glm::dvec3(0.0);
    return v / s * glm::degrees(2.0 * std::atan2(s, q.w));
}

/// Top eigenvector and eigenvalue of a symmetric 3×3 matrix (power iteration from the largest
/// column).
std::pair<glm::dvec3, double> topEigen(const glm::dmat3& m) {
    glm::dvec3 v = m[0];
    for (int k = 1; k < 3; ++k)
        if (glm::length(m[k]) > glm::length(v)) v = m[k];
    if (!(glm::length(v) > 0.0)) return {{1, 0, 0}, 0.0};
    v = glm::normalize(v);
    for (int it = 0; it < 100; ++it) {
        const glm::dvec3 w = m * v;
        const double l = glm::length(w);
        if (!(l > 0.0)) break;
        v = w / l;
    }
    return {v, glm::dot(v, m * v)};
}

void fillRange(const Model& model, const MotionAnalysis& a, JointMotion& jm) {
    const glm::quat rest = model.nodes[static_cast<std::size_t>(jm.node)].rotation;
    const glm::vec3 axis(jm.axis);
    jm.lo = 1e9;
    jm.hi = -1e9;
    int loAt = 0, hiAt = 0;
    for (std::size_t s = 0; s < a.samples.size(); ++s) {
        const double th = jointAngle(rest, a.rotations[s][static_cast<std::size_t>(jm.node)], axis);
        if (th < jm.lo) {
            jm.lo = th;
            loAt = static_cast<int>(s);
        }
        if (th > jm.hi) {
            jm.hi = th;
            hiAt = static_cast<int>(s);
        }
    }
    if (a.samples.empty()) jm.lo = jm.hi = 0.0;
    jm.clipLo = jm.lo;
    jm.clipHi = jm.hi;
    jm.peak = jm.hi;
    jm.peakSample = hiAt;
    if (jm.lo <= 0.0 && jm.hi >= 0.0) {
        jm.neutral = 0.0;
        jm.neutralSample = 0; // the rest pose
    } else {
        jm.neutral = jm.lo;
        jm.neutralSample = loAt;
    }
}

} // namespace

JointMotion motionAbout(const Model& model, const MotionAnalysis& a, int node, glm::dvec3 axis) {
    JointMotion jm;
    jm.node = node;
    jm.axis = glm::normalize(axis);
    if (node < 0 || static_cast<std::size_t>(node) >= model.nodes.size()) return jm;
    if (const JointMotion* own = a.motion(node); own && own->synthetic) {
        jm = *own;
        jm.axis = glm::normalize(axis);
        JointMotion clips = jm;
        fillRange(model, a, clips);
        jm.clipLo = clips.clipLo;
        jm.clipHi = clips.clipHi;
        return jm;
    }
    fillRange(model, a, jm);
    if (jm.hi <= 0.0) { // never turns the positive way: the far negative end is the peak
        jm.peak = jm.lo;
        jm.peakSample = 0;
        double best = 1e9;
        const glm::quat rest = model.nodes[static_cast<std::size_t>(node)].rotation;
        for (std::size_t s = 0; s < a.samples.size(); ++s) {
            const double th = jointAngle(rest, a.rotations[s][static_cast<std::size_t>(node)], glm::vec3(jm.axis));
            if (th < best) {
                best = th;
                jm.peakSample = static_cast<int>(s);
            }
        }
        jm.neutral = jm.hi;
    }
    return jm;
}

MotionAnalysis analyzeMotion(const Model& model, const RestSkin& rest, const BodyMap& body) {
    MotionAnalysis a;
    a.samples.push_back({-1, 0.0f});
    const int clips = static_cast<int>(model.clips.size());
    const int perClip = clips > 0 ? std::clamp(kSampleBudget / clips, 4, kMaxSamplesPerClip) : 0;
    for (int c = 0; c < clips; ++c) {
        const float d = model.clips[static_cast<std::size_t>(c)].duration;
        const int n = std::clamp(static_cast<int>(std::floor(d * 15.0f)) + 1, 2, perClip);
        for (int k = 0; k < n; ++k) a.samples.push_back({c, d * static_cast<float>(k) / static_cast<float>(n - 1)});
    }
    a.rotations.resize(a.samples.size());
    for (std::size_t s = 0; s < a.samples.size(); ++s) a.rotations[s] = samplePose(model, a.samples[s]).rotation;
    a.joints.resize(model.nodes.size());
    for (int j : model.joints) {
        if (j < 0 || static_cast<std::size_t>(j) >= model.nodes.size()) continue;
        JointMotion& jm = a.joints[static_cast<std::size_t>(j)];
        jm.node = j;
        const glm::dquat restQ(model.nodes[static_cast<std::size_t>(j)].rotation);
        glm::dmat3 m(0.0);
        for (std::size_t s = 0; s < a.samples.size(); ++s) {
            const glm::dvec3 r = rotationVector(glm::inverse(restQ) * glm::dquat(a.rotations[s][static_cast<std::size_t>(j)]));
            m += glm::outerProduct(r, r);
        }
        const auto [axis, value] = topEigen(m);
        const double trace = m[0][0] + m[1][1] + m[2][2];
        jm.axis = axis;
        jm.planarity = trace > 0.0 ? value / trace : 0.0;
        fillRange(model, a, jm);
        if (-jm.lo > jm.hi) { // the larger excursion positive
            jm.axis = -jm.axis;
            fillRange(model, a, jm);
        }
        if (jm.hi - jm.lo >= kMinMotionDegrees && jm.peak > 0.0) continue;
        // Synthetic: ⟂ the bone and the forward direction, bending to the front (knees back).
        jm.synthetic = true;
        jm.planarity = 1.0;
        const int child = mainChild(model, body, j);
        const int parent = model.parentJoint(j);
        glm::dvec3 bone = child >= 0 ? restJointPosition(rest, child) - restJointPosition(rest, j)
                          : parent >= 0 ? restJointPosition(rest, j) - restJointPosition(rest, parent)
                                        : glm::dvec3(0, 1, 0);
        if (!(glm::length(bone) > 0.0)) bone = {0, 1, 0};
        const glm::dvec3 forward(0, 0, 1);
        glm::dvec3 hinge = glm::cross(bone, forward);
        if (!(glm::length(hinge) > 1e-9 * glm::length(bone))) hinge = glm::cross(bone, glm::dvec3(1, 0, 0));
        hinge = glm::normalize(hinge);
        const JointInfo* info = body.info(j);
        if (info && info->role == JointRole::Knee) hinge = -hinge;
        jm.axis = glm::normalize(glm::inverse(glm::dquat(restWorldRotation(model, j))) * hinge);
        fillRange(model, a, jm); // the clips' range about the synthetic axis
        jm.lo = jm.neutral = 0.0;
        jm.hi = jm.peak = kSyntheticDegrees;
        jm.neutralSample = 0;
        jm.peakSample = -1;
    }
    return a;
}

TriangleStrain triangleStrain(glm::dvec3 a, glm::dvec3 b, glm::dvec3 c, glm::dvec3 a2, glm::dvec3 b2,
                              glm::dvec3 c2) {
    TriangleStrain out;
    const glm::dvec3 e1 = b - a, e2 = c - a;
    const double l1 = glm::length(e1);
    const glm::dvec3 n = glm::cross(e1, e2);
    if (!(l1 > 0.0) || !(glm::length(n) > 1e-30)) return out;
    const glm::dvec3 x = e1 / l1, y = glm::normalize(glm::cross(glm::normalize(n), x));
    // Rest edges in the plane's 2D frame: columns (l1, 0) and (e2·x, e2·y).
    const double px = glm::dot(e2, x), py = glm::dot(e2, y);
    if (!(std::abs(py) > 0.0)) return out;
    // F = [e1' e2'] · inverse([[l1, px], [0, py]]).
    const glm::dvec3 f1 = (b2 - a2) / l1;
    const glm::dvec3 f2 = ((c2 - a2) - px * f1) / py;
    const double c11 = glm::dot(f1, f1), c12 = glm::dot(f1, f2), c22 = glm::dot(f2, f2);
    const double mean = 0.5 * (c11 + c22), diff = 0.5 * (c11 - c22);
    const double r = std::sqrt(diff * diff + c12 * c12);
    const double lmin = std::max(0.0, mean - r), lmax = mean + r;
    out.minStretch = std::sqrt(lmin);
    out.maxStretch = std::sqrt(lmax);
    // Eigenvector of the smaller eigenvalue of [[c11, c12], [c12, c22]].
    glm::dvec2 v = std::abs(c12) > 1e-15 ? glm::dvec2(c12, lmin - c11) : (c11 <= c22 ? glm::dvec2(1, 0) : glm::dvec2(0, 1));
    if (glm::length(v) > 0.0) v = glm::normalize(v);
    out.minDirection = glm::normalize(v.x * x + v.y * y);
    return out;
}

} // namespace dermis
