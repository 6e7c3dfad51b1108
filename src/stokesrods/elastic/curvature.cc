#include "stokesrods/elastic/curvature.h"

#include "stokesrods/common/assert.h"

namespace stokesrods {

StencilCurvature CalcStencilCurvature(const Vec3& e0, const Vec3& e1, bool with_derivatives) {
  StencilCurvature c;
  c.e0 = e0;
  c.e1 = e1;
  c.has_derivatives = with_derivatives;
  const double l0 = e0.norm();
  const double l1 = e1.norm();
  c.length[0] = l0;
  c.length[1] = l1;
  c.denominator = l0 * l1 + e0.dot(e1);
  SR_DASSERT(c.denominator > 1e-14 * l0 * l1, "curvature binormal of anti-parallel edges");
  const Vec3 n = e0.cross(e1);
  c.kb = (2.0 / c.denominator) * n;
  if (!with_derivatives) return c;
  c.tangent[0] = e0 / l0;
  c.tangent[1] = e1 / l1;
  c.denominator_gradient << l1 * c.tangent[0] + e1, l0 * c.tangent[1] + e0;
  // κb = 2 n / D with n = e0 × e1, ∂n/∂e0 = −[e1]×, ∂n/∂e1 = [e0]×:
  //   ∂κb/∂e = (2 ∂n/∂e − κb ⊗ ∇D) / D.
  c.jacobian.leftCols<3>() = -2.0 * CrossMatrix(e1);
  c.jacobian.rightCols<3>() = 2.0 * CrossMatrix(e0);
  c.jacobian -= c.kb * c.denominator_gradient.transpose();
  c.jacobian /= c.denominator;
  return c;
}

Vec3 CalcCurvatureBinormal(const Vec3& e0, const Vec3& e1, Mat36* jacobian) {
  const StencilCurvature c = CalcStencilCurvature(e0, e1, jacobian != nullptr);
  if (jacobian) *jacobian = c.jacobian;
  return c.kb;
}

Mat6 CalcCurvatureBinormalHessian(const Vec3& e0, const Vec3& e1, const Vec3& w) {
  return CalcCurvatureBinormalHessian(CalcStencilCurvature(e0, e1, true), w);
}

Mat6 CalcCurvatureBinormalHessian(const StencilCurvature& c, const Vec3& w) {
  // g = w·κb = 2 f / D with f = w·(e0 × e1) bilinear in (e0, e1):
  //   ∇f = (e1 × w, w × e0),   ∇²f = [[0, −[w]×], [[w]×, 0]],
  //   ∇²D = [[(l1/l0) P0, I + t0 t1ᵀ], [I + t1 t0ᵀ, (l0/l1) P1]],  P = I − t tᵀ,
  //   ∇²g = 2∇²f/D − 2(∇f ∇Dᵀ + ∇D ∇fᵀ)/D² + 4 f ∇D ∇Dᵀ/D³ − 2 f ∇²D/D².
  SR_DASSERT(c.has_derivatives, "the curvature's Hessian needs its derivatives");
  const Vec3& e0 = c.e0;
  const Vec3& e1 = c.e1;
  const double l0 = c.length[0], l1 = c.length[1];
  const Vec3& t0 = c.tangent[0];
  const Vec3& t1 = c.tangent[1];
  const double f = w.dot(e0.cross(e1));
  Vec6 grad_f;
  grad_f << e1.cross(w), w.cross(e0);
  Mat6 hess_f = Mat6::Zero();
  hess_f.topRightCorner<3, 3>() = -CrossMatrix(w);
  hess_f.bottomLeftCorner<3, 3>() = CrossMatrix(w);
  const Mat3 identity = Mat3::Identity();
  Mat6 hess_d;
  hess_d.topLeftCorner<3, 3>() = (l1 / l0) * (identity - t0 * t0.transpose());
  hess_d.topRightCorner<3, 3>() = identity + t0 * t1.transpose();
  hess_d.bottomLeftCorner<3, 3>() = identity + t1 * t0.transpose();
  hess_d.bottomRightCorner<3, 3>() = (l0 / l1) * (identity - t1 * t1.transpose());
  const double D = c.denominator;
  const Mat6 mixed = grad_f * c.denominator_gradient.transpose();
  return 2.0 / D * hess_f - 2.0 / (D * D) * (mixed + mixed.transpose()) +
         4.0 * f / (D * D * D) * c.denominator_gradient * c.denominator_gradient.transpose() -
         2.0 * f / (D * D) * hess_d;
}

Vec11 EdgeToStencilGradient(const Vec8& g) {
  // Mᵀ g with M the map y = M q from the stencil DOFs to the edge variables
  // (e0 = x1 − x0, θ0, e1 = x2 − x1, θ1), by its ±1 pattern (as a product Eigen takes the general GEMV path at
  // this size: 6 % of the elastic assembly).
  Vec11 out;
  out.segment<3>(0) = -g.segment<3>(kEdge0);
  out[3] = g[kTheta0];
  out.segment<3>(4) = g.segment<3>(kEdge0) - g.segment<3>(kEdge1);
  out[7] = g[kTheta1];
  out.segment<3>(8) = g.segment<3>(kEdge1);
  return out;
}

Mat11 EdgeToStencilHessian(const Mat8& h) {
  // Mᵀ h M with M as in EdgeToStencilGradient, applied by its ±1 pattern: a dense
  // product costs 4× the arithmetic and, at these sizes, goes through Eigen's GEMM.
  Eigen::Matrix<double, 8, 11> a;  // h M
  a.middleCols<3>(0) = -h.middleCols<3>(kEdge0);
  a.col(3) = h.col(kTheta0);
  a.middleCols<3>(4) = h.middleCols<3>(kEdge0) - h.middleCols<3>(kEdge1);
  a.col(7) = h.col(kTheta1);
  a.middleCols<3>(8) = h.middleCols<3>(kEdge1);
  Mat11 out;  // Mᵀ (h M)
  out.middleRows<3>(0) = -a.middleRows<3>(kEdge0);
  out.row(3) = a.row(kTheta0);
  out.middleRows<3>(4) = a.middleRows<3>(kEdge0) - a.middleRows<3>(kEdge1);
  out.row(7) = a.row(kTheta1);
  out.middleRows<3>(8) = a.middleRows<3>(kEdge1);
  return out;
}

}  // namespace stokesrods
