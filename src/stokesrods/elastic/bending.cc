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

// κ = ½ (u⁰ + u¹)·κb with its gradient G and the Jacobian ∂G/∂y in y = (e0, θ0, e1, θ1), the
// directors being carried by time-parallel transport when the edges move.
//
// Gradient. Transport moves u^j by δu^j = −(u^j·δt_j) t_j, normal to κb (κb ⊥ t0, t1), so to first
// order the frames do not contribute:  ∂κ/∂e = ½ Jᵀ (u⁰ + u¹),  ∂κ/∂θ_j = ½ u'^j·κb,  J = ∂κb/∂e.
//
// Jacobian of that gradient (frames transported again, as the residual of Newton is evaluated):
//   ∂G_e/∂e   = ½ Σ_k (u⁰ + u¹)_k ∂²κb_k/∂e² − Σ_j (½/l_j) Jᵀ t_j u^jᵀ   (columns of e_j),
//   ∂G_e/∂θ_j = ½ Jᵀ u'^j = (∂G_θj/∂e)ᵀ,   ∂G_θj/∂θ_j = −½ u^j·κb,   ∂G_θ0/∂θ1 = 0.
// The frame term −(½/l_j) Jᵀ t_j u^jᵀ = (½/l_j) (∂t_j/∂e)ᵀ κb u^jᵀ is not symmetric (the
// Jacobian of G is not a Hessian; see bending.h). Its symmetric part is the second derivative of κ
// with the frames transported from the unperturbed tangents.
EdgeDerivatives CalcMaterialCurvature(const Vec3& e0, const Vec3& e1, const MaterialPair& u) {
  Mat36 jacobian;
  const Vec3 kb = CalcCurvatureBinormal(e0, e1, &jacobian);
  const Vec3 sum = u.u[0] + u.u[1];
  const int edge_index[2] = {kEdge0, kEdge1};
  const int theta_index[2] = {kTheta0, kTheta1};
  const Vec3 edges[2] = {e0, e1};

  EdgeDerivatives k;
  k.value = 0.5 * sum.dot(kb);
  const Vec6 grad_e = 0.5 * jacobian.transpose() * sum;
  Mat6 jac_e = 0.5 * CalcCurvatureBinormalHessian(e0, e1, sum);
  for (int j = 0; j < 2; ++j) {
    const double l = edges[j].norm();
    const Vec3 t = edges[j] / l;
    jac_e.middleCols<3>(3 * j) -= (0.5 / l) * (jacobian.transpose() * t) * u.u[j].transpose();
  }

  for (int a = 0; a < 2; ++a) {
    k.gradient.segment<3>(edge_index[a]) = grad_e.segment<3>(3 * a);
    for (int b = 0; b < 2; ++b) {
      k.hessian.block<3, 3>(edge_index[a], edge_index[b]) = jac_e.block<3, 3>(3 * a, 3 * b);
    }
  }
  for (int j = 0; j < 2; ++j) {
    const int th = theta_index[j];
    k.gradient[th] = 0.5 * u.du[j].dot(kb);
    k.hessian(th, th) = -0.5 * u.u[j].dot(kb);
    const Vec6 mixed = 0.5 * jacobian.transpose() * u.du[j];
    for (int a = 0; a < 2; ++a) {
      k.hessian.block<3, 1>(edge_index[a], th) = mixed.segment<3>(3 * a);
      k.hessian.block<1, 3>(th, edge_index[a]) = mixed.segment<3>(3 * a).transpose();
    }
  }
  return k;
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
  SR_ASSERT(p.stiffness >= 0.0, "bending: stiffness must be >= 0");
  const Vec3 e0 = x1 - x0;
  const Vec3 e1 = x2 - x1;
  Vec3 m1[2];
  Vec3 m2[2];
  MaterialFrame(f0, theta0, &m1[0], &m2[0]);
  MaterialFrame(f1, theta1, &m1[1], &m2[1]);
  // κ⁽¹⁾ = ½ (m2⁰ + m2¹)·κb,  κ⁽²⁾ = −½ (m1⁰ + m1¹)·κb  (paper eq. 3).
  const Vec3 kb = CalcCurvatureBinormal(e0, e1);
  const Vec2 excess =
      Vec2(0.5 * (m2[0] + m2[1]).dot(kb), -0.5 * (m1[0] + m1[1]).dot(kb)) - p.rest_curvature;
  const double energy = 0.5 * p.stiffness * excess.squaredNorm();
  if (!gradient && !hessian) return energy;
  const MaterialPair pairs[2] = {{{m2[0], m2[1]}, {-m1[0], -m1[1]}},
                                 {{-m1[0], -m1[1]}, {-m2[0], -m2[1]}}};
  // E = ½ k Σ_a Δκ_a²:  ∇E = k Σ_a Δκ_a ∇κ_a,  ∂(∇E)/∂q = k Σ_a (∇κ_a ∇κ_aᵀ + Δκ_a ∂(∇κ_a)/∂q).
  Vec8 g = Vec8::Zero();
  Mat8 h = Mat8::Zero();
  for (int a = 0; a < 2; ++a) {
    const EdgeDerivatives k = CalcMaterialCurvature(e0, e1, pairs[a]);
    g += p.stiffness * excess[a] * k.gradient;
    h += p.stiffness * (k.gradient * k.gradient.transpose() + excess[a] * k.hessian);
  }
  if (gradient) *gradient = EdgeToStencilGradient(g);
  if (hessian) *hessian = EdgeToStencilHessian(h);
  return energy;
}

}  // namespace stokesrods
