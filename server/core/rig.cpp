// Pose math of rig.hpp: clip sampling (glTF 2.0 Appendix C), world matrices, CPU linear blend
// skinning. jointAngle, axisAnglesRotation and wrapDegrees live in angles.cpp.
//
// The functions are defensive about hand-built models that break Model's invariants (a channel
// whose arrays disagree, a parent index out of range, a parent cycle, a vertex without joints):
// such data is skipped or treated as identity rather than read out of bounds.
#include "rig.hpp"

#include <algorithm>
#include <cmath>

namespace dermis {
namespace {

/// Components of one key value of a channel: 4 for rotations (x y z w), the node's morph weight
/// count for weights, else 3.
std::size_t componentsOf(const Channel& channel) {
    if (channel.path == ChannelPath::Weights) return static_cast<std::size_t>(std::max(channel.morphCount, 0));
    return channel.path == ChannelPath::Rotation ? 4 : 3;
}

/// The glm quaternion of glTF's [x, y, z, w] at `v`.
glm::quat quatAt(const float* v) {
    return glm::quat(v[3], v[0], v[1], v[2]);
}

/// Spherical linear interpolation along the shorter arc (glTF 2.0 Appendix C, "Spherical Linear
/// Interpolation"): a and −a are the same rotation, so b is negated when dot(a, b) < 0. Nearly
/// parallel quaternions fall back to a normalised lerp, where slerp's sin(θ) would vanish.
glm::quat slerpShortest(const glm::quat& a, glm::quat b, float t) {
    float d = glm::dot(a, b);
    if (d < 0.0f) {
        b = -b;
        d = -d;
    }
    if (d > 0.9995f) return glm::normalize(a * (1.0f - t) + b * t);
    const float theta = std::acos(std::min(d, 1.0f));
    const float s = std::sin(theta);
    const float wa = std::sin((1.0f - t) * theta) / s, wb = std::sin(t * theta) / s;
    return glm::normalize(a * wa + b * wb);
}

/// Writes the `comps` floats of `channel` at `time` into `out` (glTF 2.0 Appendix C). Before the
/// first key and after the last one the nearest key's value holds. Returns false (and leaves
/// `out` alone) when the channel's arrays are inconsistent.
bool sampleChannel(const Channel& channel, float time, float* out) {
    const std::size_t comps = componentsOf(channel);
    const std::size_t n = channel.times.size();
    const bool cubic = channel.interpolation == Interpolation::CubicSpline;
    // Per key: the value, or (CUBICSPLINE) in-tangent a_k, value v_k, out-tangent b_k.
    const std::size_t keyStride = cubic ? 3 * comps : comps;
    const std::size_t valueOffset = cubic ? comps : 0;
    if (n == 0 || comps == 0 || channel.values.size() < n * keyStride) return false;
    const float* values = channel.values.data();
    auto value = [&](std::size_t k) { return values + k * keyStride + valueOffset; };

    if (!(time > channel.times.front()) || n == 1) { // also NaN
        std::copy_n(value(0), comps, out);
        return true;
    }
    if (time >= channel.times.back()) {
        std::copy_n(value(n - 1), comps, out);
        return true;
    }
    // Key interval k: t_k <= time < t_{k+1}.
    const auto it = std::upper_bound(channel.times.begin(), channel.times.end(), time);
    const std::size_t k = static_cast<std::size_t>(it - channel.times.begin()) - 1;
    const float td = channel.times[k + 1] - channel.times[k];
    const float u = td > 0.0f ? (time - channel.times[k]) / td : 0.0f;

    switch (channel.interpolation) {
    case Interpolation::Step:
        std::copy_n(value(k), comps, out);
        return true;
    case Interpolation::Linear:
        if (channel.path == ChannelPath::Rotation) {
            const glm::quat q = slerpShortest(quatAt(value(k)), quatAt(value(k + 1)), u);
            out[0] = q.x, out[1] = q.y, out[2] = q.z, out[3] = q.w;
        } else {
            for (std::size_t c = 0; c < comps; ++c)
                out[c] = value(k)[c] * (1.0f - u) + value(k + 1)[c] * u;
        }
        return true;
    case Interpolation::CubicSpline: {
        // Hermite spline (Appendix C, "Cubic Spline Interpolation"):
        //   p(u) = (2u³ − 3u² + 1)·v_k + td·(u³ − 2u² + u)·b_k + (−2u³ + 3u²)·v_{k+1}
        //          + td·(u³ − u²)·a_{k+1}
        const float u2 = u * u, u3 = u2 * u;
        const float h00 = 2 * u3 - 3 * u2 + 1, h10 = u3 - 2 * u2 + u;
        const float h01 = -2 * u3 + 3 * u2, h11 = u3 - u2;
        const float* v0 = value(k);
        const float* b0 = v0 + comps; // out-tangent of key k
        const float* v1 = value(k + 1);
        const float* a1 = v1 - comps; // in-tangent of key k + 1
        for (std::size_t c = 0; c < comps; ++c)
            out[c] = h00 * v0[c] + td * h10 * b0[c] + h01 * v1[c] + td * h11 * a1[c];
        return true;
    }
    }
    return false;
}

/// Local matrix T · R · S of one node.
glm::mat4 localMatrix(const glm::vec3& t, const glm::quat& r, const glm::vec3& s) {
    glm::mat4 m = glm::mat4_cast(r);
    m[0] *= s.x;
    m[1] *= s.y;
    m[2] *= s.z;
    m[3] = glm::vec4(t, 1.0f);
    return m;
}

/// Transform for normals of a linear map M: the inverse-transpose, up to a positive factor. The
/// cofactor matrix equals det(M)·inverse(M)ᵀ, so sign(det)·cofactor points the same way without
/// a division (and stays finite when M is singular).
glm::mat3 normalMatrix(const glm::mat3& m) {
    glm::mat3 c;
    c[0] = glm::cross(m[1], m[2]);
    c[1] = glm::cross(m[2], m[0]);
    c[2] = glm::cross(m[0], m[1]);
    return glm::dot(m[0], c[0]) < 0.0f ? -c : c;
}

} // namespace

LocalPose restPose(const Model& model) {
    LocalPose pose;
    const std::size_t n = model.nodes.size();
    pose.translation.resize(n);
    pose.rotation.resize(n);
    pose.scale.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        pose.translation[i] = model.nodes[i].translation;
        pose.rotation[i] = model.nodes[i].rotation;
        pose.scale[i] = model.nodes[i].scale;
    }
    pose.morphWeights.resize(model.morphWeights.size());
    for (std::size_t i = 0; i < model.morphWeights.size(); ++i)
        pose.morphWeights[i] = model.morphWeights[i].rest;
    return pose;
}

