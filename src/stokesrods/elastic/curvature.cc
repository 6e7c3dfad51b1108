#include "stokesrods/elastic/curvature.h"

#include "stokesrods/common/assert.h"

namespace stokesrods {

namespace {

// The denominator D = |e0||e1| + e0·e1 of κb, with its gradient in (e0, e1).
struct Denominator {
  double value;
  Vec6 gradient;  // (|e1| t0 + e1, |e0| t1 + e0)
};

Denominator CalcDenominator(const Vec3& e0, const Vec3& e1) {
  const double l0 = e0.norm();
  const double l1 = e1.norm();
  Denominator d;
  d.value = l0 * l1 + e0.dot(e1);
  SR_DASSERT(d.value > 1e-14 * l0 * l1, "curvature binormal of anti-parallel edges");
  d.gradient << l1 * e0 / l0 + e1, l0 * e1 / l1 + e0;
  return d;
}

// Build the constant map y = M q from the stencil DOFs to the edge variables.
Eigen::Matrix<double, 8, 11> EdgeMap() {
  Eigen::Matrix<double, 8, 11> m = Eigen::Matrix<double, 8, 11>::Zero();
  m.block<3, 3>(kEdge0, 0) = -Mat3::Identity();  // e0 = x1 − x0
  m.block<3, 3>(kEdge0, 4) = Mat3::Identity();
  m(kTheta0, 3) = 1.0;
  m.block<3, 3>(kEdge1, 4) = -Mat3::Identity();  // e1 = x2 − x1
  m.block<3, 3>(kEdge1, 8) = Mat3::Identity();
  m(kTheta1, 7) = 1.0;
  return m;
}

}  // namespace

Mat3 CrossMatrix(const Vec3& a) {
  Mat3 m;
  m << 0.0, -a.z(), a.y(), a.z(), 0.0, -a.x(), -a.y(), a.x(), 0.0;
  return m;
}

Vec3 CalcCurvatureBinormal(const Vec3& e0, const Vec3& e1, Mat36* jacobian) {
  const Denominator d = CalcDenominator(e0, e1);
  const Vec3 kb = 2.0 * e0.cross(e1) / d.value;
  if (jacobian) {
    // κb = 2 n / D with n = e0 × e1, ∂n/∂e0 = −[e1]×, ∂n/∂e1 = [e0]×:
    //   ∂κb/∂e = (2 ∂n/∂e − κb ⊗ ∇D) / D.
    jacobian->leftCols<3>() = -2.0 * CrossMatrix(e1);
    jacobian->rightCols<3>() = 2.0 * CrossMatrix(e0);
    *jacobian -= kb * d.gradient.transpose();
    *jacobian /= d.value;
  }
  return kb;
}

Mat6 CalcCurvatureBinormalHessian(const Vec3& e0, const Vec3& e1, const Vec3& w) {
  // g = w·κb = 2 f / D with f = w·(e0 × e1) bilinear in (e0, e1):
  //   ∇f = (e1 × w, w × e0),   ∇²f = [[0, −[w]×], [[w]×, 0]],
  //   ∇²D = [[(l1/l0) P0, I + t0 t1ᵀ], [I + t1 t0ᵀ, (l0/l1) P1]],  P = I − t tᵀ,
  //   ∇²g = 2∇²f/D − 2(∇f ∇Dᵀ + ∇D ∇fᵀ)/D² + 4 f ∇D ∇Dᵀ/D³ − 2 f ∇²D/D².
  const double l0 = e0.norm();
  const double l1 = e1.norm();
  const Vec3 t0 = e0 / l0;
  const Vec3 t1 = e1 / l1;
  const Denominator d = CalcDenominator(e0, e1);
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
  const double D = d.value;
  const Mat6 mixed = grad_f * d.gradient.transpose();
  return 2.0 / D * hess_f - 2.0 / (D * D) * (mixed + mixed.transpose()) +
         4.0 * f / (D * D * D) * d.gradient * d.gradient.transpose() -
         2.0 * f / (D * D) * hess_d;
}

Vec11 EdgeToStencilGradient(const Vec8& g) {
  static const Eigen::Matrix<double, 8, 11> m = EdgeMap();
  return m.transpose() * g;
}

Mat11 EdgeToStencilHessian(const Mat8& h) {
  // Mᵀ h M with M = EdgeMap() applied by its ±1 pattern (e0 = x1 − x0, e1 = x2 − x1): a dense
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
