// Closed forms of the Regularized Stokeslet Segment (paper eqs. 8–11, 14), in a stable rewrite.
//
// Why not eqs. 11a–f as printed. They are correct (with v = x_a − x_b, r_0 = x̂ − x_a and
// T_{k,l} = ∫₀¹ α^k R_α^l dα), but evaluated literally they lose digits in three places:
//   (1) log[Δl R_α + r_α·v] and 1/(R_α[Δl R_α + r_α·v]) when r_α is nearly antiparallel to v
//       (x̂ on or near the segment's line beyond x_b, or on the segment itself): Δl R + r·v ≈ 0;
//   (2) the recurrences 11c–f subtract terms of size (r_0·v)/Δl² T ≈ |r_0|/Δl · T: far along the
//       line the result is (Δl/|r_0|) times smaller than each term, and the loss compounds through
//       the chain 11c → 11f. Measured with the printed forms (tests/fluid/stokeslet_segment_test):
//       relative error 1e-8…4e-4 on the line at |r_0| = 100 Δl, O(1) to 1e+10 at 1e4…1e6 Δl,
//       1e-8…1e-7 off the line at 3e3…1e4 Δl, 6.5e-6 on the line 2Δl beyond x_b with ε = 1e-4 Δl;
//   (3) eq. 14 sums T r rᵀ + T (r vᵀ + v rᵀ) + T v vᵀ with r = x̂ − x_a: at a collocation node the
//       sum ∫ α(1 − α)² v vᵀ/R³ is small while each term is ~1/(Δl ε²), so the v vᵀ part loses
//       ~(Δl/ε)² ulps (below 1e-8 of |A| for ε ≥ 1e-4 Δl, but avoidable).
// The rewrite: split r_α = r⊥ − t v with t = α − α* (α* the projection of x̂ on the line, r⊥ ⟂ v,
// here v = x_b − x_a), so that R² = d² + L² t², d² = |r⊥|² + ε², and
//     r_α r_αᵀ = r⊥ r⊥ᵀ − t (r⊥ vᵀ + v r⊥ᵀ) + t² v vᵀ,
// which removes (3). The moments K_{k,l} = ∫ t^k R^l dt over [t0, t1] = [−α*, 1 − α*] have closed
// forms whose end-point differences we rewrite without subtraction (identities in the comments
// below), which removes (1). (2) is avoided by using these forms only near the segment; far from
// it the integrand is analytic and smooth and Gauss–Legendre is exact to rounding.
#include "stokesrods/fluid/stokeslet_segment.h"

#include <array>
#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>

#include "stokesrods/common/assert.h"

