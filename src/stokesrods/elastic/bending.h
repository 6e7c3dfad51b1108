// Bending energy at one interior node (paper eqs. 2, 3, 5b).
#pragma once

#include "stokesrods/common/types.h"
#include "stokesrods/elastic/curvature.h"
#include "stokesrods/rod/frames.h"

namespace stokesrods {

struct BendingParams {
  double stiffness;     ///< EI / Δl_i [N·m], Δl_i the rest Voronoi length of the node
  Vec2 rest_curvature;  ///< (κ̄⁽¹⁾, κ̄⁽²⁾) of the rest shape [dimensionless, as κb is]
};

/// Material curvatures (κ⁽¹⁾, κ⁽²⁾) at the node x1 between edges e0 = x1 − x0 and e1 = x2 − x1
/// with reference frames f0, f1 (already transported to the current tangents) and twist angles
/// θ0, θ1 (paper eq. 3):  κ⁽¹⁾ = ½ (m2⁰ + m2¹)·κb,  κ⁽²⁾ = −½ (m1⁰ + m1¹)·κb  [dimensionless],
/// κb the curvature binormal of eq. 2 (elastic/curvature.h).
Vec2 MaterialCurvatures(const Vec3& x0, const Vec3& x1, const Vec3& x2, const RefFrame& f0,
                        const RefFrame& f1, double theta0, double theta1);

/// E = ½ (EI/Δl) [(κ⁽¹⁾ − κ̄⁽¹⁾)² + (κ⁽²⁾ − κ̄⁽²⁾)²]  [J]  (paper eq. 5b; stiffness = EI/Δl).
/// Local DOF order (x0, θ0, x1, θ1, x2): 11 values. Preconditions: f0, f1 orthonormal and attached
/// to the current tangents; the edges not anti-parallel.
///
/// gradient = ∂E/∂q [N or N·m], exact with the reference frames carried by time-parallel transport
/// from f0, f1 when q moves.
/// hessian(i, k) = ∂gradient_i/∂q_k [N/m, N, N·m], the gradient re-evaluated at q + dq with the
/// frames transported to it: the exact Jacobian of the elastic force as the Newton residual computes
/// it. It is NOT symmetric away from the rest curvature: the transported frames pick up the holonomy
/// of the tangents' motion. Its symmetric part is the second derivative of E with the frames
/// transported from the current configuration (the Hessian of standard DER codes); symmetrize it
/// yourself if a symmetric matrix is needed. Both are checked by finite differences in the tests.
double BendingEnergy(const BendingParams& p, const Vec3& x0, const Vec3& x1, const Vec3& x2,
                     const RefFrame& f0, const RefFrame& f1, double theta0, double theta1,
                     Vec11* gradient = nullptr, Mat11* hessian = nullptr);

/// The same in the edge variables y (curvature.h), on the node's shared curvature `c` (made with
/// derivatives when the gradient or its Jacobian is wanted): what the rod's assembly adds to the
/// twisting's before mapping both to the stencil once.
double BendingEdgeEnergy(const BendingParams& p, const StencilCurvature& c, const RefFrame& f0,
                         const RefFrame& f1, double theta0, double theta1, Vec8* gradient,
                         Mat8* hessian);

}  // namespace stokesrods
