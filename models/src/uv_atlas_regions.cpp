// The default character's UV atlas (see uv_atlas.hpp), step 1 and the mesh topology of steps
// 2–3: the body regions (Rules: which region a triangle belongs to, by rules on the skeleton, and
// each region's seam side, up direction and texel density), mesh adjacency, and a region's
// triangles as a local mesh split along the region boundary and the cut edges (buildLocal).
// Declared in uv_atlas_internal.hpp.
#include "uv_atlas_internal.hpp"

#include "core/disjoint_sets.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>

namespace dermis::chargen::atlas_detail {
namespace {

glm::vec3 mirrorX(glm::vec3 p) {
    return {-p.x, p.y, p.z};
}

} // namespace

// --- regions ------------------------------------------------------------------------------------

Rules::Rules(const Skeleton& sk) {
    const Joint& ua = sk.joints[static_cast<std::size_t>(sk.at("upper_arm.l"))];
    shoulder = ua.head;
    d = ua.frame[1];
    palmN = ua.frame[0];
    wrist = sk.joints[static_cast<std::size_t>(sk.at("hand.l"))].head;
    ankle = sk.joints[static_cast<std::size_t>(sk.at("foot.l"))].head;
    const Joint& t1 = sk.joints[static_cast<std::size_t>(sk.at("thumb_01.l"))];
    thumbA = t1.head;
    thumbB = sk.joints[static_cast<std::size_t>(sk.at("thumb_03.l"))].tail;
    thumbSide = t1.frame[2]; // the thumb's flexion side (toward the palm)
    specs.resize(kRegionCount);
    const glm::vec3 armSeam = glm::normalize(palmN + glm::vec3(0, 0, -1));
    auto both = [&](int l, const std::string& name, glm::vec3 seam, glm::vec3 up, float scale) {
        specs[static_cast<std::size_t>(l)] = {name + ".l", seam, up, scale};
        specs[static_cast<std::size_t>(l + 1)] = {name + ".r", mirrorX(seam), mirrorX(up),
                                                  scale};
    };
    specs[kTorso] = {"torso", {0, 0, -1}, {0, 1, 0}, 1.0f};
    specs[kHeadFront] = {"face", {0, 0, -1}, {0, 1, 0}, 1.0f};
    specs[kHeadBack] = {"head_back", {0, 0, -1}, {0, 1, 0}, 0.8f};
    both(kArmL, "arm", armSeam, -d, 1.0f);
    both(kHandBackL, "hand_back", {0, 0, -1}, -d, 0.75f);
    both(kPalmL, "palm", {0, 0, -1}, -d, 0.75f);
    both(kLegL, "leg", {-1, 0, 0}, {0, 1, 0}, 1.0f);
    both(kFootTopL, "foot_top", {0, 0, -1}, {0, 0, -1}, 0.75f);
    both(kSoleL, "sole", {0, 0, -1}, {0, 0, -1}, 0.6f);
}

/// Region of a triangle with centroid c and unit normal n.
int Rules::classify(const glm::vec3& c, const glm::vec3& n) const {
    // Head: above a plane under the jaw and across the base of the skull.
    const glm::vec3 headN = glm::normalize(glm::vec3(0, 0.92f, 0.39f));
    if (c.y > 1.45f && std::abs(c.x) < 0.13f &&
        glm::dot(c - glm::vec3(0, 1.53f, 0.06f), headN) > 0)
        return c.z > -0.012f ? kHeadFront : kHeadBack;
    const int side = c.x >= 0 ? 0 : 1;
    const glm::vec3 q(std::abs(c.x), c.y, c.z);
    const glm::vec3 qn(side == 0 ? n.x : -n.x, n.y, n.z);
    // Hands: beyond the wrist; palm or back by normal and depth.
    if (q.x > 0.3f && glm::dot(q - wrist, d) > 0.0f) {
        // By the normal: every digit splits lengthwise into two half-tubes; the thumb, which
        // is turned toward the palm, splits about its own flexion side.
        const glm::vec3 ab = thumbB - thumbA;
        const float u = std::clamp(glm::dot(q - thumbA, ab) / glm::dot(ab, ab), 0.0f, 1.0f);
        const bool onThumb = u > 0.15f && glm::length(q - (thumbA + ab * u)) < 0.02f;
        const glm::vec3 facing = onThumb ? thumbSide : palmN;
        return (glm::dot(qn, facing) > 0 ? kPalmL : kHandBackL) + side;
    }
    // Arms: beyond a plane through the shoulder, from the armpit over the deltoid.
    const glm::vec3 shoulderN = glm::normalize(d + glm::vec3(0, 0.9f, 0));
    if (q.x > 0.12f && c.y > 1.0f &&
        glm::dot(q - (shoulder - glm::vec3(0.015f, 0, 0)), shoulderN) > 0)
        return kArmL + side;
    // Feet: below a plane through the ankle, tilted down toward the heel.
    const glm::vec3 footN = glm::normalize(glm::vec3(0, 1, -0.5f));
    if (c.y < 0.2f && glm::dot(q - (ankle + glm::vec3(0, -0.005f, 0)), footN) < 0)
        return (n.y < -0.5f && c.y < 0.025f ? kSoleL : kFootTopL) + side;
    // Legs: below the line from the crotch to the side of the hip.
    const glm::vec3 legN = glm::normalize(glm::vec3(-0.12f, 0.17f, 0));
    if (c.y < 1.0f && glm::dot(q - glm::vec3(0, 0.8f, 0), legN) < 0) return kLegL + side;
    return kTorso;
}

// --- mesh adjacency -------------------------------------------------------------------------

/// adj[t][c] = triangle across edge (t[c], t[c+1]); the mesh is a closed manifold.
std::vector<std::array<int, 3>> adjacency(const TriMesh& mesh) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
    for (std::size_t t = 0; t < mesh.tris.size(); ++t)
        for (int c = 0; c < 3; ++c)
            directed[{mesh.tris[t][c], mesh.tris[t][(c + 1) % 3]}] = static_cast<int>(t);
    std::vector<std::array<int, 3>> adj(mesh.tris.size());
    for (std::size_t t = 0; t < mesh.tris.size(); ++t)
        for (int c = 0; c < 3; ++c) {
            auto it = directed.find({mesh.tris[t][(c + 1) % 3], mesh.tris[t][c]});
            adj[t][static_cast<std::size_t>(c)] = it == directed.end() ? -1 : it->second;
        }
    return adj;
}