namespace stokesrods {
namespace {

constexpr int kFarFieldPoints = 20;  // the most points a far-field rule uses

struct GaussLegendreRule {
  std::array<double, kFarFieldPoints> node{};    // on [0, 1]
  std::array<double, kFarFieldPoints> weight{};  // sum 1
  int size = 0;
};

// Nodes of P_n by Newton from the Chebyshev guesses; mapped to [0, 1].
GaussLegendreRule MakeGaussLegendreRule(int n) {
  GaussLegendreRule rule;
  rule.size = n;
  for (int i = 0; i < n; ++i) {
    double x = std::cos(kPi * (i + 0.75) / (n + 0.5));
    double dp = 1.0;
    for (int iteration = 0; iteration < 100; ++iteration) {
      double p0 = 1.0;
      double p1 = x;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = n * (x * p1 - p0) / (x * x - 1.0);
      const double step = p1 / dp;
      x -= step;
      if (std::abs(step) < 1e-16) break;
    }
    rule.node[static_cast<size_t>(i)] = 0.5 * (1.0 + x);
    rule.weight[static_cast<size_t>(i)] = 1.0 / ((1.0 - x * x) * dp * dp);  // 2/(…)·½
  }
  return rule;
}

// asinh(x1) − asinh(x0) for x0 < x1 without cancellation. With s = √(1 + x²),
// asinh x = log(x + s) and, for 0 ≤ x0 < x1, (x1 + s1)/(x0 + s0) − 1 =
// (x1 − x0)(1 + (x0 + x1)/(s0 + s1))/(x0 + s0)  (since s1 − s0 = (x1² − x0²)/(s0 + s1)).
double AsinhDifference(double x0, double x1) {
  if (x0 < 0.0 && x1 > 0.0) return std::asinh(x1) + std::asinh(-x0);  // two positive terms
  if (x1 <= 0.0) {                                                     // asinh is odd
    const double y0 = -x1;
    x1 = -x0;
    x0 = y0;
  }
  const double s0 = std::sqrt(1.0 + x0 * x0);
  const double s1 = std::sqrt(1.0 + x1 * x1);
  return std::log1p((x1 - x0) * (1.0 + (x0 + x1) / (s0 + s1)) / (x0 + s0));
}

// The six moments K_{k,l} = ∫_{t0}^{t1} t^k R^l dt, R = √(d² + L² t²), t1 − t0 = 1.
struct Moments {
  double k0m1, k1m1;              // l = −1, k = 0, 1
  double k0m3, k1m3, k2m3, k3m3;  // l = −3, k = 0 … 3
};

Moments CalcMoments(double length, double d, double t0, double t1) {
  const double l2 = length * length;
  const double r0 = std::sqrt(d * d + l2 * t0 * t0);
  const double r1 = std::sqrt(d * d + l2 * t1 * t1);
  const double x0 = length * t0 / d;
  const double x1 = length * t1 / d;
  Moments m{};
  // K0,−1 = [asinh(L t/d)]/L.
  const double asinh_difference = AsinhDifference(x0, x1);
  m.k0m1 = asinh_difference / length;
  // K1,−1 = [R]/L², and R1 − R0 = L² (t1² − t0²)/(R0 + R1) = L² (t0 + t1)/(R0 + R1).
  m.k1m1 = (t0 + t1) / (r0 + r1);
  // K0,−3 = [t/R]/d². Same signs: t1 R0 − t0 R1 = d² (t0 + t1)/(t1 R0 + t0 R1).
  if (t0 >= 0.0 || t1 <= 0.0) {
    m.k0m3 = (t0 + t1) / (r0 * r1 * (t1 * r0 + t0 * r1));
  } else {
    m.k0m3 = (t1 / r1 - t0 / r0) / (d * d);  // two positive terms
  }
  // K1,−3 = −[1/R]/L² = (R1 − R0)/(R0 R1 L²).
  m.k1m3 = (t0 + t1) / (r0 * r1 * (r0 + r1));
  // K2,−3 = [asinh(x) − x/√(1 + x²)]/L³, x = L t/d; the bracket is increasing in x and its
  // difference over an interval of length L/d ≥ 1 (near zone) is O(1): no cancellation.
  m.k2m3 = (asinh_difference - (x1 / std::sqrt(1.0 + x1 * x1) - x0 / std::sqrt(1.0 + x0 * x0))) /
           (l2 * length);
  // K3,−3 = [R + d²/R]/L⁴ = (R1 − R0)(R0 R1 − d²)/(R0 R1 L⁴), with
  // R0 R1 − d² = (d² L² (t0² + t1²) + L⁴ t0² t1²)/(R0 R1 + d²) ≥ 0.
  const double r0r1 = r0 * r1;
  const double r0r1_minus_d2 =
      (d * d * l2 * (t0 * t0 + t1 * t1) + l2 * l2 * t0 * t0 * t1 * t1) / (r0r1 + d * d);
  m.k3m3 = m.k1m1 * r0r1_minus_d2 / (r0r1 * l2);
  return m;
}

// L ∫ φ S_ε dt for the weight φ = c0 + c1 t (paper eq. 14 in the variable t).
Mat3 WeightedSegmentMatrix(const Moments& m, double c0, double c1, double length, double eps,
                           const Vec3& r_perp, const Vec3& v) {
  const double s_m1 = c0 * m.k0m1 + c1 * m.k1m1;  // ∫ φ/R
  const double s_0 = c0 * m.k0m3 + c1 * m.k1m3;   // ∫ φ/R³
  const double s_1 = c0 * m.k1m3 + c1 * m.k2m3;   // ∫ φ t/R³
  const double s_2 = c0 * m.k2m3 + c1 * m.k3m3;   // ∫ φ t²/R³
  const Mat3 rv = r_perp * v.transpose();
  Mat3 a = (s_m1 + eps * eps * s_0) * Mat3::Identity() + s_0 * (r_perp * r_perp.transpose()) -
           s_1 * (rv + rv.transpose()) + s_2 * (v * v.transpose());
  return length * a;
}

// Gauss–Legendre rules with 1 … kFarFieldPoints points.
const GaussLegendreRule& Rule(int n) {
  static const std::array<GaussLegendreRule, kFarFieldPoints + 1> rules = [] {
    std::array<GaussLegendreRule, kFarFieldPoints + 1> r{};
    for (int k = 1; k <= kFarFieldPoints; ++k) r[static_cast<size_t>(k)] = MakeGaussLegendreRule(k);
    return r;
  }();
  return rules[static_cast<size_t>(n)];
}

// Points for n-point Gauss–Legendre to reach round-off on the integrand of eq. 8. Its nearest
// singularities are at α = α* ± i d/L (R_α = 0, d² = |r⊥|² + ε²), at z0 on z = 2α − 1; the error
// of n points falls like ρ^(−2n), ρ the parameter of the Bernstein ellipse of [−1, 1] through z0:
// n = ln(1e-16)/(−2 ln ρ), plus two for the algebraic prefactor of the R⁻³ singularity.
// z0 lies at distance 2δ from [−1, 1], δ = √(distance from x̂ to the segment² + ε²)/L, and the
// Bernstein ellipses come closest to the interval at its ends (semi-major axis a = (ρ + 1/ρ)/2 = 1 + 2δ there), so
// ρ ≥ ρ_min(δ) with ρ_min + 1/ρ_min = 2 + 4δ. The smallest δ for which n points suffice is
// tabulated once from that bound: never fewer points than the exact rule.
// kRoundOffMinDelta[n]: the smallest δ at which n points reach round-off (n ≥ 3).
const std::array<double, kFarFieldPoints + 1> kRoundOffMinDelta = [] {
  std::array<double, kFarFieldPoints + 1> t{};
  for (int n = 3; n <= kFarFieldPoints; ++n) {
    const double rho = std::exp(36.8 / (2.0 * (n - 2)));  // from n = ⌈36.8/(2 ln ρ)⌉ + 2
    t[static_cast<size_t>(n)] = (rho + 1.0 / rho - 2.0) / 4.0;  // ρ + 1/ρ = 2 + 4δ
  }
  return t;
}();

int FarFieldPointCount(double delta) {
  for (int n = 3; n < kFarFieldPoints; ++n)
    if (delta >= kRoundOffMinDelta[static_cast<size_t>(n)]) return n;
  return kFarFieldPoints;
}

// δ above which n points meet the tolerance: GaussRuleError(n, δ) = tolerance.
double ToleranceMinDelta(int n, double tolerance) {
  return std::pow(GaussRuleError(n, 1.0) / tolerance, 1.0 / (2.0 * n - 1.0));
}

SegmentMobility FarFieldSegment(const Vec3& xa, const Vec3& v, double length, double eps,
                                const Vec3& point, int points) {
  // Σ_q w_q L φ(α_q) S_ε(r_q), φ = 1 − α (a) and α (b). Both are symmetric: accumulate the
  // diagonal weight and the six entries of r rᵀ/R³ as scalars (no 3×3 temporaries per point).
  const GaussLegendreRule& rule = Rule(points);
  const double eps2 = eps * eps;
  const Vec3 r0 = point - xa;
  double a[7] = {0, 0, 0, 0, 0, 0, 0}, b[7] = {0, 0, 0, 0, 0, 0, 0};  // diag, xx, xy, xz, yy, yz, zz
  for (int q = 0; q < rule.size; ++q) {
    const double alpha = rule.node[static_cast<size_t>(q)];
    const double rx = r0.x() - alpha * v.x(), ry = r0.y() - alpha * v.y(), rz = r0.z() - alpha * v.z();
    const double inv = 1.0 / std::sqrt(rx * rx + ry * ry + rz * rz + eps2);
    const double w = rule.weight[static_cast<size_t>(q)] * length;
    const double w3 = w * inv * inv * inv;
    const double terms[7] = {w * inv + eps2 * w3, w3 * rx * rx, w3 * rx * ry, w3 * rx * rz,
                             w3 * ry * ry,        w3 * ry * rz, w3 * rz * rz};
    for (int k = 0; k < 7; ++k) {
      a[k] += (1.0 - alpha) * terms[k];
      b[k] += alpha * terms[k];
    }
  }
  SegmentMobility out;
  out.a << a[0] + a[1], a[2], a[3], a[2], a[0] + a[4], a[5], a[3], a[5], a[0] + a[6];
  out.b << b[0] + b[1], b[2], b[3], b[2], b[0] + b[4], b[5], b[3], b[5], b[0] + b[6];
  return out;
}

}  // namespace

SegmentMobility StokesletSegmentGauss(const Vec3& xa, const Vec3& xb, double regularization,
                                      const Vec3& point, int n) {
  SR_ASSERT(n >= 1 && n <= kFarFieldPoints, "Gauss rule size out of range");
  const Vec3 v = xb - xa;
  return FarFieldSegment(xa, v, v.norm(), regularization, point, n);
}

void GaussLegendreRule01(int n, const double** nodes, const double** weights) {
  SR_ASSERT(n >= 1 && n <= kFarFieldPoints, "Gauss rule size out of range");
  const GaussLegendreRule& rule = Rule(n);
  *nodes = rule.node.data();
  *weights = rule.weight.data();
}

Mat3 RegularizedStokesletMatrix(const Vec3& r, double regularization) {
  const double eps2 = regularization * regularization;
  const double big_r2 = r.squaredNorm() + eps2;
  SR_DASSERT(big_r2 > 0.0, "regularized Stokeslet at r = 0 needs ε > 0");
  const double inv_r = 1.0 / std::sqrt(big_r2);
  const double inv_r3 = inv_r * inv_r * inv_r;
  return (inv_r + eps2 * inv_r3) * Mat3::Identity() + inv_r3 * (r * r.transpose());
}

Mat3 StokesletMatrix(const Vec3& r) {
  const double r2 = r.squaredNorm();
  SR_DASSERT(r2 > 0.0, "singular Stokeslet at r = 0");
  const double inv_r = 1.0 / std::sqrt(r2);
  return inv_r * Mat3::Identity() + (inv_r * inv_r * inv_r) * (r * r.transpose());
}

double GaussRuleError(int n, double delta) {
  return 2.0 * 9.6e-3 * std::pow(13.5, -(n - 2.0)) * std::pow(delta, -(2.0 * n - 1.0));
}

double GaussRuleMinDelta(int n, double tolerance) {
  SR_ASSERT(n >= 1 && n <= kFarFieldPoints, "Gauss rule size out of range");
  // StokesletSegment uses min(round-off count, the first n ≥ 2 meeting the tolerance) points.
  double min_delta = n >= 3 ? kRoundOffMinDelta[static_cast<size_t>(n)]
                            : std::numeric_limits<double>::infinity();
  if (n == kFarFieldPoints) min_delta = 1.0;  // the round-off rule never uses more
  if (tolerance > 0.0 && n >= 2) min_delta = std::min(min_delta, ToleranceMinDelta(n, tolerance));
  return std::max(min_delta, 1.0);
}

SegmentMobility StokesletSegment(const Vec3& xa, const Vec3& xb, double regularization,
                                 const Vec3& point, double tolerance) {
  const Vec3 v = xb - xa;
  const double l2 = v.squaredNorm();
  SR_ASSERT(l2 > 0.0, "Stokeslet segment of zero length");
  SR_ASSERT(regularization > 0.0, "Stokeslet segment needs ε > 0");
  const double length = std::sqrt(l2);
  const double eps = regularization;
  const Vec3 ra = point - xa;
  const double alpha_star = ra.dot(v) / l2;  // projection of x̂ on the line x_a + α v
  const Vec3 r_perp = ra - alpha_star * v;   // ⟂ v; r_α = r⊥ − (α − α*) v
  const double along = alpha_star < 0.0 ? -alpha_star : (alpha_star > 1.0 ? alpha_star - 1.0 : 0.0);
  const double distance2 = r_perp.squaredNorm() + along * along * l2;
  if (distance2 + eps * eps >= l2) {
    const double delta = std::sqrt((distance2 + eps * eps) / l2);
    int points = FarFieldPointCount(delta);
    if (tolerance > 0.0) {
      // δ above which n points meet the tolerance, GaussRuleError(n, δ) = tolerance, tabulated
      // once per tolerance (per thread: the assembly runs in parallel).
      thread_local double table_tolerance = -1.0;
      thread_local std::array<double, kFarFieldPoints + 1> min_delta{};
      if (tolerance != table_tolerance) {
        for (int n = 2; n <= kFarFieldPoints; ++n)
          min_delta[static_cast<size_t>(n)] = ToleranceMinDelta(n, tolerance);
        table_tolerance = tolerance;
      }
      for (int n = 2; n < points; ++n)
        if (delta >= min_delta[static_cast<size_t>(n)]) {
          points = n;
          break;
        }
    }
    return FarFieldSegment(xa, v, length, eps, point, points);
  }

  const double d = std::sqrt(r_perp.squaredNorm() + eps * eps);
  const Moments m = CalcMoments(length, d, -alpha_star, 1.0 - alpha_star);
  // Weights in t: φ_a = 1 − α = (1 − α*) − t,  φ_b = α = α* + t.
  SegmentMobility out;
  out.a = WeightedSegmentMatrix(m, 1.0 - alpha_star, -1.0, length, eps, r_perp, v);
  out.b = WeightedSegmentMatrix(m, alpha_star, 1.0, length, eps, r_perp, v);
  return out;
}

}  // namespace stokesrods
