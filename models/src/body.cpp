// The default character's implicit body (see body.hpp): primitive distance functions and the
// table of groups that shapes a 1.75 m adult.
#include "body.hpp"

#include <algorithm>
#include <cmath>

namespace dermis::chargen {
namespace {

constexpr float kFar = 1e9f;

float dot2(const glm::vec3& v) {
    return glm::dot(v, v);
}

/// Exact distance to a round cone (capsule with radii r1 at a and r2 at b), after Inigo Quilez.
float roundCone(const glm::vec3& p, const glm::vec3& a, const glm::vec3& b, float r1, float r2) {
    const glm::vec3 ba = b - a;
    const float l2 = glm::dot(ba, ba);
    const float rr = r1 - r2;
    const float a2 = l2 - rr * rr;
    const float il2 = 1.0f / l2;
    const glm::vec3 pa = p - a;
    const float y = glm::dot(pa, ba);
    const float z = y - l2;
    const float x2 = dot2(pa * l2 - ba * y);
    const float y2 = y * y * l2;
    const float z2 = z * z * l2;
    const float k = (rr > 0 ? 1.0f : rr < 0 ? -1.0f : 0.0f) * rr * rr * x2;
    if ((z > 0 ? 1.0f : z < 0 ? -1.0f : 0.0f) * a2 * z2 > k) return std::sqrt(x2 + z2) * il2 - r2;
    if ((y > 0 ? 1.0f : y < 0 ? -1.0f : 0.0f) * a2 * y2 < k) return std::sqrt(x2 + y2) * il2 - r1;
    return (std::sqrt(x2 * a2 * il2) + y * rr) * il2 - r1;
}

/// Approximate distance to an axis-aligned ellipsoid with radii r centred at the origin.
float ellipsoid(const glm::vec3& p, const glm::vec3& r) {
    const float k0 = glm::length(p / r);
    const float k1 = glm::length(p / (r * r));
    if (k1 < 1e-12f) return -std::min(r.x, std::min(r.y, r.z));
    return k0 * (k0 - 1.0f) / k1;
}

/// Distance to an axis-aligned box with half extents b whose edges are rounded by r.
float roundBox(const glm::vec3& p, const glm::vec3& b, float r) {
    const glm::vec3 q = glm::abs(p) - b + r;
    return glm::length(glm::max(q, glm::vec3(0))) +
           std::min(std::max(q.x, std::max(q.y, q.z)), 0.0f) - r;
}

Primitive ellipsoidPrim(glm::vec3 c, glm::vec3 r, float blend, glm::mat3 axes = glm::mat3(1)) {
    Primitive p;
    p.kind = Primitive::Kind::Ellipsoid;
    p.a = c;
    p.radii = r;
    p.axes = axes;
    p.blend = blend;
    return p;
}

Primitive cone(glm::vec3 a, glm::vec3 b, float ra, float rb, float blend) {
    Primitive p;
    p.kind = Primitive::Kind::RoundCone;
    p.a = a;
    p.b = b;
    p.radii = glm::vec3(ra, rb, 0);
    p.blend = blend;
    return p;
}

Primitive box(glm::vec3 c, glm::vec3 half, float rounding, glm::mat3 axes, float blend) {
    Primitive p;
    p.kind = Primitive::Kind::RoundBox;
    p.a = c;
    p.radii = half;
    p.rounding = rounding;
    p.axes = axes;
    p.blend = blend;
    return p;
}

glm::vec3 mirrorX(glm::vec3 p) {
    return {-p.x, p.y, p.z};
}

/// Mirrors a primitive across the plane x = 0 (axes stay a proper rotation: X and the other
/// axes are reflected, then X negated, which keeps the shape since the primitives are
/// symmetric about their local axes).
Primitive mirrored(Primitive p) {
    p.a = mirrorX(p.a);
    p.b = mirrorX(p.b);
    for (int c = 0; c < 3; ++c)
        p.axes[c] = mirrorX(p.axes[c]);
    p.axes[0] = -p.axes[0];
    return p;
}

} // namespace

float smin(float a, float b, float k) {
    if (k <= 0.0f) return std::min(a, b);
    const float h = std::max(k - std::abs(a - b), 0.0f) / k;
    return std::min(a, b) - h * h * k * 0.25f;
}

float Primitive::distance(const glm::vec3& p) const {
    switch (kind) {
    case Kind::Ellipsoid:
        return ellipsoid(glm::transpose(axes) * (p - a), radii);
    case Kind::RoundCone:
        return roundCone(p, a, b, radii.x, radii.y);
    case Kind::RoundBox:
        return roundBox(glm::transpose(axes) * (p - a), radii, rounding);
    }
    return kFar;
}

glm::vec3 Primitive::boundCentre() const {
    return kind == Kind::RoundCone ? 0.5f * (a + b) : a;
}

float Primitive::boundRadius() const {
    switch (kind) {
    case Kind::Ellipsoid:
        return std::max(radii.x, std::max(radii.y, radii.z));
    case Kind::RoundCone:
        return 0.5f * glm::length(b - a) + std::max(radii.x, radii.y);
    case Kind::RoundBox:
        return glm::length(radii);
    }
    return 0.0f;
}

float Group::distance(const glm::vec3& p) const {
    float d = kFar;
    for (const Primitive& pr : prims) {
        // Skip primitives that cannot change the smooth union (lower bound beyond d + blend).
        const float lb = glm::length(p - pr.boundCentre()) - pr.boundRadius();
        if (pr.subtract) {
            if (d + lb >= pr.blend) continue; // smooth max(d, −prim) = d there
            d = -smin(-d, pr.distance(p), pr.blend);
            continue;
        }
        if (lb > d + pr.blend) continue;
        d = smin(d, pr.distance(p), pr.blend);
    }
    if (clipBelowGround) d = -smin(-d, p.y, 0.008f);
    return d;
}

float Body::sdf(const glm::vec3& p) const {
    float d = kFar;
    for (const Group& g : groups_) {
        const float lb = glm::length(p - g.boundCentre) - g.boundRadius;
        if (lb > d + g.blend) continue;
        d = smin(d, g.distance(p), g.blend);
    }
    return d;
}

glm::vec3 Body::gradient(const glm::vec3& p) const {
    const float e = 1e-4f;
    return glm::vec3(sdf(p + glm::vec3(e, 0, 0)) - sdf(p - glm::vec3(e, 0, 0)),
                     sdf(p + glm::vec3(0, e, 0)) - sdf(p - glm::vec3(0, e, 0)),
                     sdf(p + glm::vec3(0, 0, e)) - sdf(p - glm::vec3(0, 0, e))) /
           (2.0f * e);
}

void Body::groupDistances(const glm::vec3& p, std::vector<float>& out) const {
    out.resize(groups_.size());
    for (std::size_t g = 0; g < groups_.size(); ++g)
        out[g] = groups_[g].distance(p);
}

glm::vec3 Body::project(glm::vec3 p, int steps) const {
    for (int i = 0; i < steps; ++i) {
        const float f = sdf(p);
        if (std::abs(f) < 1e-6f) break;
        const glm::vec3 g = gradient(p);
        const float g2 = glm::dot(g, g);
        if (g2 < 1e-8f) break;
        glm::vec3 step = g * (f / g2);
        // Never jump more than 1 cm in one step (keeps thin parts on their own sheet).
        const float len = glm::length(step);
        if (len > 0.01f) step *= 0.01f / len;
        p -= step;
    }
    return p;
}

float Body::sizing(const glm::vec3& p) const {
    // Soft-min over the groups' distances, weighting each group's sizing factor.
    float wsum = 0.0f, ssum = 0.0f, dmin = kFar;
    std::vector<float> d;
    groupDistances(p, d);
    for (float v : d)
        dmin = std::min(dmin, v);
    for (std::size_t g = 0; g < groups_.size(); ++g) {
        const float w = std::exp(-(d[g] - dmin) / 0.01f);
        wsum += w;
        ssum += w * groups_[g].sizing;
    }
    return ssum / wsum;
}

void Body::finish() {
    lo_ = glm::vec3(kFar);
    hi_ = glm::vec3(-kFar);
    for (Group& g : groups_) {
        glm::vec3 lo(kFar), hi(-kFar);
        for (const Primitive& p : g.prims) {
            lo = glm::min(lo, p.boundCentre() - glm::vec3(p.boundRadius()));
            hi = glm::max(hi, p.boundCentre() + glm::vec3(p.boundRadius()));
        }
        g.boundCentre = 0.5f * (lo + hi);
        g.boundRadius = 0.5f * glm::length(hi - lo);
        lo_ = glm::min(lo_, lo);
        hi_ = glm::max(hi_, hi);
    }
    lo_ -= glm::vec3(0.03f);
    hi_ += glm::vec3(0.03f);
    lo_.y = std::max(lo_.y, -0.02f);
}

Body::Body(const Skeleton& s) {
    auto J = [&](const std::string& n) { return s.joints[static_cast<std::size_t>(s.at(n))]; };
    const glm::vec3 fwd(0, 0, 1);

    // --- chains -------------------------------------------------------------------------------
    auto chain = [&](const std::string& name, std::vector<std::string> bones,
                     std::vector<float> hw) {
        Chain c;
        c.name = name;
        for (const auto& b : bones)
            c.bones.push_back(s.at(b));
        for (int b : c.bones)
            c.points.push_back(s.joints[static_cast<std::size_t>(b)].head);
        c.points.push_back(s.joints[static_cast<std::size_t>(c.bones.back())].tail);
        c.halfWidth = std::move(hw);
        c.junctionNormal.assign(c.halfWidth.size(), glm::vec3(0));
        chains_.push_back(c);
        return static_cast<int>(chains_.size()) - 1;
    };
    const int torso =
        chain("torso",
              {"pelvis", "spine_01", "spine_02", "spine_03", "chest", "neck_01", "neck_02", "head"},
              {0.045f, 0.05f, 0.05f, 0.05f, 0.04f, 0.03f, 0.03f});
    // The head's lower boundary tilts forward so that the jaw and chin follow the head.
    chains_[static_cast<std::size_t>(torso)].junctionNormal[6] =
        glm::normalize(glm::vec3(0, 1, 1.2f));
    int arm[2], leg[2], thumb[2], index[2], fingers[2];
    for (int side = 0; side < 2; ++side) {
        const std::string sfx = side == 0 ? ".l" : ".r";
        arm[side] = chain("arm" + sfx,
                          {"clavicle" + sfx, "upper_arm" + sfx, "upper_arm_twist" + sfx,
                           "forearm" + sfx, "forearm_twist" + sfx, "hand" + sfx},
                          {0.065f, 0.07f, 0.045f, 0.06f, 0.025f});
        leg[side] = chain("leg" + sfx,
                          {"thigh" + sfx, "thigh_twist" + sfx, "shin" + sfx, "shin_twist" + sfx,
                           "foot" + sfx, "toes" + sfx},
                          {0.1f, 0.05f, 0.08f, 0.035f, 0.02f});
        thumb[side] = chain("thumb" + sfx,
                            {"hand" + sfx, "thumb_01" + sfx, "thumb_02" + sfx, "thumb_03" + sfx},
                            {0.015f, 0.01f, 0.008f});
        index[side] = chain("index" + sfx,
                            {"hand" + sfx, "index_01" + sfx, "index_02" + sfx, "index_03" + sfx},
                            {0.012f, 0.008f, 0.007f});
        fingers[side] =
            chain("fingers" + sfx,
                  {"hand" + sfx, "fingers_01" + sfx, "fingers_02" + sfx, "fingers_03" + sfx},
                  {0.012f, 0.008f, 0.007f});
    }

    // --- trunk ----------------------------------------------------------------------------------
    {
        Group g;
        g.name = "torso";
        g.chain = torso;
        g.blend = 0.0f;
        g.sizing = 1.0f;
        g.prims.push_back(ellipsoidPrim({0, 0.94f, -0.008f}, {0.138f, 0.1f, 0.1f}, 0));
        g.prims.push_back(ellipsoidPrim({0, 1.0f, 0.022f}, {0.13f, 0.09f, 0.088f}, 0.04f));
        g.prims.push_back(ellipsoidPrim({0, 1.09f, -0.002f}, {0.143f, 0.12f, 0.097f}, 0.05f));
        g.prims.push_back(ellipsoidPrim({0, 1.26f, -0.012f}, {0.155f, 0.17f, 0.11f}, 0.06f));
        g.prims.push_back(ellipsoidPrim({0, 1.37f, -0.028f}, {0.178f, 0.085f, 0.09f}, 0.05f));
        // A broad chest plate (pectorals) across both sides.
        g.prims.push_back(ellipsoidPrim({0, 1.325f, 0.03f}, {0.15f, 0.065f, 0.08f}, 0.06f));
        for (int side = 0; side < 2; ++side) {
            Primitive glute =
                ellipsoidPrim({0.066f, 0.9f, -0.05f}, {0.074f, 0.088f, 0.064f}, 0.035f);
            g.prims.push_back(side == 0 ? glute : mirrored(glute));
        }
        groups_.push_back(g);
    }
    {
        Group g;
        g.name = "neck";
        g.chain = torso;
        g.blend = 0.04f;
        g.sizing = 0.85f;
        g.prims.push_back(cone({0, 1.43f, -0.035f}, {0, 1.60f, -0.015f}, 0.06f, 0.052f, 0));
        groups_.push_back(g);
    }
    {
        Group g;
        g.name = "head";
        g.chain = torso;
        g.blend = 0.035f;
        g.sizing = 0.6f;
        g.prims.push_back(ellipsoidPrim({0, 1.672f, -0.016f}, {0.077f, 0.09f, 0.097f}, 0));
        g.prims.push_back(ellipsoidPrim({0, 1.62f, 0.026f}, {0.063f, 0.08f, 0.068f}, 0.03f));
        g.prims.push_back(ellipsoidPrim({0, 1.567f, 0.038f}, {0.05f, 0.03f, 0.048f}, 0.03f));
        g.prims.push_back(ellipsoidPrim({0, 1.548f, 0.072f}, {0.022f, 0.017f, 0.017f}, 0.02f));
        g.prims.push_back(ellipsoidPrim({0, 1.667f, 0.072f}, {0.056f, 0.016f, 0.022f}, 0.02f));
        {
            const float tilt = 0.35f;
            const glm::mat3 noseAxes(glm::vec3(1, 0, 0),
                                     glm::vec3(0, std::cos(tilt), std::sin(tilt)),
                                     glm::vec3(0, -std::sin(tilt), std::cos(tilt)));
            g.prims.push_back(
                ellipsoidPrim({0, 1.622f, 0.09f}, {0.012f, 0.026f, 0.014f}, 0.014f, noseAxes));
        }
        for (int side = 0; side < 2; ++side) {
            Primitive ear =
                ellipsoidPrim({0.074f, 1.638f, -0.012f}, {0.014f, 0.031f, 0.02f}, 0.02f);
            Primitive cheek = ellipsoidPrim({0.04f, 1.615f, 0.06f}, {0.025f, 0.022f, 0.02f}, 0.02f);
            Primitive eye =
                ellipsoidPrim({0.031f, 1.652f, 0.096f}, {0.018f, 0.011f, 0.014f}, 0.012f);
            eye.subtract = true;
            g.prims.push_back(side == 0 ? ear : mirrored(ear));
            g.prims.push_back(side == 0 ? cheek : mirrored(cheek));
            g.prims.push_back(side == 0 ? eye : mirrored(eye));
        }
        groups_.push_back(g);
    }

    // --- limbs ----------------------------------------------------------------------------------
    for (int side = 0; side < 2; ++side) {
        const std::string sfx = side == 0 ? ".l" : ".r";
        auto M = [&](Primitive p) { return side == 0 ? p : mirrored(p); };
        // Left-side geometry, mirrored for the right side.
        const Joint ua = J("upper_arm.l"), fa = J("forearm.l"), hand = J("hand.l");
        const glm::vec3 d = ua.frame[1];     // along the arm
        const glm::vec3 palmN = ua.frame[0]; // left: palm normal (toward the body, down)
        const glm::mat3 armAxes(palmN, d, glm::cross(palmN, d));
        {
            Group g;
            g.name = "shoulder" + sfx;
            g.chain = arm[side];
            g.blend = 0.05f;
            g.sizing = 1.0f;
            g.prims.push_back(
                M(cone({0.045f, 1.49f, -0.045f}, {0.16f, 1.445f, -0.03f}, 0.04f, 0.038f, 0)));
            groups_.push_back(g);
        }
        {
            Group g;
            g.name = "arm" + sfx;
            g.chain = arm[side];
            g.blend = 0.045f;
            g.sizing = 0.85f;
            const glm::vec3 sh = ua.head, el = fa.head, wr = hand.head;
            g.prims.push_back(M(ellipsoidPrim(sh + d * 0.03f + glm::vec3(0, 0.008f, 0),
                                              {0.05f, 0.075f, 0.052f}, 0, armAxes)));
            g.prims.push_back(M(cone(sh, el, 0.05f, 0.039f, 0.03f)));
            g.prims.push_back(M(ellipsoidPrim(sh + d * 0.15f + fwd * 0.014f, {0.04f, 0.09f, 0.04f},
                                              0.02f, armAxes)));
            g.prims.push_back(M(ellipsoidPrim(sh + d * 0.12f - fwd * 0.014f, {0.041f, 0.1f, 0.04f},
                                              0.02f, armAxes)));
            g.prims.push_back(M(cone(el, wr, 0.04f, 0.027f, 0.03f)));
            g.prims.push_back(
                M(ellipsoidPrim(el + d * 0.07f, {0.039f, 0.085f, 0.046f}, 0.03f, armAxes)));
            g.prims.push_back(
                M(ellipsoidPrim(wr - d * 0.03f, {0.021f, 0.05f, 0.031f}, 0.02f, armAxes)));
            groups_.push_back(g);
        }
        {
            Group g;
            g.name = "hand" + sfx;
            g.chain = arm[side];
            g.blend = 0.02f;
            g.sizing = 0.42f;
            const glm::vec3 wr = hand.head;
            g.prims.push_back(
                M(box(wr + d * 0.052f, {0.0145f, 0.048f, 0.041f}, 0.012f, armAxes, 0)));
            g.prims.push_back(M(ellipsoidPrim(wr + d * 0.035f + fwd * 0.022f + palmN * 0.01f,
                                              {0.017f, 0.03f, 0.02f}, 0.015f, armAxes)));
            groups_.push_back(g);
        }
        {
            Group g;
            g.name = "thumb" + sfx;
            g.chain = thumb[side];
            g.blend = 0.012f;
            g.sizing = 0.42f;
            const Joint t1 = J("thumb_01.l"), t2 = J("thumb_02.l"), t3 = J("thumb_03.l");
            g.prims.push_back(M(cone(t1.head, t2.head, 0.0135f, 0.0115f, 0)));
            g.prims.push_back(
                M(cone(t2.head, t3.tail - t3.frame[1] * 0.008f, 0.0115f, 0.0088f, 0.006f)));
            groups_.push_back(g);
        }
        {
            Group g;
            g.name = "index" + sfx;
            g.chain = index[side];
            g.blend = 0.006f;
            g.sizing = 0.42f;
            const Joint i1 = J("index_01.l"), i3 = J("index_03.l");
            g.prims.push_back(M(cone(i1.head - i1.frame[1] * 0.012f, i3.tail - i3.frame[1] * 0.008f,
                                     0.0098f, 0.0082f, 0)));
            groups_.push_back(g);
        }
        {
            Group g;
            g.name = "fingers" + sfx;
            g.chain = fingers[side];
            g.blend = 0.008f;
            g.sizing = 0.42f;
            const Joint f1 = J("fingers_01.l"), f3 = J("fingers_03.l");
            const glm::vec3 a = f1.head - f1.frame[1] * 0.012f, b = f3.tail;
            const glm::vec3 dir = glm::normalize(b - a);
            const glm::mat3 ax(palmN, dir, glm::normalize(glm::cross(palmN, dir)));
            g.prims.push_back(M(
                box(0.5f * (a + b), {0.0105f, 0.5f * glm::length(b - a), 0.027f}, 0.0098f, ax, 0)));
            groups_.push_back(g);
        }
        // Legs.
        const Joint th = J("thigh.l"), sh = J("shin.l"), ft = J("foot.l");
        const glm::vec3 hip = th.head, knee = sh.head, ankle = ft.head;
        const glm::vec3 ld = glm::normalize(knee - hip);
        const glm::mat3 legAxes(glm::vec3(1, 0, 0), ld,
                                glm::normalize(glm::cross(glm::vec3(1, 0, 0), ld)));
        {
            Group g;
            g.name = "leg" + sfx;
            g.chain = leg[side];
            g.blend = 0.04f;
            g.sizing = 1.0f;
            g.prims.push_back(M(cone(hip + glm::vec3(0.005f, 0.02f, 0), knee, 0.088f, 0.056f, 0)));
            g.prims.push_back(
                M(ellipsoidPrim(glm::mix(hip, knee, 0.42f) + glm::vec3(0.004f, 0, 0.022f),
                                {0.06f, 0.17f, 0.05f}, 0.03f, legAxes)));
            g.prims.push_back(M(
                ellipsoidPrim(knee + glm::vec3(0, 0.005f, 0.005f), {0.05f, 0.056f, 0.05f}, 0.02f)));
            g.prims.push_back(M(cone(knee, ankle, 0.05f, 0.033f, 0.02f)));
            g.prims.push_back(M(ellipsoidPrim(knee + glm::vec3(0.002f, -0.13f, -0.03f),
                                              {0.05f, 0.11f, 0.048f}, 0.03f)));
            groups_.push_back(g);
        }
        {
            Group g;
            g.name = "foot" + sfx;
            g.chain = leg[side];
            g.blend = 0.03f;
            g.sizing = 0.7f;
            g.clipBelowGround = true;
            g.prims.push_back(
                M(ellipsoidPrim({0.105f, 0.045f, -0.045f}, {0.034f, 0.045f, 0.04f}, 0)));
            g.prims.push_back(
                M(ellipsoidPrim({0.11f, 0.045f, 0.055f}, {0.042f, 0.04f, 0.1f}, 0.03f)));
            g.prims.push_back(
                M(ellipsoidPrim({0.116f, 0.028f, 0.15f}, {0.045f, 0.024f, 0.055f}, 0.02f)));
            groups_.push_back(g);
        }
    }
    finish();
}

} // namespace dermis::chargen
