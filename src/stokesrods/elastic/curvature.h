// Pieces shared by the bending and twisting kernels: the curvature binormal (paper eq. 2) with its
// first and second derivatives, and the map between edge variables and the local stencil DOFs.
//
// Both kernels are written in the 8 "edge variables" y = (e0[3], θ0, e1[3], θ1), with
// e0 = x1 − x0 and e1 = x2 − x1, and mapped at the end to the 11 local DOFs
// q = (x0[3], θ0, x1[3], θ1, x2[3]) by the constant linear map y = M q.
#pragma once

#include <Eigen/Geometry>  // cross products (types.h brings only Eigen/Core)

#include "stokesrods/common/types.h"

namespace stokesrods {

using Vec8 = Vec<8>;
using Mat8 = Mat<8>;
using Mat36 = Eigen::Matrix<double, 3, 6>;

/// Index of e0, θ0, e1, θ1 in the edge variables y.
inline constexpr int kEdge0 = 0;
inline constexpr int kTheta0 = 3;
inline constexpr int kEdge1 = 4;
inline constexpr int kTheta1 = 7;

/// A scalar of the stencil with its gradient in the edge variables y and the Jacobian of that
/// gradient, hessian(i, k) = ∂gradient_i/∂y_k, taken with the reference frames transported in time
/// (not symmetric in general: see bending.h).
struct EdgeDerivatives {
  double value = 0.0;
  Vec8 gradient = Vec8::Zero();
  Mat8 hessian = Mat8::Zero();
};

/// Curvature binormal κb = 2 e0 × e1 / (|e0||e1| + e0·e1)   [dimensionless]  (paper eq. 2),
/// |κb| = 2 tan(φ/2) with φ the turning angle. Precondition: the edges are not anti-parallel.
/// If `jacobian` is given, it receives ∂κb/∂(e0, e1) (3 × 6) [1/m].
Vec3 CalcCurvatureBinormal(const Vec3& e0, const Vec3& e1, Mat36* jacobian = nullptr);

/// What the bending and twisting kernels of one node share: the edges, κb and, when made with
/// derivatives, ∂κb/∂(e0, e1), the edges' lengths and tangents and the denominator
/// D = |e0||e1| + e0·e1 of κb with its gradient (computed once per node, not once per kernel).
struct StencilCurvature {
  Vec3 e0, e1;
  Vec3 kb;
  bool has_derivatives = false;
  Mat36 jacobian;        ///< ∂κb/∂(e0, e1) [1/m]
  double length[2];      ///< |e0|, |e1|
  Vec3 tangent[2];       ///< e0/|e0|, e1/|e1|
  double denominator;    ///< D
  Vec6 denominator_gradient;  ///< ∂D/∂(e0, e1) = (|e1| t0 + e1, |e0| t1 + e0)
};
StencilCurvature CalcStencilCurvature(const Vec3& e0, const Vec3& e1, bool with_derivatives);

/// Σ_k w_k ∂²(κb)_k / ∂(e0, e1)²  (6 × 6, symmetric) [|w|/m²]: the Hessian of w·κb for a fixed
/// vector w.
Mat6 CalcCurvatureBinormalHessian(const Vec3& e0, const Vec3& e1, const Vec3& w);
/// The same on a curvature made with derivatives.
Mat6 CalcCurvatureBinormalHessian(const StencilCurvature& c, const Vec3& w);

/// Gradient with respect to the stencil DOFs q (x0, θ0, x1, θ1, x2): Mᵀ g.
Vec11 EdgeToStencilGradient(const Vec8& g);

/// Hessian (or gradient Jacobian) with respect to the stencil DOFs q: Mᵀ H M.
Mat11 EdgeToStencilHessian(const Mat8& h);

}  // namespace stokesrods
