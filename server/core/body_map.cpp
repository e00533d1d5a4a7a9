// What each joint of a character is. See body_map.hpp.
#include "body_map.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <functional>

namespace dermis {

std::string_view roleWord(JointRole r) {
    switch (r) {
    case JointRole::Pelvis: return "pelvis";
    case JointRole::Spine: return "spine";
    case JointRole::Neck: return "neck";
    case JointRole::Head: return "head";
    case JointRole::Clavicle: return "clavicle";
    case JointRole::Shoulder: return "shoulder";
    case JointRole::Elbow: return "elbow";
    case JointRole::Wrist: return "wrist";
    case JointRole::Finger: return "finger";
    case JointRole::Hip: return "hip";
    case JointRole::Knee: return "knee";
    case JointRole::Ankle: return "ankle";
    case JointRole::Toe: return "toe";
    case JointRole::Twist: return "twist";
    case JointRole::Other: break;
    }
    return "joint";
}

namespace {

/// Lower-case words of a joint name: split at non-alphanumerics and at camel-case humps
/// ("LeftForeArm" → left, fore, arm), digits dropped.
std::vector<std::string> words(const std::string& name) {
    std::vector<std::string> out;
    std::string cur;
    const auto flush = [&] {
        if (!cur.empty()) out.push_back(cur);
        cur.clear();
    };
    for (std::size_t i = 0; i < name.size(); ++i) {
        const unsigned char c = static_cast<unsigned char>(name[i]);
        if (std::isdigit(c)) {
            flush();
            continue;
        }
        if (!std::isalpha(c)) {
            flush();
            continue;
        }
        if (std::isupper(c) && i > 0 && std::islower(static_cast<unsigned char>(name[i - 1]))) flush();
        cur.push_back(static_cast<char>(std::tolower(c)));
    }
    flush();
    return out;
}

bool has(const std::string& s, std::initializer_list<const char*> keys) {
    for (const char* k : keys)
        if (s.find(k) != std::string::npos) return true;
    return false;
}

} // namespace

JointRole roleFromName(const std::string& name) {
    static const char* kDrop[] = {"l", "r", "left", "right", "mixamorig", "cc", "base", "skeleton", "bip",
                                  "def", "org", "mch", "j", "bn", "b", "joint", "jnt", "bone", "mixamo"};
    static const char* kNotBody[] = {"ik", "control", "ctrl", "pole", "slot", "target", "helper", "nub",
                                     "socket", "attach", "prop", "weapon", "end", "tip", "null"};
    std::string s;
    // "arm" and "leg" alone name Mixamo's upper arm and shin; numbered ("leg_joint_L_2") they
    // only say which limb.
    const bool numbered = std::any_of(name.begin(), name.end(), [](char ch) { return std::isdigit(static_cast<unsigned char>(ch)) != 0; });
    for (const std::string& w : words(name)) {
        for (const char* n : kNotBody)
            if (w == n) return JointRole::Other;
        bool drop = false;
        for (const char* d : kDrop) drop = drop || w == d;
        if (!drop) s += w;
    }
    if (s.empty()) return JointRole::Other;
    if (has(s, {"twist", "roll"})) return JointRole::Twist;
    if (has(s, {"thumb", "index", "middle", "ring", "pinky", "little", "finger"})) return JointRole::Finger;
    if (has(s, {"clavicle", "collar", "shoulder"})) return JointRole::Clavicle;
    if (has(s, {"forearm", "lowerarm", "elbow"})) return JointRole::Elbow;
    if (has(s, {"upperarm", "uparm"}) || (s == "arm" && !numbered)) return JointRole::Shoulder;
    if (has(s, {"hand", "wrist", "palm"})) return JointRole::Wrist;
    if (has(s, {"thigh", "upleg", "upperleg"})) return JointRole::Hip;
    if (has(s, {"shin", "calf", "lowerleg", "knee"}) || (s == "leg" && !numbered)) return JointRole::Knee;
    if (has(s, {"foot", "ankle"})) return JointRole::Ankle;
    if (has(s, {"toe", "ball"})) return JointRole::Toe;
    if (has(s, {"neck"})) return JointRole::Neck;
    if (has(s, {"head"})) return JointRole::Head;
    if (has(s, {"spine", "chest", "torso", "abdomen", "belly", "waist"})) return JointRole::Spine;
    if (has(s, {"pelvis", "hip"})) return JointRole::Pelvis;
    return JointRole::Other;
}

int BodyMap::find(JointRole role, char side) const {
    for (const Limb& l : limbs)
        for (int n : l.chain)
            if (byNode[static_cast<std::size_t>(n)].role == role && byNode[static_cast<std::size_t>(n)].side == side)
                return n;
    for (const JointInfo& j : byNode)
        if (j.node >= 0 && j.role == role && j.side == side) return j.node;
    return -1;
}

BodyMap mapBody(const Model& model, const RestSkin& rest, const SymmetryPlane& plane) {
    BodyMap body;
    const std::size_t nodes = model.nodes.size();
    body.byNode.resize(nodes);
    const glm::vec3 extent = rest.bounds.max - rest.bounds.min;
    body.height = std::max(1e-6, static_cast<double>(extent.y));
    body.width = std::max(1e-6, static_cast<double>(extent[plane.axis]));
    const auto pos = [&](int n) {
        return static_cast<std::size_t>(n) < rest.world.size() ? glm::dvec3(rest.world[static_cast<std::size_t>(n)][3])
                                                                : glm::dvec3(0.0);
    };
    // Which joints deform the skin.
    std::vector<float> maxWeight(nodes, 0.0f);
    for (const MeshPart& p : model.parts)
        for (std::size_t v = 0; v < p.joints.size() && v < p.weights.size(); ++v)
            for (int k = 0; k < 4; ++k) {
                const std::size_t inf = p.joints[v][k];
                if (inf >= p.influences.size()) continue;
                const int n = p.influences[inf].node;
                if (n >= 0 && static_cast<std::size_t>(n) < nodes)
                    maxWeight[static_cast<std::size_t>(n)] = std::max(maxWeight[static_cast<std::size_t>(n)], p.weights[v][k]);
            }
    std::vector<std::vector<int>> children(nodes);
    for (int j : model.joints) {
        if (j < 0 || static_cast<std::size_t>(j) >= nodes) continue;
        JointInfo& info = body.byNode[static_cast<std::size_t>(j)];
        info.node = j;
        info.role = roleFromName(model.nodes[static_cast<std::size_t>(j)].name);
        info.deforms = maxWeight[static_cast<std::size_t>(j)] >= 0.05f;
        info.side = sideOf(model.nodes[static_cast<std::size_t>(j)].name);
        if (info.side == 0) {
            const double d = pos(j)[plane.axis] - plane.offset;
            if (std::abs(d) > 0.04 * body.width) info.side = d > 0 ? 'l' : 'r';
        }
        if (const int p = model.parentJoint(j); p >= 0) children[static_cast<std::size_t>(p)].push_back(j);
    }
    // Reach (farthest descendant) and whether a subtree deforms, children before parents.
    std::vector<bool> subtreeDeforms(nodes, false);
    std::function<void(int)> visit = [&](int j) {
        JointInfo& info = body.byNode[static_cast<std::size_t>(j)];
        bool d = info.deforms;
        double reach = 0.0;
        for (int c : children[static_cast<std::size_t>(j)]) {
            visit(c);
            d = d || subtreeDeforms[static_cast<std::size_t>(c)];
            reach = std::max(reach, glm::length(pos(c) - pos(j)) + body.byNode[static_cast<std::size_t>(c)].reach);
        }
        subtreeDeforms[static_cast<std::size_t>(j)] = d;
        info.reach = reach;
    };
    for (int j : model.joints)
        if (j >= 0 && static_cast<std::size_t>(j) < nodes && model.parentJoint(j) < 0) visit(j);
    // Limbs: chains from a sided joint whose parent joint is central.
    for (int j : model.joints) {
        if (j < 0 || static_cast<std::size_t>(j) >= nodes) continue;
        const JointInfo& info = body.byNode[static_cast<std::size_t>(j)];
        const int parent = model.parentJoint(j);
        if (info.side == 0 || !subtreeDeforms[static_cast<std::size_t>(j)] || parent < 0 ||
            body.byNode[static_cast<std::size_t>(parent)].side != 0)
            continue;
        Limb limb;
        limb.side = info.side;
        for (int cur = j; cur >= 0;) {
            limb.chain.push_back(cur);
            int next = -1;
            double best = -1.0;
            for (int c : children[static_cast<std::size_t>(cur)]) {
                if (!subtreeDeforms[static_cast<std::size_t>(c)]) continue;
                const double r = glm::length(pos(c) - pos(cur)) + body.byNode[static_cast<std::size_t>(c)].reach;
                if (r > best) {
                    best = r;
                    next = c;
                }
            }
            cur = next;
        }
        if (limb.chain.size() < 2) continue;
        limb.leg = pos(limb.chain.back()).y < rest.bounds.min.y + 0.2 * body.height;
        body.limbs.push_back(std::move(limb));
    }
    // Limbs whose names say no elbow or knee: the joint at half the chain's length is.
    for (std::size_t li = 0; li < body.limbs.size(); ++li) {
        Limb& limb = body.limbs[li];
        const JointRole mid = limb.leg ? JointRole::Knee : JointRole::Elbow;
        bool named = false;
        for (int n : limb.chain) {
            body.byNode[static_cast<std::size_t>(n)].limb = static_cast<int>(li);
            named = named || body.byNode[static_cast<std::size_t>(n)].role == mid;
        }
        if (named || limb.chain.size() < 3) continue;
        std::vector<double> along(limb.chain.size(), 0.0);
        for (std::size_t k = 1; k < limb.chain.size(); ++k)
            along[k] = along[k - 1] + glm::length(pos(limb.chain[k]) - pos(limb.chain[k - 1]));
        std::size_t m = 1;
        for (std::size_t k = 1; k + 1 < limb.chain.size(); ++k)
            if (std::abs(along[k] - 0.5 * along.back()) < std::abs(along[m] - 0.5 * along.back())) m = k;
        const auto set = [&](std::size_t k, JointRole r) {
            JointRole& role = body.byNode[static_cast<std::size_t>(limb.chain[k])].role;
            if (role == JointRole::Other) role = r;
        };
        body.byNode[static_cast<std::size_t>(limb.chain[m])].role = mid;
        set(m - 1, limb.leg ? JointRole::Hip : JointRole::Shoulder);
        if (m + 1 < limb.chain.size()) set(m + 1, limb.leg ? JointRole::Ankle : JointRole::Wrist);
        if (limb.leg && m + 2 < limb.chain.size()) set(m + 2, JointRole::Toe);
    }
    return body;
}

int mainChild(const Model& model, const BodyMap& body, int node) {
    int best = -1;
    double reach = -1.0;
    for (int j : model.joints) {
        if (model.parentJoint(j) != node) continue;
        const JointInfo* info = body.info(j);
        const double r = info ? info->reach + 1e-9 * static_cast<double>(info->deforms) : 0.0;
        if (r > reach) {
            reach = r;
            best = j;
        }
    }
    return best;
}

int boneParent(const Model& model, const BodyMap& body, int j, std::vector<int>* skipped) {
    int p = model.parentJoint(j);
    while (p >= 0 && body.info(p) && body.info(p)->role == JointRole::Twist) {
        if (skipped) skipped->push_back(p);
        p = model.parentJoint(p);
    }
    return p;
}

int boneChild(const Model& model, const BodyMap& body, int j, std::vector<int>* skipped) {
    int c = mainChild(model, body, j);
    while (c >= 0 && body.info(c) && body.info(c)->role == JointRole::Twist) {
        const int next = mainChild(model, body, c);
        if (next < 0) break;
        if (skipped) skipped->push_back(c);
        c = next;
    }
    return c;
}

std::string describeJoint(const Model& model, const BodyMap& body, int node) {
    const JointInfo* info = body.info(node);
    if (!info) return node >= 0 && static_cast<std::size_t>(node) < model.nodes.size() ? model.nodes[static_cast<std::size_t>(node)].name : "";
    if (info->role == JointRole::Other || info->role == JointRole::Twist)
        return model.nodes[static_cast<std::size_t>(node)].name;
    std::string out;
    if (info->side == 'l') out = "left ";
    if (info->side == 'r') out = "right ";
    return out + std::string(roleWord(info->role));
}

} // namespace dermis
