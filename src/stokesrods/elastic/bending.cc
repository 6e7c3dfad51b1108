#include "stokesrods/elastic/bending.h"

#include "stokesrods/common/assert.h"
#include "stokesrods/elastic/curvature.h"

namespace stokesrods {

namespace {

// One material curvature written as κ = ½ (u⁰ + u¹)·κb, with u^j a material director of edge j:
//   κ⁽¹⁾: u^j = m2^j,  u'^j = ∂u^j/∂θ_j = −m1^j;   κ⁽²⁾: u^j = −m1^j,  u'^j = −m2^j;
// in both cases ∂²u^j/∂θ_j² = −u^j.
struct MaterialPair {
  Vec3 u[2];
  Vec3 du[2];
};

// κ = ½ (u⁰ + u¹)·κb: its gradient G and the Jacobian ∂G/∂y in y = (e0, θ0, e1, θ1), the
// directors being carried by time-parallel transport when the edges move. κb and J = ∂κb/∂e are
// given (the same for both curvatures).
//
// Gradient. Transport moves u^j by δu^j = −(u^j·δt_j) t_j, normal to κb (κb ⊥ t0, t1), so to first
// order the frames do not contribute:  ∂κ/∂e = ½ Jᵀ (u⁰ + u¹),  ∂κ/∂θ_j = ½ u'^j·κb.
Vec8 MaterialCurvatureGradient(const Vec3& kb, const Mat36& jacobian, const MaterialPair& u) {
  Vec8 g;
  const Vec6 grad_e = 0.5 * jacobian.transpose() * (u.u[0] + u.u[1]);
  g.segment<3>(kEdge0) = grad_e.head<3>();
  g.segment<3>(kEdge1) = grad_e.tail<3>();
  g[kTheta0] = 0.5 * u.du[0].dot(kb);
  g[kTheta1] = 0.5 * u.du[1].dot(kb);
  return g;
}

// Jacobian of that gradient (frames transported again, as the residual of Newton is evaluated):
//   ∂G_e/∂e   = ½ Σ_k (u⁰ + u¹)_k ∂²κb_k/∂e² − Σ_j (½/l_j) Jᵀ t_j u^jᵀ   (columns of e_j),
//   ∂G_e/∂θ_j = ½ Jᵀ u'^j = (∂G_θj/∂e)ᵀ,   ∂G_θj/∂θ_j = −½ u^j·κb,   ∂G_θ0/∂θ1 = 0.
// The frame term −(½/l_j) Jᵀ t_j u^jᵀ = (½/l_j) (∂t_j/∂e)ᵀ κb u^jᵀ is not symmetric (the
// Jacobian of G is not a Hessian; see bending.h). Its symmetric part is the second derivative of κ
// with the frames transported from the unperturbed tangents. Every term is linear in the directors
// (u, u'), so Σ_a c_a ∂G_a/∂y is this Jacobian of the directors Σ_a c_a (u_a, u'_a): one evaluation
// serves both curvatures.
Mat8 MaterialCurvatureJacobian(const StencilCurvature& c, const MaterialPair& u) {
  const int edge_index[2] = {kEdge0, kEdge1};
  const int theta_index[2] = {kTheta0, kTheta1};
  const Vec3& kb = c.kb;
  const Mat36& jacobian = c.jacobian;
  Mat6 jac_e = 0.5 * CalcCurvatureBinormalHessian(c, u.u[0] + u.u[1]);
  for (int j = 0; j < 2; ++j) {
    jac_e.middleCols<3>(3 * j) -=
        (0.5 / c.length[j]) * (jacobian.transpose() * c.tangent[j]) * u.u[j].transpose();
  }
  Mat8 h = Mat8::Zero();
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b)
      h.block<3, 3>(edge_index[a], edge_index[b]) = jac_e.block<3, 3>(3 * a, 3 * b);
  for (int j = 0; j < 2; ++j) {
    const int th = theta_index[j];
    h(th, th) = -0.5 * u.u[j].dot(kb);
    const Vec6 mixed = 0.5 * jacobian.transpose() * u.du[j];
    for (int a = 0; a < 2; ++a) {
      h.block<3, 1>(edge_index[a], th) = mixed.segment<3>(3 * a);
      h.block<1, 3>(th, edge_index[a]) = mixed.segment<3>(3 * a).transpose();
    }
  }
  return h;
}

}  // namespace

