// Reference evaluation of paper eq. 8 by adaptive Gauss–Kronrod (7, 15) quadrature.
// Independent of the closed forms: only the point blob S_ε of eq. 7 is shared.
#include <algorithm>
#include <array>
#include <cmath>

#include "stokesrods/common/assert.h"
#include "stokesrods/fluid/stokeslet_segment.h"

namespace stokesrods {
namespace {

// Kronrod nodes on [−1, 1] (x ≥ 0 half; odd indices are the 7-point Gauss nodes) and weights.
constexpr std::array<double, 8> kKronrodNode = {
    0.991455371120812639206854697526329, 0.949107912342758524526189684047851,
    0.864864423359769072789712788640926, 0.741531185599394439863864773280788,
    0.586087235467691130294144845693013, 0.405845151377397166906606412076961,
    0.207784955007898467600689403773245, 0.0};
constexpr std::array<double, 8> kKronrodWeight = {
    0.022935322010529224963732008058970, 0.063092092629978553290700663189204,
    0.104790010322250183839876322541518, 0.140653259715525918745189590510238,
    0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
    0.204432940075298892414161999234649, 0.209482141084727828012999174891714};
constexpr std::array<double, 4> kGaussWeight = {  // at kKronrodNode[1], [3], [5], [7]
    0.129484966168869693270611432679082, 0.279705391489276667901467771423780,
    0.381830050505118944950369775488975, 0.417959183673469387755102040816327};

struct Integrand {
  Vec3 xa, v, point;
  double length, eps;
  // (A_a | A_b) integrand at α: L S_ε(x̂ − x_α) (1 − α | α), a 3 × 6 block.
  Eigen::Matrix<double, 3, 6> operator()(double alpha) const {
    const Mat3 s = length * RegularizedStokesletMatrix(point - xa - alpha * v, eps);
    Eigen::Matrix<double, 3, 6> out;
    out << (1.0 - alpha) * s, alpha * s;
    return out;
  }
};

using Block = Eigen::Matrix<double, 3, 6>;

// One G7K15 panel on [lo, hi]: Kronrod estimate and |Kronrod − Gauss| (Frobenius).
void Panel(const Integrand& f, double lo, double hi, Block* kronrod, double* error) {
  const double half = 0.5 * (hi - lo);
  const double centre = 0.5 * (hi + lo);
  Block k = Block::Zero();
  Block g = Block::Zero();
  for (size_t i = 0; i < kKronrodNode.size(); ++i) {
    const double dx = half * kKronrodNode[i];
    const Block sum = (i + 1 == kKronrodNode.size()) ? f(centre) : Block(f(centre - dx) + f(centre + dx));
    k += kKronrodWeight[i] * sum;
    if (i % 2 == 1) g += kGaussWeight[i / 2] * sum;
  }
  *kronrod = half * k;
  *error = (half * (k - g)).norm();
}

// Bisect until the panel error is below tolerance_per_length × panel length.
Block Adaptive(const Integrand& f, double lo, double hi, double tolerance_per_length, int depth) {
  Block estimate;
  double error = 0.0;
  Panel(f, lo, hi, &estimate, &error);
  // Accept when below tolerance, or when the Kronrod–Gauss difference is rounding noise: near a
  // point on the segment, r_α = (x̂ − x_a) − α v carries an absolute error ~1e-16 |x̂ − x_a|, so
  // tiny panels there see ~1e-14 relative noise in the integrand itself.
  constexpr double kRoundingFloor = 1e-13;
  if (error <= tolerance_per_length * (hi - lo) || error <= kRoundingFloor * estimate.norm() ||
      depth >= 50) {
    return estimate;
  }
  const double mid = 0.5 * (lo + hi);
  return Adaptive(f, lo, mid, tolerance_per_length, depth + 1) +
         Adaptive(f, mid, hi, tolerance_per_length, depth + 1);
}

}  // namespace

SegmentMobility StokesletSegmentByQuadrature(const Vec3& xa, const Vec3& xb, double regularization,
                                             const Vec3& point, double relative_tolerance) {
  const Vec3 v = xb - xa;
  SR_ASSERT(v.squaredNorm() > 0.0, "Stokeslet segment of zero length");
  SR_ASSERT(regularization > 0.0, "Stokeslet segment needs ε > 0");
  const Integrand f{xa, v, point, v.norm(), regularization};
  // Break points: the projection α* of x̂ (where a near point makes the integrand peak).
  const double alpha_star = std::clamp((point - xa).dot(v) / v.squaredNorm(), 0.0, 1.0);
  std::array<double, 3> breaks = {0.0, alpha_star, 1.0};
  // The scale |A| for the relative tolerance: first from one panel per piece, then from a full
  // adaptive pass (a narrow peak missed by the first guess only makes the second pass stricter).
  Block scale = Block::Zero();
  for (size_t i = 0; i + 1 < breaks.size(); ++i) {
    Block panel;
    double error = 0.0;
    if (breaks[i + 1] > breaks[i]) Panel(f, breaks[i], breaks[i + 1], &panel, &error);
    if (breaks[i + 1] > breaks[i]) scale += panel;
  }
  double norm = scale.norm();
  for (int pass = 0; pass < 2; ++pass) {
    Block total = Block::Zero();
    for (size_t i = 0; i + 1 < breaks.size(); ++i) {
      if (breaks[i + 1] > breaks[i]) {
        total += Adaptive(f, breaks[i], breaks[i + 1], relative_tolerance * norm, 0);
      }
    }
    norm = total.norm();
    scale = total;
  }
  SegmentMobility out;
  out.a = scale.leftCols<3>();
  out.b = scale.rightCols<3>();
  return out;
}

}  // namespace stokesrods
