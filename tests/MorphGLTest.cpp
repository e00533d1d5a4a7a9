// MorphGLTest — glTF morph targets on the GPU (shaders/skin.vert: targets in bind space, then
// skinning) against the CPU reference (core/rig.hpp skin with morph weights), on the backend named
// by $DERMIS_TEST_GL: transform-feedback vertices equal the CPU's on a hand-made file and on
// CesiumMan with synthetic targets over its clips; a morphed frame is the frame of its baked
// vertices (legacy and pbr shading, vertex and tessellated displacement), also when the height
// maps' layout re-orders the vertices; and weight 0 is the unmorphed frame.
#include "BuildPaths.hpp"
#include "GltfTestBuilder.hpp"
#include "ImageCompare.hpp"
#include "RendererSuite.hpp"

#include "core/texture_layout.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace dermis;
using namespace dermis::test;

namespace {

const std::string kCesium = std::string(dermis::build::testModelsDir()) + "/CesiumMan/CesiumMan.glb";

class MorphGLTest : public RendererSuite {};

/// CesiumMan with two synthetic targets on every part: "swell" moves each vertex along its
/// normal by a ripple of ±3 cm and tips the normal, "lift" moves everything 2 cm along +z.
std::shared_ptr<const Model> cesiumWithMorphs() {
    auto m = loadGltfFile(kCesium);
    EXPECT_TRUE(m) << (m ? "" : m.error().message);
    if (!m) return nullptr;
    m->morphWeights = {{"swell", 0, 0.0f}, {"lift", 0, 0.0f}};
    for (MeshPart& p : m->parts) {
        MorphTarget swell, lift;
        swell.weight = 0;
        lift.weight = 1;
        for (std::size_t v = 0; v < p.positions.size(); ++v) {
            const float s = std::sin(40.0f * p.positions[v].y + 25.0f * p.positions[v].z);
            swell.positions.push_back(p.normals[v] * (0.03f * s));
            swell.normals.push_back(glm::vec3(0.4f * s, 0.0f, 0.0f));
            lift.positions.push_back(glm::vec3(0.0f, 0.0f, 0.02f));
        }
        p.morphs = {swell, lift};
    }
    return std::make_shared<const Model>(std::move(*m));
}

std::shared_ptr<const Model> morphedTriangle() {
    gltf::MorphedTriangle t;
    auto m = gltf::parseModel(t.b.glb());
    EXPECT_TRUE(m.ok()) << (m.ok() ? "" : m.error().message);
    return m.ok() ? std::make_shared<const Model>(std::move(*m)) : nullptr;
}

/// `m` with its targets baked in at `weights` and dropped.
std::shared_ptr<const Model> baked(const Model& m, const std::vector<float>& weights) {
    return std::make_shared<const Model>(gltf::bakedMorphs(m, weights));
}

void expectGpuEqualsCpu(Renderer& gl, const std::shared_ptr<const Model>& model,
                        const std::vector<std::vector<float>>& weightSets) {
    ASSERT_TRUE(model);
    std::vector<LocalPose> poses = {restPose(*model)};
    for (std::size_t c = 0; c < model->clips.size() && c < 2; ++c)
        poses.push_back(sampleClip(*model, static_cast<int>(c), 0.6f * model->clips[c].duration));
    for (const LocalPose& pose : poses)
        for (const std::vector<float>& w : weightSets) {
            const auto world = worldMatrices(*model, pose);
            const auto cpu = skin(*model, world, w);
            auto gpu = gl.skinOnGpu(model, world, w);
            ASSERT_TRUE(gpu) << gpu.error().message;
            ASSERT_EQ(gpu->size(), cpu.size());
            float maxPos = 0.0f, minDot = 1.0f;
            for (std::size_t pi = 0; pi < cpu.size(); ++pi) {
                ASSERT_EQ((*gpu)[pi].positions.size(), cpu[pi].positions.size());
                for (std::size_t v = 0; v < cpu[pi].positions.size(); ++v) {
                    maxPos = std::max(maxPos, glm::length((*gpu)[pi].positions[v] - cpu[pi].positions[v]));
                    minDot = std::min(minDot, glm::dot((*gpu)[pi].normals[v], cpu[pi].normals[v]));
                }
            }
            // The tolerance of RendererGLTest's skinning comparison.
            EXPECT_LE(maxPos, 1e-4f) << "weights " << (w.empty() ? -1.0f : w[0]);
            EXPECT_GE(minDot, 0.9999f) << "weights " << (w.empty() ? -1.0f : w[0]);
        }
}

FrameRequest request(const std::shared_ptr<const Model>& m, const std::vector<float>& weights,
                     Shading shading, DisplacementMode displacement) {
    FrameRequest req;
    req.model = m;
    req.world = worldMatrices(*m, sampleClip(*m, 0, 0.5f));
    req.morphWeights = weights;
    req.render.size = {192, 192};
    req.render.aa = AntiAliasing::None;
    req.render.shading = shading;
    req.render.displacement = displacement;
    req.render.displacementScale = 0.0; // framing from the bounds alone, same in both frames
    return req;
}

Image8 frame(Renderer& gl, const FrameRequest& req) {
    auto f = gl.renderFrame(req);
    EXPECT_TRUE(f) << (f ? "" : f.error().message);
    return f ? f->image : Image8{};
}

/// Pixels whose colour differs by more than 24 in a channel.
std::size_t differing(const Image8& a, const Image8& b) {
    std::size_t n = 0;
    for (std::size_t p = 0; p + 3 < a.rgba.size() && p + 3 < b.rgba.size(); p += 4)
        for (int c = 0; c < 3; ++c)
            if (std::abs(int(a.rgba[p + c]) - int(b.rgba[p + c])) > 24) {
                ++n;
                break;
            }
    return n;
}

/// Same picture up to float rounding: a stray edge pixel or two.
const ImageTolerance kSame{24, 0.002, 0.5};

} // namespace

