// Twisting energy at one interior node (paper eqs. 4, 5c).
#pragma once

#include "stokesrods/common/types.h"

namespace stokesrods {

struct TwistingParams {
  double stiffness;   ///< GJ / Δl_i [N·m], Δl_i the rest Voronoi length of the node
  double rest_twist;  ///< τ̄ [rad], the twist of the rest shape
};

/// E = ½ (GJ/Δl) (τ − τ̄)², τ = θ1 − θ0 + m_ref  [J]  (paper eq. 4, 5c).
/// `reference_twist` is m_ref at the current configuration (see ReferenceTwist in rod/frames.h).
/// Local DOF order (x0, θ0, x1, θ1, x2). Derivatives include those of m_ref with respect to the
/// positions under time-parallel transport of the reference frames.
double TwistingEnergy(const TwistingParams& p, const Vec3& x0, const Vec3& x1, const Vec3& x2,
                      double theta0, double theta1, double reference_twist,
                      Vec11* gradient = nullptr, Mat11* hessian = nullptr);

}  // namespace stokesrods
