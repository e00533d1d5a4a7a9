// Test helper — the deformation model for one value, composed from core/deform.hpp's pieces the
// way the CPU and GPU height passes compose them per placement (normalizedT, deformConstant,
// applyDeform). Tests use it as the reference form of paper eq. 1 and 2; the product does not.
#pragma once

#include "core/deform.hpp"

namespace dermis {

/// The drive parameters of one placement (the fields of a scene placement that eq. 1/2 use).
struct Drive {
    double thetaMin = 0.0;  ///< degrees: angle at which the pattern is absent (t = 0)
    double thetaMax = 90.0; ///< degrees: angle at which the pattern is full (t = 1); ≠ thetaMin
    double h = 1.0;         ///< gain, ≥ 0
    DeformModel model = DeformModel::Scale;
    Response response = Response::Log2;
};

/// L_out for one pattern value L at joint angle theta (degrees).
inline float deformHeight(const Drive& d, float L, double theta) {
    const double t = normalizedT(theta, d.thetaMin, d.thetaMax);
    return applyDeform(d.model, L, static_cast<float>(d.h), t,
                       deformConstant(d.model, d.response, t));
}

} // namespace dermis
