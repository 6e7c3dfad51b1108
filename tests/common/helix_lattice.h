// The helix lattice of the Stokeslet-sum tests and benchmark: helices of 65 nodes (radius 0.01 m,
// pitch 0.05 m, axis 0.2 m along −z) on a square lattice 0.04 m apart; sources: 2 Gauss points
// per segment, ε = 1.02e-3 m; targets: the nodes.
#pragma once

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

}  // namespace stokesrods::testing