EdgeKey edgeKey(std::uint32_t a, std::uint32_t b) {
    return a < b ? EdgeKey{a, b} : EdgeKey{b, a};
}

// --- chart-local meshes -----------------------------------------------------------------------

LocalMesh buildLocal(const TriMesh& mesh, const std::vector<std::array<int, 3>>& adj,
                     const std::vector<int>& tris, const std::vector<int>& region, int r,
                     const std::set<EdgeKey>& cuts) {
    LocalMesh lm;
    lm.tris = tris;
    std::map<int, int> localIndex;
    for (std::size_t i = 0; i < tris.size(); ++i)
        localIndex[tris[i]] = static_cast<int>(i);
    const std::size_t nc = tris.size() * 3;
    DisjointSets corners(nc);
    auto cornerOf = [&](int lt, std::uint32_t v) {
        const glm::uvec3& tri =
            mesh.tris[static_cast<std::size_t>(tris[static_cast<std::size_t>(lt)])];
        for (int c = 0; c < 3; ++c)
            if (tri[c] == v) return static_cast<std::size_t>(lt) * 3 + static_cast<std::size_t>(c);
        return std::size_t(0);
    };
    for (std::size_t i = 0; i < tris.size(); ++i) {
        const auto t = static_cast<std::size_t>(tris[i]);
        for (int c = 0; c < 3; ++c) {
            const int o = adj[t][static_cast<std::size_t>(c)];
            if (o < 0 || region[static_cast<std::size_t>(o)] != r) continue;
            const std::uint32_t a = mesh.tris[t][c], b = mesh.tris[t][(c + 1) % 3];
            if (cuts.count(edgeKey(a, b))) continue;
            const int lo = localIndex[o];
            corners.joinToSmaller(i * 3 + static_cast<std::size_t>(c), cornerOf(lo, a));
            corners.joinToSmaller(i * 3 + static_cast<std::size_t>((c + 1) % 3), cornerOf(lo, b));
        }
    }
    std::map<std::size_t, std::uint32_t> vid;
    lm.local.resize(tris.size());
    for (std::size_t i = 0; i < tris.size(); ++i)
        for (int c = 0; c < 3; ++c) {
            const std::size_t root = corners.root(i * 3 + static_cast<std::size_t>(c));
            auto it = vid.find(root);
            if (it == vid.end()) {
                it = vid.emplace(root, static_cast<std::uint32_t>(lm.source.size())).first;
                lm.source.push_back(mesh.tris[static_cast<std::size_t>(tris[i])][c]);
            }
            lm.local[i][c] = it->second;
        }
    // Boundary: directed local edges without a twin.
    std::set<std::pair<std::uint32_t, std::uint32_t>> directed;
    for (const auto& t : lm.local)
        for (int c = 0; c < 3; ++c)
            directed.insert({t[c], t[(c + 1) % 3]});
    std::map<std::uint32_t, std::uint32_t> next;
    for (const auto& e : directed)
        if (!directed.count({e.second, e.first})) next[e.first] = e.second;
    lm.loopOf.assign(lm.source.size(), -1);
    for (const auto& [start, unused] : next) {
        (void)unused;
        if (lm.loopOf[start] >= 0) continue;
        std::vector<std::uint32_t> loop;
        std::uint32_t v = start;
        do {
            lm.loopOf[v] = static_cast<int>(lm.loops.size());
            loop.push_back(v);
            v = next[v];
        } while (v != start && loop.size() <= next.size());
        lm.loops.push_back(loop);
    }
    return lm;
}

} // namespace dermis::chargen::atlas_detail