LocalPose sampleClip(const Model& model, int clip, float time) {
    LocalPose pose = restPose(model);
    if (clip < 0 || static_cast<std::size_t>(clip) >= model.clips.size()) return pose;
    const Clip& c = model.clips[static_cast<std::size_t>(clip)];
    // Clamp to [0, duration]; NaN becomes 0.
    const float t = time > 0.0f ? std::min(time, c.duration) : 0.0f;
    std::vector<float> weights;
    for (const Channel& channel : c.channels) {
        if (channel.path == ChannelPath::Weights) {
            if (channel.morphFirst < 0 || channel.morphCount <= 0 ||
                static_cast<std::size_t>(channel.morphFirst) + static_cast<std::size_t>(channel.morphCount) >
                    pose.morphWeights.size())
                continue;
            weights.resize(static_cast<std::size_t>(channel.morphCount));
            if (!sampleChannel(channel, t, weights.data())) continue;
            std::copy(weights.begin(), weights.end(),
                      pose.morphWeights.begin() + channel.morphFirst);
            continue;
        }
        if (channel.node < 0 || static_cast<std::size_t>(channel.node) >= model.nodes.size())
            continue;
        float v[4];
        if (!sampleChannel(channel, t, v)) continue;
        const auto node = static_cast<std::size_t>(channel.node);
        switch (channel.path) {
        case ChannelPath::Translation:
            pose.translation[node] = {v[0], v[1], v[2]};
            break;
        case ChannelPath::Scale:
            pose.scale[node] = {v[0], v[1], v[2]};
            break;
        case ChannelPath::Rotation:
            // LINEAR slerp stays unit; CUBICSPLINE and raw keys are renormalised (Appendix C).
            // glm::normalize maps a zero quaternion to the identity.
            pose.rotation[node] = glm::normalize(quatAt(v));
            break;
        case ChannelPath::Weights:
            break; // handled above
        }
    }
    return pose;
}

std::vector<glm::mat4> worldMatrices(const Model& model, const LocalPose& pose) {
    const std::size_t n = model.nodes.size();
    std::vector<glm::mat4> world(n, glm::mat4(1.0f));
    const bool complete =
        pose.translation.size() >= n && pose.rotation.size() >= n && pose.scale.size() >= n;
    // 0 = not computed, 1 = on the current parent chain, 2 = done.
    std::vector<unsigned char> state(n, 0);
    std::vector<std::size_t> chain;
    for (std::size_t start = 0; start < n; ++start) {
        // Walk up to a root or an already computed ancestor, then compute back down, so children
        // may precede their parents in Model::nodes. A parent cycle (invalid model) is cut where
        // it closes: that node is treated as a root.
        chain.clear();
        std::size_t i = start;
        while (state[i] == 0) {
            state[i] = 1;
            chain.push_back(i);
            const int p = model.nodes[i].parent;
            if (p < 0 || static_cast<std::size_t>(p) >= n) break;
            i = static_cast<std::size_t>(p);
        }
        for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
            const std::size_t k = *it;
            const glm::mat4 local =
                complete ? localMatrix(pose.translation[k], pose.rotation[k], pose.scale[k])
                         : glm::mat4(1.0f);
            const int p = model.nodes[k].parent;
            const bool hasParent = p >= 0 && static_cast<std::size_t>(p) < n &&
                                   state[static_cast<std::size_t>(p)] == 2;
            world[k] = hasParent ? world[static_cast<std::size_t>(p)] * local : local;
            state[k] = 2;
        }
    }
    return world;
}

