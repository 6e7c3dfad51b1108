#include "stokesrods/elastic/twisting.h"

#include "stokesrods/common/assert.h"
#include "stokesrods/elastic/curvature.h"

namespace stokesrods {

namespace {

// Gradient of the reference twist m_ref and its Jacobian in y = (e0, θ0, e1, θ1) (value left at 0).
//
// Gradient. Moving t1 to t1 + δt1 with d1¹ transported in time changes m_ref by the holonomy of the
// spherical triangle (t0, t1, t1 + δt1), i.e. by (t0 × t1)·δt1 / (1 + t0·t1) = ½ κb·δt1; moving t0
// likewise gives ½ κb·δt0. With δt = (I − t tᵀ) δe / |e| and κb ⊥ t0, t1:
//   ∂m_ref/∂e0 = κb / (2|e0|),   ∂m_ref/∂e1 = κb / (2|e1|),   ∂m_ref/∂θ = 0
// (Bergou et al. 2008, sec. 7; Jawed et al. 2018).
//
// Jacobian of that gradient (what the Newton residual sees when the frames are transported again):
//   ∂/∂e_j (κb / 2l_i) = (∂κb/∂e_j) / (2 l_i) − δ_ij κb t_iᵀ / (2 l_i²).
// The off-diagonal blocks are transposes of each other, but the diagonal blocks are not symmetric:
// their antisymmetric parts come from the holonomy of the spherical triangle
// (t_i, t_i + δt_i, t_i + δt_i + dt_i), ½ t_i·(δt_i × dt_i), which the re-based gradient sees. The
// symmetric part of the Jacobian is the second derivative of m_ref with the frames transported from
// the unperturbed tangents; the standard DER Hessian (Bergou et al. 2010; dismech) is that part.
// The Jacobian only `with_jacobian` (else left at 0).
EdgeDerivatives CalcReferenceTwistDerivatives(const StencilCurvature& c, bool with_jacobian) {
  const int edge_index[2] = {kEdge0, kEdge1};
  EdgeDerivatives m;
  Mat8& jac = m.hessian;
  for (int i = 0; i < 2; ++i) {
    const int row = edge_index[i];
    m.gradient.segment<3>(row) = c.kb / (2.0 * c.length[i]);
    if (!with_jacobian) continue;
    for (int j = 0; j < 2; ++j) {
      jac.block<3, 3>(row, edge_index[j]) = c.jacobian.middleCols<3>(3 * j) / (2.0 * c.length[i]);
    }
    jac.block<3, 3>(row, row) -= c.kb * c.tangent[i].transpose() / (2.0 * c.length[i] * c.length[i]);
  }
  return m;
}

}  // namespace

double TwistingEnergy(const TwistingParams& p, const Vec3& x0, const Vec3& x1, const Vec3& x2,
                      double theta0, double theta1, double reference_twist, Vec11* gradient,
                      Mat11* hessian) {
  const StencilCurvature c = CalcStencilCurvature(x1 - x0, x2 - x1, gradient || hessian);
  Vec8 g;
  Mat8 h;
  const double energy = TwistingEdgeEnergy(p, c, theta0, theta1, reference_twist,
                                           gradient ? &g : nullptr, hessian ? &h : nullptr);
  if (gradient) *gradient = EdgeToStencilGradient(g);
  if (hessian) *hessian = EdgeToStencilHessian(h);
  return energy;
}

double TwistingEdgeEnergy(const TwistingParams& p, const StencilCurvature& c, double theta0,
                          double theta1, double reference_twist, Vec8* gradient, Mat8* hessian) {
  SR_ASSERT(p.stiffness >= 0.0, "twisting: stiffness must be >= 0");
  // τ = θ1 − θ0 + m_ref (paper eq. 4);  E = ½ k (τ − τ̄)²,
  // ∇E = k Δτ ∇τ,  ∂(∇E)/∂q = k (∇τ ∇τᵀ + Δτ ∂(∇m_ref)/∂q)  (θ enters τ linearly).
  const double excess = theta1 - theta0 + reference_twist - p.rest_twist;
  const double energy = 0.5 * p.stiffness * excess * excess;
  if (!gradient && !hessian) return energy;
  SR_ASSERT(c.has_derivatives, "twisting: the gradient needs the curvature's derivatives");
  EdgeDerivatives tau = CalcReferenceTwistDerivatives(c, hessian != nullptr);
  tau.gradient[kTheta0] = -1.0;
  tau.gradient[kTheta1] = 1.0;
  if (gradient) *gradient = p.stiffness * excess * tau.gradient;
  if (hessian) *hessian = p.stiffness * (tau.gradient * tau.gradient.transpose() + excess * tau.hessian);
  return energy;
}

}  // namespace stokesrods
