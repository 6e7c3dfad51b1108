// Twisting energy at one interior node (paper eqs. 4, 5c).
#pragma once

#include "stokesrods/common/types.h"
#include "stokesrods/elastic/curvature.h"

namespace stokesrods {

struct TwistingParams {
  double stiffness;   ///< GJ / Δl_i [N·m], Δl_i the rest Voronoi length of the node
  double rest_twist;  ///< τ̄ [rad], the twist of the rest shape
};

/// E = ½ (GJ/Δl) (τ − τ̄)², τ = θ1 − θ0 + m_ref  [J]  (paper eq. 4, 5c; the paper's 5c has no τ̄,
/// a naturally twisted rest shape needs it).
/// `reference_twist` is m_ref at the current configuration (see ReferenceTwist in rod/frames.h).
/// Local DOF order (x0, θ0, x1, θ1, x2). Derivatives include those of m_ref with respect to the
/// positions under time-parallel transport of the reference frames:
/// ∂m_ref/∂e0 = κb / (2|e0|), ∂m_ref/∂e1 = κb / (2|e1|) (κb of paper eq. 2).
/// As for BendingEnergy, hessian(i, k) = ∂gradient_i/∂q_k with the frames transported to q + dq:
/// not symmetric when τ ≠ τ̄; its symmetric part is the second derivative of E.
double TwistingEnergy(const TwistingParams& p, const Vec3& x0, const Vec3& x1, const Vec3& x2,
                      double theta0, double theta1, double reference_twist,
                      Vec11* gradient = nullptr, Mat11* hessian = nullptr);

/// The same in the edge variables y (curvature.h), on the node's shared curvature `c` (made with
/// derivatives when the gradient or its Jacobian is wanted).
double TwistingEdgeEnergy(const TwistingParams& p, const StencilCurvature& c, double theta0,
                          double theta1, double reference_twist, Vec8* gradient, Mat8* hessian);

}  // namespace stokesrods
