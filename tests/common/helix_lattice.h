// The helix lattice of the Stokeslet-sum tests and benchmark: helices of 65 nodes (radius 0.01 m,
// pitch 0.05 m, axis 0.2 m along −z) on a square lattice 0.04 m apart; sources: 2 Gauss points
// per segment, ε = 1.02e-3 m; targets: the nodes. And the error measure of the Stokeslet sums.
#pragma once

#include <algorithm>
#include <cmath>

#include "stokesrods/common/types.h"

namespace stokesrods::testing {

struct PointCloud {
  Matrix3X sources, targets;
  VecX regularization;
};

inline PointCloud HelixLattice(int rows, int cols) {
  const int nodes = 65;
  const double radius = 0.01, pitch = 0.05, length = 0.2, spacing = 0.04;
  PointCloud c;
  c.targets.resize(3, rows * cols * nodes);
  c.sources.resize(3, rows * cols * 2 * (nodes - 1));
  int nt = 0, ns = 0;
  for (int i = 0; i < rows; ++i) {
    for (int j = 0; j < cols; ++j) {
      const Vec3 base(spacing * i, spacing * j, 0.0);
      auto at = [&](double z) {
        const double phi = 2.0 * kPi * z / pitch;
        return Vec3(base + Vec3(radius * std::cos(phi), radius * std::sin(phi), -z));
      };
      for (int k = 0; k < nodes; ++k) c.targets.col(nt++) = at(length * k / (nodes - 1));
      for (int k = 0; k + 1 < nodes; ++k)
        for (double a : {0.5 - 0.5 / std::sqrt(3.0), 0.5 + 0.5 / std::sqrt(3.0)})
          c.sources.col(ns++) = at(length * (k + a) / (nodes - 1));
    }
  }
  c.regularization = VecX::Constant(ns, 1.02e-3);
  return c;
}

/// The error measure of stokeslet_sum.h: max over targets of |w − w_ref| / Σ_s |S(x_t − y_s)|₂ |g_s|.
inline double StokesletSumError(const PointCloud& c, const Matrix3X& g, const Matrix3X& w,
                                const Matrix3X& ref) {
  double worst = 0.0;
  for (Eigen::Index t = 0; t < c.targets.cols(); ++t) {
    double scale = 0.0;
    for (Eigen::Index s = 0; s < c.sources.cols(); ++s) {
      const Vec3 r = c.targets.col(t) - c.sources.col(s);
      const double e2 = c.regularization[s] * c.regularization[s];
      const double big_r = std::sqrt(r.squaredNorm() + e2);
      // The eigenvalues of S_ε are 1/R + ε²/R³ (twice) and 1/R + (ε² + r²)/R³, the largest.
      scale += (1.0 / big_r + (e2 + r.squaredNorm()) / (big_r * big_r * big_r)) * g.col(s).norm();
    }
    worst = std::max(worst, (w.col(t) - ref.col(t)).norm() / scale);
  }
  return worst;
}

}  // namespace stokesrods::testing