TEST_F(MorphGLTest, GpuMorphingEqualsTheCpuReferenceOnAHandMadeFile) {
    expectGpuEqualsCpu(gl(), morphedTriangle(), {{}, {0.0f, 0.0f}, {1.0f, 1.0f}, {-0.5f, 2.0f}});
}

TEST_F(MorphGLTest, GpuMorphingEqualsTheCpuReferenceOnCesiumManOverItsClip) {
    expectGpuEqualsCpu(gl(), cesiumWithMorphs(), {{}, {0.7f, -0.4f}, {1.0f, 1.0f}});
}

TEST_F(MorphGLTest, AMorphedFrameIsTheFrameOfItsBakedVertices) {
    const auto model = cesiumWithMorphs();
    ASSERT_TRUE(model);
    const std::vector<float> w{0.8f, 1.0f};
    const auto flat = baked(*model, w);
    const auto plain = baked(*model, {0.0f, 0.0f});
    for (Shading shading : {Shading::Legacy, Shading::Pbr})
        for (DisplacementMode d : {DisplacementMode::Vertex, DisplacementMode::Tessellated}) {
            const std::string name = std::string("morph_") + std::string(toString(shading)) + "_" +
                                     (d == DisplacementMode::Vertex ? "vertex" : "tessellated");
            const Image8 morphed = frame(gl(), request(model, w, shading, d));
            const Image8 bakedFrame = frame(gl(), request(flat, {}, shading, d));
            EXPECT_TRUE(compareImages(morphed, bakedFrame, name, kSame));
            // Weight 0 is the model as loaded, and the targets do show.
            const Image8 zero = frame(gl(), request(model, {0.0f, 0.0f}, shading, d));
            const Image8 unmorphed = frame(gl(), request(plain, {}, shading, d));
            EXPECT_TRUE(compareImages(zero, unmorphed, name + "_zero", kSame));
            EXPECT_GT(differing(morphed, unmorphed), morphed.rgba.size() / 4 / 50) << name;
        }
}

TEST_F(MorphGLTest, LayoutPartsCarryTheirSourceVerticesDeltas) {
    const auto model = cesiumWithMorphs();
    ASSERT_TRUE(model);
    // The model's own UVs as a layout with every part's vertices in reverse order: the same
    // surface, drawn from buffers gathered through `source`.
    auto layout = std::make_shared<TextureLayout>(modelTextureLayout(*model));
    layout->kind = "generated";
    for (std::size_t k = 0; k < layout->parts.size(); ++k) {
        PartLayout& pl = layout->parts[k];
        const auto n = static_cast<std::uint32_t>(pl.source.size());
        PartLayout rev;
        for (std::uint32_t v = 0; v < n; ++v) {
            rev.source.push_back(pl.source[n - 1 - v]);
            rev.uvs.push_back(pl.uvs[n - 1 - v]);
        }
        for (std::uint32_t i : pl.indices) rev.indices.push_back(n - 1 - i);
        pl = std::move(rev);
    }
    const std::vector<float> w{1.0f, -1.0f};
    FrameRequest own = request(model, w, Shading::Legacy, DisplacementMode::Vertex);
    FrameRequest reordered = own;
    reordered.layout = layout;
    EXPECT_TRUE(compareImages(frame(gl(), reordered), frame(gl(), own), "morph_layout", kSame));
}
