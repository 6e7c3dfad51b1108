// Regularized Stokeslets and Regularized Stokeslet Segments (Cortez 2018, J Comput Phys 375:783;
// paper eqs. 7–11, 14). Pure kernels: no rods, no DOF map, no viscosity (every matrix here is
// 8πμ times a mobility, so it is dimensionless when it maps force densities [N/m], and [1/m] when
// it maps point forces [N]).
//
// Point blob (paper eq. 7), r = x̂ − x, R² = |r|² + ε²:
//     8πμ u(x̂) = S_ε(r) f,   S_ε(r) = (1/R + ε²/R³) I + r rᵀ / R³.
// Segment x_a → x_b, L = |x_b − x_a|, x_α = x_a + α (x_b − x_a), force density linear in α,
// f_α = (1 − α) f_a + α f_b (paper eq. 8):
//     8πμ u(x̂) = L ∫₀¹ S_ε(x̂ − x_α) f_α dα = A_a f_a + A_b f_b.
// Paper eq. 14 gives A_a = 𝔸₁, A_b = 𝔸₂ with its r_i = x̂ − x_a and v_i = x_a − x_b.
#pragma once

#include "stokesrods/common/types.h"

namespace stokesrods {

/// The two 3×3 matrices of one segment: 8πμ u(x̂) = a f_a + b f_b   [–].
struct SegmentMobility {
  Mat3 a = Mat3::Zero();
  Mat3 b = Mat3::Zero();
};

/// S_ε(r) of paper eq. 7 [1/m]. Precondition ε > 0 or r ≠ 0.
Mat3 RegularizedStokesletMatrix(const Vec3& r, double regularization);

/// The singular Stokeslet (Oseen tensor times 8πμ): I/|r| + r rᵀ/|r|³ [1/m]. Precondition r ≠ 0.
Mat3 StokesletMatrix(const Vec3& r);

/// A_a, A_b of eq. 8 integrated exactly, for a segment x_a → x_b (L > 0) and blob size ε > 0 [m],
/// evaluated at `point` (anywhere, including on the segment and at its end points).
/// Near the segment (dist(x̂, segment)² + ε² < L²) the closed forms are written in the variable
/// t = α − α* centred on the projection α* of x̂ on the segment's line, in forms free of
/// cancellation; farther away the integrand is analytic in a Bernstein ellipse of parameter
/// ρ ≥ 2 + √5 and a 20-point Gauss–Legendre rule is exact to rounding (error ∝ ρ^−40 < 1e-25).
/// Relative error (Frobenius) below 1e-12 everywhere tested, worst 2.5e-13, the reference's own
/// noise level (tests/fluid/stokeslet_segment_test.cc).
/// With `tolerance` > 0 the far field may use fewer points: the fewest whose measured error
/// bound GaussRuleError(n, δ) is below `tolerance` relative to |A| (never more than the
/// round-off rule; the near closed forms are unchanged).
SegmentMobility StokesletSegment(const Vec3& xa, const Vec3& xb, double regularization,
                                 const Vec3& point, double tolerance = 0.0);

/// Bound on the relative error (Frobenius, of (A_a, A_b)) of the n-point Gauss–Legendre rule on
/// one segment at δ = √(d² + ε²)/L ≥ 1: twice the measured worst case e_n(δ) ≈ c_n δ^−(2n−1),
/// c_n ≈ 9.6e-3 · 13.5^−(n−2) (calibration in tests/fluid/mobility_operator_test.cc).
double GaussRuleError(int n, double delta);

/// A_a, A_b of eq. 8 by an n-point Gauss–Legendre rule (1 ≤ n ≤ 20): exact to rounding only far
/// from the segment (see StokesletSegment); the far field of the matrix-free mobility.
SegmentMobility StokesletSegmentGauss(const Vec3& xa, const Vec3& xb, double regularization,
                                      const Vec3& point, int n);

/// The smallest δ = √(d² + ε²)/L (never below 1, the closed forms' zone) from which an n-point
/// Gauss–Legendre rule is at least as accurate as StokesletSegment(…, tolerance) there: where
/// StokesletSegment would itself use n points or fewer. Infinity when no δ qualifies.
double GaussRuleMinDelta(int n, double tolerance);

/// Nodes (on [0, 1]) and weights (summing to 1) of the n-point Gauss–Legendre rule, 1 ≤ n ≤ 20.
void GaussLegendreRule01(int n, const double** nodes, const double** weights);

/// Reference for the tests: eq. 8 by adaptive Gauss–Kronrod (7, 15) quadrature, bisecting until
/// the Kronrod–Gauss difference of every interval is below `relative_tolerance` × |A| (Frobenius)
/// × the interval's length. The interval is first split at the projection α* of x̂.
/// Slow: one call may cost thousands of kernel evaluations.
SegmentMobility StokesletSegmentByQuadrature(const Vec3& xa, const Vec3& xb, double regularization,
                                             const Vec3& point, double relative_tolerance = 1e-14);

}  // namespace stokesrods
