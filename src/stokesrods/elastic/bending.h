// Bending energy at one interior node (paper eqs. 2, 3, 5b).
#pragma once

#include "stokesrods/common/types.h"
#include "stokesrods/rod/frames.h"

namespace stokesrods {

struct BendingParams {
  double stiffness;     ///< EI / Δl_i [N·m], Δl_i the rest Voronoi length of the node
  Vec2 rest_curvature;  ///< (κ̄⁽¹⁾, κ̄⁽²⁾) of the rest shape [dimensionless, as κb is]
};

/// Material curvatures (κ⁽¹⁾, κ⁽²⁾) at the node x1 between edges e0 = x1 − x0 and e1 = x2 − x1
/// with reference frames f0, f1 (already transported to the current tangents) and twist angles
/// θ0, θ1 (paper eq. 3).
Vec2 MaterialCurvatures(const Vec3& x0, const Vec3& x1, const Vec3& x2, const RefFrame& f0,
                        const RefFrame& f1, double theta0, double theta1);

/// E = ½ (EI/Δl) [(κ⁽¹⁾ − κ̄⁽¹⁾)² + (κ⁽²⁾ − κ̄⁽²⁾)²]  [J].
/// Local DOF order (x0, θ0, x1, θ1, x2): 11 values. The derivatives are those of the energy with
/// the reference frames carried by time-parallel transport from f0, f1 (so they are exact at the
/// current configuration, as Newton needs).
double BendingEnergy(const BendingParams& p, const Vec3& x0, const Vec3& x1, const Vec3& x2,
                     const RefFrame& f0, const RefFrame& f1, double theta0, double theta1,
                     Vec11* gradient = nullptr, Mat11* hessian = nullptr);

}  // namespace stokesrods