Vec2 MaterialCurvatures(const Vec3& x0, const Vec3& x1, const Vec3& x2, const RefFrame& f0,
                        const RefFrame& f1, double theta0, double theta1) {
  Vec3 m1[2];
  Vec3 m2[2];
  MaterialFrame(f0, theta0, &m1[0], &m2[0]);
  MaterialFrame(f1, theta1, &m1[1], &m2[1]);
  const Vec3 kb = CalcCurvatureBinormal(x1 - x0, x2 - x1);
  return Vec2(0.5 * (m2[0] + m2[1]).dot(kb), -0.5 * (m1[0] + m1[1]).dot(kb));
}

double BendingEnergy(const BendingParams& p, const Vec3& x0, const Vec3& x1, const Vec3& x2,
                     const RefFrame& f0, const RefFrame& f1, double theta0, double theta1,
                     Vec11* gradient, Mat11* hessian) {
  const StencilCurvature c = CalcStencilCurvature(x1 - x0, x2 - x1, gradient || hessian);
  Vec8 g;
  Mat8 h;
  const double energy = BendingEdgeEnergy(p, c, f0, f1, theta0, theta1, gradient ? &g : nullptr,
                                          hessian ? &h : nullptr);
  if (gradient) *gradient = EdgeToStencilGradient(g);
  if (hessian) *hessian = EdgeToStencilHessian(h);
  return energy;
}

double BendingEdgeEnergy(const BendingParams& p, const StencilCurvature& c, const RefFrame& f0,
                         const RefFrame& f1, double theta0, double theta1, Vec8* gradient,
                         Mat8* hessian) {
  SR_ASSERT(p.stiffness >= 0.0, "bending: stiffness must be >= 0");
  Vec3 m1[2];
  Vec3 m2[2];
  MaterialFrame(f0, theta0, &m1[0], &m2[0]);
  MaterialFrame(f1, theta1, &m1[1], &m2[1]);
  // κ⁽¹⁾ = ½ (m2⁰ + m2¹)·κb,  κ⁽²⁾ = −½ (m1⁰ + m1¹)·κb  (paper eq. 3).
  const Vec3& kb = c.kb;
  const Vec2 excess =
      Vec2(0.5 * (m2[0] + m2[1]).dot(kb), -0.5 * (m1[0] + m1[1]).dot(kb)) - p.rest_curvature;
  const double energy = 0.5 * p.stiffness * excess.squaredNorm();
  if (!gradient && !hessian) return energy;
  SR_ASSERT(c.has_derivatives, "bending: the gradient needs the curvature's derivatives");
  const MaterialPair pairs[2] = {{{m2[0], m2[1]}, {-m1[0], -m1[1]}},
                                 {{-m1[0], -m1[1]}, {-m2[0], -m2[1]}}};
  // E = ½ k Σ_a Δκ_a²:  ∇E = k Σ_a Δκ_a ∇κ_a,  ∂(∇E)/∂q = k Σ_a (∇κ_a ∇κ_aᵀ + Δκ_a ∂(∇κ_a)/∂q),
  // the last sum one Jacobian of the directors weighted by c_a = k Δκ_a (see above).
  const Vec8 grad[2] = {MaterialCurvatureGradient(kb, c.jacobian, pairs[0]),
                        MaterialCurvatureGradient(kb, c.jacobian, pairs[1])};
  if (gradient) *gradient = p.stiffness * (excess[0] * grad[0] + excess[1] * grad[1]);
  if (hessian) {
    MaterialPair weighted;
    for (int j = 0; j < 2; ++j) {
      weighted.u[j] = p.stiffness * (excess[0] * pairs[0].u[j] + excess[1] * pairs[1].u[j]);
      weighted.du[j] = p.stiffness * (excess[0] * pairs[0].du[j] + excess[1] * pairs[1].du[j]);
    }
    *hessian = MaterialCurvatureJacobian(c, weighted);
    for (int a = 0; a < 2; ++a) hessian->noalias() += p.stiffness * grad[a] * grad[a].transpose();
  }
  return energy;
}

}  // namespace stokesrods
