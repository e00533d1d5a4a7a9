// TangentsGLTest — generated MikkTSpace tangents in pbr frames (core/tangents.hpp; the loader
// generates them for normal-mapped primitives without TANGENT), on the backend named by
// $DERMIS_TEST_GL:
//   * NormalTangentMirrorTest (mirrored UVs, TANGENT in the file) drawn with its file's tangents
//     and with tangents regenerated from scratch: the same picture;
//   * DamagedHelmet (a normal map, no TANGENT) drawn with its generated tangents and with the
//     per-pixel derivative frame used before: nearly the same picture (SSIM ≥ 0.97), not the
//     identical one (the vertex frame is in use).
#include "BuildPaths.hpp"
#include "ImageCompare.hpp"
#include "RendererSuite.hpp"

#include "core/image_similarity.hpp"
#include "core/rig.hpp"
#include "core/tangents.hpp"
#include "io/gltf_loader.hpp"

#include <gtest/gtest.h>

#include <iostream>

using namespace dermis;
using namespace dermis::test;

namespace {

const std::string kFidelity = std::string(dermis::build::testModelsDir()) + "/fidelity";

class TangentsGLTest : public RendererSuite {};

Model load(const std::string& rel) {
    auto m = loadGltfFile(kFidelity + rel);
    EXPECT_TRUE(m) << rel << ": " << (m ? "" : m.error().message);
    return m ? std::move(*m) : Model{};
}

Image8 pbrFrame(Renderer& gl, Model model) {
    auto shared = std::make_shared<const Model>(std::move(model));
    FrameRequest req;
    req.model = shared;
    req.world = worldMatrices(*shared, restPose(*shared));
    req.render.size = {256, 256};
    req.render.aa = AntiAliasing::None;
    req.render.shading = Shading::Pbr;
    req.render.camera.yaw = 20.0;
    req.render.camera.pitch = 10.0;
    auto f = gl.renderFrame(req);
    EXPECT_TRUE(f) << (f ? "" : f.error().message);
    return f ? f->image : Image8{};
}

} // namespace

TEST_F(TangentsGLTest, RegeneratedTangentsDrawTheFilesPicture) {
    Model file = load("/NormalTangentMirrorTest/NormalTangentMirrorTest.glb");
    ASSERT_FALSE(file.parts.empty());
    Model regenerated = file;
    for (MeshPart& p : regenerated.parts) {
        ASSERT_FALSE(p.tangents.empty());
        p.tangents.clear();
        ASSERT_TRUE(generateTangents(p));
    }
    const Image8 a = pbrFrame(gl(), std::move(file)), b = pbrFrame(gl(), std::move(regenerated));
    EXPECT_TRUE(compareImages(b, a, "tangents_mirror_regenerated", ImageTolerance{16, 0.001, 0.3}));
}

TEST_F(TangentsGLTest, TheHelmetsGeneratedTangentsShadeAsItsDerivativeFrameDid) {
    Model generated = load("/DamagedHelmet/DamagedHelmet.glb");
    ASSERT_EQ(generated.parts.size(), 1u);
    ASSERT_TRUE(generated.parts[0].tangentsGenerated);
    Model derivative = generated;
    derivative.parts[0].tangents.clear();
    derivative.parts[0].tangentsGenerated = false;
    const Image8 a = pbrFrame(gl(), std::move(generated)), b = pbrFrame(gl(), std::move(derivative));
    auto s = ssim(a, b);
    ASSERT_TRUE(s) << s.error().message;
    std::cout << "DamagedHelmet, generated tangents against the derivative frame: SSIM " << *s << "\n";
    EXPECT_GE(*s, 0.97);
    EXPECT_NE(a.rgba, b.rgba);
}