float morphWeightOf(const Model& model, const MorphTarget& target, const std::vector<float>& weights) {
    if (target.weight < 0 || static_cast<std::size_t>(target.weight) >= model.morphWeights.size())
        return 0.0f;
    const auto k = static_cast<std::size_t>(target.weight);
    return weights.size() == model.morphWeights.size() ? weights[k] : model.morphWeights[k].rest;
}

MorphedPart morphPart(const Model& model, const MeshPart& part, const std::vector<float>& weights) {
    MorphedPart out;
    const std::size_t nv = part.positions.size();
    out.positions = part.positions;
    if (part.normals.size() == nv) out.normals = part.normals;
    if (part.tangents.size() == nv) out.tangents = part.tangents;
    if (part.morphs.empty()) return out;
    std::vector<glm::vec3> tangents(out.tangents.size());
    for (std::size_t v = 0; v < tangents.size(); ++v)
        tangents[v] = glm::vec3(out.tangents[v]);
    bool any = false;
    for (const MorphTarget& target : part.morphs) {
        const float w = morphWeightOf(model, target, weights);
        if (w == 0.0f) continue;
        any = true;
        auto add = [&](std::vector<glm::vec3>& dst, const std::vector<glm::vec3>& delta) {
            if (delta.size() != nv || dst.size() != nv) return;
            for (std::size_t v = 0; v < nv; ++v)
                dst[v] += w * delta[v];
        };
        add(out.positions, target.positions);
        add(out.normals, target.normals);
        add(tangents, target.tangents);
    }
    if (!any) return out;
    for (std::size_t v = 0; v < out.normals.size(); ++v) {
        const float len = glm::length(out.normals[v]);
        out.normals[v] = len > 0.0f && std::isfinite(len) ? out.normals[v] / len : part.normals[v];
    }
    for (std::size_t v = 0; v < tangents.size(); ++v) {
        const float len = glm::length(tangents[v]);
        if (len > 0.0f && std::isfinite(len))
            out.tangents[v] = glm::vec4(tangents[v] / len, part.tangents[v].w);
    }
    return out;
}

std::vector<SkinnedPart> skin(const Model& model, const std::vector<glm::mat4>& world,
                              const std::vector<float>& morphWeights) {
    std::vector<SkinnedPart> out(model.parts.size());
    std::vector<glm::mat4> jointMatrix;
    MorphedPart morphed;
    for (std::size_t pi = 0; pi < model.parts.size(); ++pi) {
        const MeshPart& part = model.parts[pi];
        SkinnedPart& sp = out[pi];
        const std::size_t nv = part.positions.size();
        // Morph targets first (bind space), then skinning, in glTF 2.0's order.
        const bool morphs = !part.morphs.empty();
        if (morphs) morphed = morphPart(model, part, morphWeights);
        const std::vector<glm::vec3>& positions = morphs ? morphed.positions : part.positions;
        const std::vector<glm::vec3>& normals = morphs ? morphed.normals : part.normals;

        // Joint matrix of each influence: world(node_k) · inverseBind_k.
        jointMatrix.assign(part.influences.size(), glm::mat4(1.0f));
        for (std::size_t k = 0; k < part.influences.size(); ++k) {
            const Influence& inf = part.influences[k];
            const bool valid = inf.node >= 0 && static_cast<std::size_t>(inf.node) < world.size();
            jointMatrix[k] = (valid ? world[static_cast<std::size_t>(inf.node)] : glm::mat4(1.0f)) *
                             inf.inverseBind;
        }

        const bool hasNormals = normals.size() == nv;
        const bool hasWeights = part.joints.size() == nv && part.weights.size() == nv;
        sp.positions.resize(nv);
        sp.normals.resize(nv);
        for (std::size_t v = 0; v < nv; ++v) {
            // Blended matrix Σ w_k · J_k. A vertex without joint data follows influence 0.
            glm::mat4 m(0.0f);
            if (hasWeights) {
                for (int c = 0; c < 4; ++c) {
                    const float w = part.weights[v][c];
                    const std::size_t j = part.joints[v][c];
                    if (w != 0.0f && j < jointMatrix.size()) m += w * jointMatrix[j];
                }
            } else {
                m = jointMatrix.empty() ? glm::mat4(1.0f) : jointMatrix[0];
            }
            sp.positions[v] = glm::vec3(m * glm::vec4(positions[v], 1.0f));
            if (hasNormals) {
                const glm::vec3 nrm = normalMatrix(glm::mat3(m)) * normals[v];
                const float len = glm::length(nrm);
                sp.normals[v] = len > 0.0f && std::isfinite(len) ? nrm / len : normals[v];
            }
        }
        // A hand-built part without normals gets the posed surface's own.
        if (!hasNormals) sp.normals = computeNormals(sp.positions, part.indices);
    }
    return out;
}

} // namespace dermis
