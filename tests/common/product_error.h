// A fast operator against its dense reference, product by product (tests only).
#pragma once

#include <algorithm>
#include <random>

#include "stokesrods/fluid/mobility_operator.h"

namespace stokesrods {

/// max over 4 random forces (normal, from `seed`) of |op F − dense F|_∞ / |dense F|_∞.
inline double WorstProductError(const MobilityOperator& op, const MatX& dense, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  double worst = 0.0;
  for (int trial = 0; trial < 4; ++trial) {
    VecX f(dense.cols());
    for (Eigen::Index i = 0; i < f.size(); ++i) f(i) = normal(rng);
    VecX u;
    op.Apply(f, &u);
    const VecX reference = dense * f;
    worst = std::max(worst, (u - reference).lpNorm<Eigen::Infinity>() /
                                reference.lpNorm<Eigen::Infinity>());
  }
  return worst;
}

/// The matrix-free options at one far-field accuracy `tolerance`, the far sum always direct.
inline MobilityOptions DirectSumOptions(double tolerance) {
  MobilityOptions options;
  options.kind = MobilityKind::kMatrixFree;
  options.tolerance = std::min(tolerance, MobilityOptions{}.tolerance);
  options.fast_sum_tolerance = tolerance;
  options.direct_sum_below = 1e12;  // never the FMM
  return options;
}

}  // namespace stokesrods
