// Writing the default character (see gltf_out.hpp). This file holds the generator's tinygltf
// implementation (the generator does not link dermis_io, which has its own).
#include <fstream> // tinygltf's writer needs it
#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_STB_IMAGE // the character has no images
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>

#include "gltf_out.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>
#include <sstream>

namespace dermis::chargen {
namespace {

/// Appends raw bytes to the buffer as a new buffer view (4-byte aligned); returns its index.
int addView(tinygltf::Model& g, const void* data, std::size_t bytes, int target) {
    auto& buf = g.buffers[0].data;
    while (buf.size() % 4)
        buf.push_back(0);
    tinygltf::BufferView view;
    view.buffer = 0;
    view.byteOffset = buf.size();
    view.byteLength = bytes;
    view.target = target;
    const auto* p = static_cast<const unsigned char*>(data);
    buf.insert(buf.end(), p, p + bytes);
    g.bufferViews.push_back(view);
    return static_cast<int>(g.bufferViews.size()) - 1;
}

int addAccessor(tinygltf::Model& g, int view, int componentType, int type, std::size_t count,
                std::vector<double> mn = {}, std::vector<double> mx = {}, bool normalized = false) {
    tinygltf::Accessor a;
    a.bufferView = view;
    a.byteOffset = 0;
    a.componentType = componentType;
    a.type = type;
    a.count = count;
    a.minValues = std::move(mn);
    a.maxValues = std::move(mx);
    a.normalized = normalized;
    g.accessors.push_back(a);
    return static_cast<int>(g.accessors.size()) - 1;
}

std::vector<double> quatValues(const glm::quat& q) {
    return {q.x, q.y, q.z, q.w};
}

double round5(double x) {
    return std::round(x * 1e5) / 1e5;
}

} // namespace

std::vector<std::uint8_t> encodeGlb(const dermis::Model& model) {
    tinygltf::Model g;
    g.asset.version = "2.0";
    g.asset.generator = "dermis-charactergen";
    g.buffers.emplace_back();
    const dermis::MeshPart& part = model.parts.at(0);
    const int meshNode = static_cast<int>(model.nodes.size()) - 1;

    // Nodes.
    for (std::size_t i = 0; i < model.nodes.size(); ++i) {
        const dermis::Node& n = model.nodes[i];
        tinygltf::Node gn;
        gn.name = n.name;
        if (n.translation != glm::vec3(0))
            gn.translation = {n.translation.x, n.translation.y, n.translation.z};
        if (n.rotation != glm::quat(1, 0, 0, 0)) gn.rotation = quatValues(n.rotation);
        g.nodes.push_back(gn);
    }
    for (std::size_t i = 0; i < model.nodes.size(); ++i)
        if (model.nodes[i].parent >= 0)
            g.nodes[static_cast<std::size_t>(model.nodes[i].parent)].children.push_back(
                static_cast<int>(i));
    g.nodes[static_cast<std::size_t>(meshNode)].mesh = 0;
    g.nodes[static_cast<std::size_t>(meshNode)].skin = 0;

    // Mesh.
    const std::size_t nv = part.positions.size();
    glm::vec3 lo(1e30f), hi(-1e30f);
    for (const auto& p : part.positions) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    constexpr int kArray = TINYGLTF_TARGET_ARRAY_BUFFER,
                  kElement = TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER;
    constexpr int kFloat = TINYGLTF_COMPONENT_TYPE_FLOAT;
    const int pos = addAccessor(g, addView(g, part.positions.data(), nv * 12, kArray), kFloat,
                                TINYGLTF_TYPE_VEC3, nv, {lo.x, lo.y, lo.z}, {hi.x, hi.y, hi.z});
    const int nrm = addAccessor(g, addView(g, part.normals.data(), nv * 12, kArray), kFloat,
                                TINYGLTF_TYPE_VEC3, nv);
    const int uv =
        addAccessor(g, addView(g, part.uvs.data(), nv * 8, kArray), kFloat, TINYGLTF_TYPE_VEC2, nv);
    std::vector<std::uint8_t> joints;
    for (const auto& j : part.joints)
        for (int c = 0; c < 4; ++c)
            joints.push_back(static_cast<std::uint8_t>(j[c]));
    const int jnt = addAccessor(g, addView(g, joints.data(), joints.size(), kArray),
                                TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_TYPE_VEC4, nv);
    const int wgt = addAccessor(g, addView(g, part.weights.data(), nv * 16, kArray), kFloat,
                                TINYGLTF_TYPE_VEC4, nv);
    std::vector<std::uint16_t> indices(part.indices.begin(), part.indices.end());
    const int idx =
        addAccessor(g, addView(g, indices.data(), indices.size() * 2, kElement),
                    TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, TINYGLTF_TYPE_SCALAR, indices.size());
    tinygltf::Primitive prim;
    prim.attributes = {{"POSITION", pos},
                       {"NORMAL", nrm},
                       {"TEXCOORD_0", uv},
                       {"JOINTS_0", jnt},
                       {"WEIGHTS_0", wgt}};
    prim.indices = idx;
    prim.material = 0;
    prim.mode = TINYGLTF_MODE_TRIANGLES;
    tinygltf::Mesh mesh;
    mesh.name = part.name;
    mesh.primitives.push_back(prim);
    g.meshes.push_back(mesh);

    tinygltf::Material mat;
    mat.name = model.materials.at(0).name;
    const glm::vec4 c = model.materials[0].baseColorFactor;
    mat.pbrMetallicRoughness.baseColorFactor = {c.r, c.g, c.b, c.a};
    mat.pbrMetallicRoughness.metallicFactor = 0.0;
    mat.pbrMetallicRoughness.roughnessFactor = 0.65;
    g.materials.push_back(mat);

    // Skin.
    std::vector<float> ibm;
    for (const auto& inf : part.influences)
        for (int col = 0; col < 4; ++col)
            for (int row = 0; row < 4; ++row)
                ibm.push_back(inf.inverseBind[col][row]);
    tinygltf::Skin skin;
    skin.name = "skeleton";
    skin.inverseBindMatrices = addAccessor(g, addView(g, ibm.data(), ibm.size() * 4, 0), kFloat,
                                           TINYGLTF_TYPE_MAT4, part.influences.size());
    for (const auto& inf : part.influences)
        skin.joints.push_back(inf.node);
    skin.skeleton = 0;
    g.skins.push_back(skin);

    // Animations: one input accessor per clip (all channels share the key times).
    for (const dermis::Clip& clip : model.clips) {
        tinygltf::Animation anim;
        anim.name = clip.name;
        const auto& times = clip.channels.at(0).times;
        const int input =
            addAccessor(g, addView(g, times.data(), times.size() * 4, 0), kFloat,
                        TINYGLTF_TYPE_SCALAR, times.size(), {times.front()}, {times.back()});
        for (const dermis::Channel& ch : clip.channels) {
            const bool rot = ch.path == dermis::ChannelPath::Rotation;
            tinygltf::AnimationSampler s;
            s.input = input;
            s.interpolation = "LINEAR";
            s.output = addAccessor(g, addView(g, ch.values.data(), ch.values.size() * 4, 0), kFloat,
                                   rot ? TINYGLTF_TYPE_VEC4 : TINYGLTF_TYPE_VEC3, times.size());
            anim.samplers.push_back(s);
            tinygltf::AnimationChannel ac;
            ac.sampler = static_cast<int>(anim.samplers.size()) - 1;
            ac.target_node = ch.node;
            ac.target_path = rot                                           ? "rotation"
                             : ch.path == dermis::ChannelPath::Translation ? "translation"
                                                                           : "scale";
            anim.channels.push_back(ac);
        }
        g.animations.push_back(anim);
    }
    while (g.buffers[0].data.size() % 4)
        g.buffers[0].data.push_back(0);

    tinygltf::Scene scene;
    scene.name = "default";
    scene.nodes = {0, meshNode};
    g.scenes.push_back(scene);
    g.defaultScene = 0;

    tinygltf::TinyGLTF writer;
    std::ostringstream os;
    if (!writer.WriteGltfSceneToStream(&g, os, /*prettyPrint=*/false, /*writeBinary=*/true))
        return {};
    const std::string s = os.str();
    return std::vector<std::uint8_t>(s.begin(), s.end());
}

std::string chartsJson(const Character& ch, const std::string& modelFile) {
    // Hand-assembled so that each chart and landmark sits on one line (diff-friendly); the
    // items themselves are nlohmann::ordered_json, keys in the order written here.
    using nlohmann::ordered_json;
    auto line = [](const ordered_json& j) { return j.dump(); };
    std::ostringstream os;
    os << "{\n";
    os << "  \"format\": \"dermis.charts/1\",\n";
    os << "  \"model\": " << ordered_json(modelFile).dump() << ",\n";
    os << "  \"description\": "
       << ordered_json(
              "UV charts of the built-in default character. glTF UV convention: u right, v down, "
              "(0,0) = first pixel of the first image row. bounds = [u_min, v_min, u_max, v_max]. "
              "Each chart is turned so that up on the body is up in the texture (v decreasing) and "
              "is never mirrored; charts never overlap (padding 6 texels at 1024). landmarks give "
              "the texture coordinates of spots that suit the built-in patterns, with the joint "
              "and "
              "axis that drive them.")
              .dump()
       << ",\n";
    os << "  \"triangles\": " << ch.model.triangleCount() << ",\n";
    os << "  \"vertices\": " << ch.model.parts.at(0).positions.size() << ",\n";
    os << "  \"charts\": [\n";
    for (std::size_t i = 0; i < ch.atlas.charts.size(); ++i) {
        const ChartInfo& c = ch.atlas.charts[i];
        ordered_json j;
        j["name"] = c.name;
        j["bounds"] = {round5(c.lo.x), round5(c.lo.y), round5(c.hi.x), round5(c.hi.y)};
        j["triangles"] = c.triangles;
        j["surface_area_m2"] = round5(c.surfaceArea);
        j["texels_per_metre_at_1024"] =
            static_cast<int>(std::lround(1024.0 * std::sqrt(c.uvArea / c.surfaceArea)));
        j["conformal_distortion"] = std::round(c.conformal * 1000.0) / 1000.0;
        os << "    " << line(j) << (i + 1 < ch.atlas.charts.size() ? ",\n" : "\n");
    }
    os << "  ],\n";
    os << "  \"landmarks\": [\n";
    for (std::size_t i = 0; i < ch.landmarks.size(); ++i) {
        const Landmark& l = ch.landmarks[i];
        ordered_json j;
        j["name"] = l.name;
        j["chart"] = l.chart;
        j["uv"] = {round5(l.uv.x), round5(l.uv.y)};
        j["position"] = {round5(l.position.x), round5(l.position.y), round5(l.position.z)};
        j["pattern"] = l.pattern;
        j["joint"] = l.joint;
        j["axis"] = l.axis;
        os << "    " << line(j) << (i + 1 < ch.landmarks.size() ? ",\n" : "\n");
    }
    os << "  ],\n";
    ordered_json names = ordered_json::array();
    for (const auto& j : ch.skeleton.joints)
        names.push_back(j.name);
    os << "  \"joints\": " << names.dump() << "\n";
    os << "}\n";
    return os.str();
}

} // namespace dermis::chargen
