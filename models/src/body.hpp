// dermis-charactergen — the default character's body as a smooth implicit surface.
//
// The body is a signed distance-like field f (negative inside, positive outside, ≈ metres near
// the surface, |∇f| ≈ 1): a smooth-min union of GROUPS (torso pieces, limbs, hands, feet), each
// a smooth-min union of simple primitives (ellipsoids, round cones, rounded boxes) placed on the
// skeleton's rest pose. Each group belongs to one skinning CHAIN (a list of bones along which
// skin weights blend; see weights.hpp). Pure math; deterministic; thread-safe for const calls.
#pragma once

#include "skeleton.hpp"

#include <glm/glm.hpp>

#include <string>
#include <vector>

namespace dermis::chargen {

/// One primitive of a group.
struct Primitive {
    enum class Kind { Ellipsoid, RoundCone, RoundBox } kind = Kind::Ellipsoid;
    glm::vec3 a{0}, b{0};  ///< ellipsoid/box: centre in a; round cone: segment a → b
    glm::vec3 radii{0};    ///< ellipsoid radii / box half extents (local axes); cone: ra, rb
    glm::mat3 axes{1};     ///< ellipsoid / box orientation (columns = local axes in world)
    float rounding = 0.0f; ///< round box edge radius
    float blend = 0.0f;    ///< smooth-min radius when joining the group's previous primitives
    bool subtract = false; ///< carve this primitive out of the group so far (smooth max)
    float distance(const glm::vec3& p) const;
    glm::vec3 boundCentre() const; ///< centre of a sphere containing the primitive
    float boundRadius() const;
};

/// A skinning chain: bones in order with the half-width of the blend zone at each junction.
struct Chain {
    std::string name;
    std::vector<int> bones;        ///< joint indices, proximal first
    std::vector<glm::vec3> points; ///< bones.size() + 1 points: bone k spans points[k..k+1]
    std::vector<float> halfWidth;  ///< bones.size() − 1 blend half-widths (junction k+1)
    /// Optional normals of the junction planes (zero: bisector of the two bones' directions).
    std::vector<glm::vec3> junctionNormal;
};

struct Group {
    std::string name;
    int chain = 0;      ///< index into Body::chains
    float blend = 0.0f; ///< smooth-min radius when joining the body so far
    std::vector<Primitive> prims;
    bool clipBelowGround = false; ///< smooth-intersect with y ≥ 0 (flat soles)
    float sizing = 1.0f;          ///< target edge length factor for this group (hands < 1)
    float distance(const glm::vec3& p) const;
    glm::vec3 boundCentre{0}; ///< filled by Body::finish()
    float boundRadius = 0.0f;
};

class Body {
  public:
    /// The default character's body on `skeleton` (from buildSkeleton()).
    explicit Body(const Skeleton& skeleton);

    /// The field at p (negative inside).
    float sdf(const glm::vec3& p) const;
    /// Central-difference gradient of sdf (not normalised).
    glm::vec3 gradient(const glm::vec3& p) const;
    /// Distance of every group at p (same order as groups()).
    void groupDistances(const glm::vec3& p, std::vector<float>& out) const;
    /// Moves p onto the zero set by a few Newton steps along the gradient. Returns the result
    /// (p unchanged where the gradient vanishes).
    glm::vec3 project(glm::vec3 p, int steps = 4) const;
    /// Desired relative edge length at p (1 on the trunk, smaller on hands, feet, face).
    float sizing(const glm::vec3& p) const;

    const std::vector<Group>& groups() const { return groups_; }
    const std::vector<Chain>& chains() const { return chains_; }
    /// Axis-aligned box containing the surface.
    glm::vec3 boundsMin() const { return lo_; }
    glm::vec3 boundsMax() const { return hi_; }

  private:
    void finish();
    std::vector<Group> groups_;
    std::vector<Chain> chains_;
    glm::vec3 lo_{0}, hi_{0};
};

/// Polynomial smooth minimum with blend radius k (k ≤ 0: plain min).
float smin(float a, float b, float k);

} // namespace dermis::chargen
