// glTF animations → Model::clips for the converter (gltf_convert.cpp): channels on a node's
// translation, rotation, scale and morph weights (glTF 2.0 §3.11), their samplers' keys checked.
#include "gltf_internal.hpp"

#include <algorithm>
#include <cmath>

namespace dermis::gltf_detail {

Status convertAnimations(const tg::Model& g, Model& m, const MorphSlots& morphSlots) {
    for (std::size_t a = 0; a < g.animations.size(); ++a) {
        const tg::Animation& anim = g.animations[a];
        const std::string field = "/animations/" + str(a);
        Clip clip;
        clip.name = anim.name.empty() ? "animation" + str(a) : anim.name;
        for (std::size_t c = 0; c < anim.channels.size(); ++c) {
            const tg::AnimationChannel& ch = anim.channels[c];
            const std::string cfield = field + "/channels/" + str(c);
            ChannelPath path;
            if (ch.target_path == "translation")
                path = ChannelPath::Translation;
            else if (ch.target_path == "rotation")
                path = ChannelPath::Rotation;
            else if (ch.target_path == "scale")
                path = ChannelPath::Scale;
            else if (ch.target_path == "weights")
                path = ChannelPath::Weights;
            else
                continue; // extension paths (KHR_animation_pointer): not loaded
            if (ch.target_node < 0) continue; // targeted by an extension only
            if (static_cast<std::size_t>(ch.target_node) >= m.nodes.size())
                return parseError(cfield + "/target/node",
                                  "node " + str(ch.target_node) + " does not exist");
            Channel out;
            out.node = ch.target_node;
            out.path = path;
            if (path == ChannelPath::Weights) {
                // The node's morph weights; a node whose mesh has no targets, or is not in the
                // default scene, moves nothing.
                const auto slots = morphSlots.find(ch.target_node);
                if (slots == morphSlots.end()) continue;
                out.morphFirst = slots->second.first;
                out.morphCount = slots->second.second;
            }
            if (ch.sampler < 0 || static_cast<std::size_t>(ch.sampler) >= anim.samplers.size())
                return parseError(cfield + "/sampler",
                                  "sampler " + str(ch.sampler) + " does not exist");
            const tg::AnimationSampler& smp = anim.samplers[static_cast<std::size_t>(ch.sampler)];
            const std::string sfield = field + "/samplers/" + str(ch.sampler);
            if (smp.interpolation == "LINEAR" || smp.interpolation.empty())
                out.interpolation = Interpolation::Linear;
            else if (smp.interpolation == "STEP")
                out.interpolation = Interpolation::Step;
            else if (smp.interpolation == "CUBICSPLINE")
                out.interpolation = Interpolation::CubicSpline;
            else
                return makeError(ErrorCode::Unsupported, kWhere, sfield + "/interpolation",
                                 "unknown interpolation '" + smp.interpolation + "'");

            auto in = readAccessor(g, smp.input, TINYGLTF_TYPE_SCALAR, Want::Float,
                                   {TINYGLTF_COMPONENT_TYPE_FLOAT}, sfield + "/input");
            if (!in) return in.error();
            if (in->count == 0) return parseError(sfield + "/input", "no keys");
            out.times.resize(in->count);
            for (std::size_t k = 0; k < in->count; ++k) {
                const double t = in->values[k];
                if (!std::isfinite(t) || !std::isfinite(static_cast<float>(t)))
                    return parseError(sfield + "/input", "non-finite key time");
                out.times[k] = static_cast<float>(t);
                if (k > 0 && !(out.times[k] > out.times[k - 1]))
                    return parseError(sfield + "/input",
                                      "key times must be strictly increasing (key " + str(k) + ")");
            }
            const int type = path == ChannelPath::Rotation ? TINYGLTF_TYPE_VEC4
                             : path == ChannelPath::Weights ? TINYGLTF_TYPE_SCALAR
                                                            : TINYGLTF_TYPE_VEC3;
            auto values = readAccessor(g, smp.output, type, Want::Float, {}, sfield + "/output");
            if (!values) return values.error();
            // Per key: one value (three for CUBICSPLINE) of 1 element, or of one scalar per
            // morph target (glTF 2.0 §3.11: the weights' output holds count × targets scalars).
            const std::size_t perKey = (out.interpolation == Interpolation::CubicSpline ? 3 : 1) *
                                       (path == ChannelPath::Weights
                                            ? static_cast<std::size_t>(out.morphCount)
                                            : 1);
            if (values->count != in->count * perKey)
                return parseError(sfield + "/output",
                                  str(values->count) + " values for " + str(in->count) +
                                      " keys (" + smp.interpolation +
                                      (path == ChannelPath::Weights
                                           ? ", " + str(out.morphCount) + " morph targets)"
                                           : ")"));
            out.values.resize(values->values.size());
            for (std::size_t k = 0; k < values->values.size(); ++k) {
                out.values[k] = static_cast<float>(values->values[k]);
                if (!std::isfinite(out.values[k]))
                    return parseError(sfield + "/output", "non-finite value");
            }
            clip.duration = std::max(clip.duration, out.times.back());
            clip.channels.push_back(std::move(out));
        }
        m.clips.push_back(std::move(clip));
    }
    return Ok{};
}

} // namespace dermis::gltf_detail
