// ProposeTest — SPEC §8 proposals from the range-of-motion analysis (core body_map, motion,
// propose) on the real characters: CesiumMan, the KayKit Barbarian, RiggedFigure and the default
// character. No GL, no HTTP.
#include "core/body_map.hpp"
#include "core/model_derived.hpp"
#include "core/motion.hpp"
#include "core/propose.hpp"
#include "io/gltf_loader.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <memory>
#include <string>

using namespace dermis;

namespace {

const std::string kSource = DERMIS_SOURCE_DIR;
const std::string kModels = std::string(DERMIS_SHARED_DIR) + "/models/";

std::shared_ptr<const Model> load(const std::string& path) {
    auto m = loadGltfFile(path);
    EXPECT_TRUE(m) << path << ": " << (m ? "" : m.error().message);
    return m ? std::make_shared<const Model>(std::move(*m)) : nullptr;
}

TEST(ProposeTest, Dump) {
    for (const std::string path : {kSource + "/models/default.glb", kModels + "CesiumMan/CesiumMan.glb",
                                   kModels + "KayKitBarbarian/Barbarian.glb", kModels + "RiggedFigure/RiggedFigure.glb"}) {
        auto model = load(path);
        ASSERT_TRUE(model);
        ModelDerived d(model);
        const BodyMap body = mapBody(*model, d.restSkin(), d.symmetryPlane());
        const MotionAnalysis motion = analyzeMotion(*model, d.restSkin(), body);
        std::printf("%s plane %d samples %zu\n", path.c_str(), d.symmetryPlane().axis, motion.samples.size());
        for (int j : model->joints) {
            const JointInfo* i = body.info(j);
            const JointMotion* m = motion.motion(j);
            const glm::dvec3 p = restJointPosition(d.restSkin(), j);
            std::printf("  %-28s %-16s side %c limb %d def %d pos %6.3f %6.3f %6.3f axis %5.2f %5.2f %5.2f lo %7.1f hi %7.1f n %6.1f pk %6.1f plan %.2f syn %d\n",
                        model->nodes[j].name.c_str(), describeJoint(*model, body, j).c_str(), i->side ? i->side : '-', i->limb,
                        i->deforms, p.x, p.y, p.z, m->axis.x, m->axis.y, m->axis.z, m->lo, m->hi, m->neutral, m->peak,
                        m->planarity, m->synthetic);
            if (m->synthetic) {
                JointMotion copy = *m;
                copy.synthetic = false;
                MotionAnalysis a2 = motion;
                a2.joints[j].synthetic = false;
                const JointMotion about = motionAbout(*model, a2, j, m->axis);
                std::printf("      clip range about synthetic axis: %.2f .. %.2f\n", about.lo, about.hi);
            }
        }
        const auto props = proposePatterns(*model, d.restSkin(), d.symmetryPlane(), body, motion);
        for (const Proposal& p : props)
            std::printf("    %-18s %-22s %-8s joint %-24s th %6.1f..%6.1f size %.3f x %.3f score %.2f comp %.3f str %.3f corr %.2f clip %s twin %s\n",
                        p.placement.id.c_str(), p.placement.label.c_str(), p.kind.c_str(), p.placement.joint.c_str(),
                        p.placement.thetaMin, p.placement.thetaMax, p.placement.size[0], p.placement.size[1], p.score,
                        p.why.compression, p.why.stretch, p.why.correlation, p.why.peakClip.c_str(), p.twin.c_str());
    }
}

} // namespace
