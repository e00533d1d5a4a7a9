#include "deform.hpp"

#include <algorithm>
#include <cmath>

namespace dermis {

std::string_view toString(DeformModel m) { return m == DeformModel::Scale ? "scale" : "bias"; }

std::string_view toString(Response r) {
    switch (r) {
    case Response::Log2: return "log2";
    case Response::Ln: return "ln";
    case Response::Linear: return "linear";
    case Response::Smoothstep: return "smoothstep";
    }
    return "log2";
}

std::string_view toString(Target t) { return t == Target::Bump ? "bump" : "displacement"; }

std::string_view toString(PatternKind k) {
    switch (k) {
    case PatternKind::Wrinkle: return "wrinkle";
    case PatternKind::Bulge: return "bulge";
    case PatternKind::Bone: return "bone";
    }
    return "wrinkle";
}

std::optional<DeformModel> deformModelFromString(std::string_view s) {
    if (s == "scale") return DeformModel::Scale;
    if (s == "bias") return DeformModel::Bias;
    return std::nullopt;
}

std::optional<Response> responseFromString(std::string_view s) {
    if (s == "log2") return Response::Log2;
    if (s == "ln") return Response::Ln;
    if (s == "linear") return Response::Linear;
    if (s == "smoothstep") return Response::Smoothstep;
    return std::nullopt;
}

std::optional<Target> targetFromString(std::string_view s) {
    if (s == "bump") return Target::Bump;
    if (s == "displacement") return Target::Displacement;
    return std::nullopt;
}

std::optional<PatternKind> patternKindFromString(std::string_view s) {
    if (s == "wrinkle") return PatternKind::Wrinkle;
    if (s == "bulge") return PatternKind::Bulge;
    if (s == "bone") return PatternKind::Bone;
    return std::nullopt;
}

DeformModel defaultModel(PatternKind k) {
    return k == PatternKind::Bone ? DeformModel::Bias : DeformModel::Scale;
}

Target defaultTarget(PatternKind k) {
    return k == PatternKind::Bulge ? Target::Displacement : Target::Bump;
}

double normalizedT(double theta, double thetaMin, double thetaMax) {
    double t = (theta - thetaMin) / (thetaMax - thetaMin);
    return std::clamp(t, 0.0, 1.0);
}

double responseGain(Response r, double t) {
    switch (r) {
    case Response::Log2: return std::log2(1.0 + t);
    case Response::Ln: return std::log(1.0 + t);
    case Response::Linear: return t;
    case Response::Smoothstep: return t * t * (3.0 - 2.0 * t);
    }
    return t;
}

double responseOffset(Response r, double t) {
    switch (r) {
    case Response::Log2: return std::log2(2.0 - t);
    case Response::Ln: return std::log(2.0 - t);
    case Response::Linear: return 1.0 - t;
    case Response::Smoothstep: return 1.0 - t * t * (3.0 - 2.0 * t);
    }
    return 1.0 - t;
}

float deformConstant(DeformModel m, Response r, double t) {
    return static_cast<float>(m == DeformModel::Scale ? responseGain(r, t) : responseOffset(r, t));
}

} // namespace dermis
