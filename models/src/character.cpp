// Assembly of the default character (see character.hpp).
#include "character.hpp"

#include "clips.hpp"
#include "core/rig.hpp"

#include <glm/gtc/matrix_transform.hpp>

#include <cmath>
#include <cstdio>

namespace dermis::chargen {
namespace {

/// The body surface point hit by a ray from `from` (inside the body) along `dir`.
glm::vec3 surfaceAlong(const Body& body, glm::vec3 from, glm::vec3 dir) {
    dir = glm::normalize(dir);
    float t = 0.0f;
    for (int i = 0; i < 400 && body.sdf(from + dir * t) < 0.0f; ++i)
        t += 0.0025f;
    // Bisection between the last inside and the first outside sample.
    float a = std::max(t - 0.0025f, 0.0f), b = t;
    for (int i = 0; i < 30; ++i) {
        const float m = 0.5f * (a + b);
        (body.sdf(from + dir * m) < 0.0f ? a : b) = m;
    }
    return from + dir * (0.5f * (a + b));
}

} // namespace

bool buildCharacter(Character& out, std::string& error, std::FILE* log) {
    auto say = [&](const char* fmt, auto... args) {
        if (log) std::fprintf(log, fmt, args...);
    };
    out.skeleton = buildSkeleton();
    const Skeleton& sk = out.skeleton;
    const Body body(sk);

    // Surface.
    out.mesh = polygonize(body, kGridCell);
    say("polygonized: %zu triangles\n", out.mesh.tris.size());
    decimate(out.mesh, body, kTriangleBudget);
    optimize(out.mesh, body, 4);
    const TopologyReport topo = checkTopology(out.mesh);
    if (!topo.closedManifold || topo.euler != 2) {
        error = "surface is not a closed genus-0 manifold: " + topo.problem;
        return false;
    }
    if (out.mesh.tris.size() != kTriangleBudget) {
        error = "triangle budget missed: " + std::to_string(out.mesh.tris.size());
        return false;
    }
    say("surface: %zu vertices, %zu triangles, smallest angle %.1f°\n", out.mesh.positions.size(),
        out.mesh.tris.size(), static_cast<double>(topo.minAngleDeg));

    // Atlas and weights.
    if (!buildAtlas(out.mesh, body, sk, out.atlas, error, log)) return false;
    for (const ChartInfo& c : out.atlas.charts)
        say("  chart %-12s %5d tris  uv [%.3f %.3f]-[%.3f %.3f]  conformal %.3f  area %.3f\n",
            c.name.c_str(), c.triangles, static_cast<double>(c.lo.x), static_cast<double>(c.lo.y),
            static_cast<double>(c.hi.x), static_cast<double>(c.hi.y),
            static_cast<double>(c.conformal), static_cast<double>(c.areaSpread));
    out.weights = computeWeights(out.mesh, body, sk);

    // Model.
    dermis::Model& m = out.model;
    m = dermis::Model{};
    for (std::size_t j = 0; j < sk.joints.size(); ++j) {
        dermis::Node n;
        n.name = sk.joints[j].name;
        n.parent = sk.joints[j].parent;
        n.translation = sk.restLocalTranslation(static_cast<int>(j));
        n.rotation = sk.restLocalRotation(static_cast<int>(j));
        m.nodes.push_back(n);
        m.joints.push_back(static_cast<int>(j));
    }
    dermis::Node bodyNode;
    bodyNode.name = "body";
    m.nodes.push_back(bodyNode);

    const std::vector<glm::mat4> restWorld = dermis::worldMatrices(m, dermis::restPose(m));
    dermis::MeshPart part;
    part.name = "body";
    part.material = 0;
    for (std::size_t v = 0; v < out.atlas.source.size(); ++v) {
        const std::uint32_t s = out.atlas.source[v];
        part.positions.push_back(out.mesh.positions[s]);
        part.normals.push_back(glm::normalize(body.gradient(out.mesh.positions[s])));
        part.uvs.push_back(out.atlas.uvs[v]);
        part.joints.push_back(out.weights.joints[s]);
        part.weights.push_back(out.weights.weights[s]);
    }
    for (const auto& t : out.atlas.tris)
        part.indices.insert(part.indices.end(), {t[0], t[1], t[2]});
    for (std::size_t j = 0; j < sk.joints.size(); ++j)
        part.influences.push_back({static_cast<int>(j), glm::inverse(restWorld[j])});
    for (const auto& w : part.weights) {
        const float sum = w[0] + w[1] + w[2] + w[3];
        if (std::abs(sum - 1.0f) > 1e-6f || w[0] <= 0.0f) {
            error = "skin weights not normalised";
            return false;
        }
    }
    m.parts.push_back(std::move(part));
    dermis::Material skin;
    skin.name = "skin";
    skin.baseColorFactor = glm::vec4(0.80f, 0.62f, 0.52f, 1.0f);
    m.materials.push_back(skin);
    m.clips = buildClips(sk);
    say("model: %zu nodes, %zu joints, %zu vertices, %zu clips\n", m.nodes.size(), m.joints.size(),
        m.parts[0].positions.size(), m.clips.size());

    // Landmarks for pattern placement (left side; right side mirrored).
    struct Spot {
        const char* name;
        const char* pattern;
        const char* joint;
        const char* axis;
        glm::vec3 from, dir;
        bool sided;
    };
    auto head = [&](const char* n) { return sk.joints[static_cast<std::size_t>(sk.at(n))].head; };
    const glm::vec3 armAxis = sk.joints[static_cast<std::size_t>(sk.at("upper_arm.l"))].frame[1];
    const Spot spots[] = {
        {"stomach", "stomach_wrinkles", "spine_02", "x", {0, 1.06f, 0}, {0, 0, 1}, false},
        {"waist_side", "waist_twist", "spine_02", "y", {0, 1.08f, 0}, {1, 0, 0.15f}, true},
        {"ribs", "ribs", "chest", "x", {0.02f, 1.22f, 0}, {0.8f, 0, 0.6f}, true},
        {"clavicle", "clavicle", "upper_arm", "z", {0.08f, 1.42f, 0}, {0, 0.35f, 1}, true},
        {"scapula", "scapula", "upper_arm", "x", {0.09f, 1.33f, -0.03f}, {0, 0, -1}, true},
        {"neck_front", "neck_rings", "neck_01", "x", {0, 1.5f, -0.03f}, {0, 0, 1}, false},
        {"biceps",
         "round_bulge",
         "forearm",
         "x",
         head("upper_arm.l") + armAxis * 0.15f,
         {0, 0, 1},
         true},
        {"elbow_inner", "crease", "forearm", "x", head("forearm.l"), {0, 0, 1}, true},
        {"thigh_front",
         "elongated_bulge",
         "thigh",
         "x",
         glm::mix(head("thigh.l"), head("shin.l"), 0.4f),
         {0, 0, 1},
         true},
        {"knee_back", "crease", "shin", "x", head("shin.l"), {0, 0, -1}, true},
    };
    out.landmarks.clear();
    for (const Spot& s : spots)
        for (int side = 0; side < (s.sided ? 2 : 1); ++side) {
            Landmark l;
            const std::string sfx = s.sided ? (side == 0 ? ".l" : ".r") : "";
            l.name = s.name + sfx;
            l.pattern = s.pattern;
            l.joint =
                sk.find(std::string(s.joint) + sfx) >= 0 ? std::string(s.joint) + sfx : s.joint;
            l.axis = s.axis;
            glm::vec3 from = s.from, dir = s.dir;
            if (side == 1) {
                from.x = -from.x;
                dir.x = -dir.x;
            }
            l.position = surfaceAlong(body, from, dir);
            int chart = -1;
            l.uv = uvAt(out.mesh, out.atlas, l.position, &chart);
            l.chart = chart >= 0 ? out.atlas.charts[static_cast<std::size_t>(chart)].name : "";
            out.landmarks.push_back(l);
        }
    return true;
}

} // namespace dermis::chargen
