#include "stokesrods/fluid/lsbt.h"

#include <algorithm>
#include <cmath>

#include "stokesrods/common/assert.h"
#include "stokesrods/fluid/stokeslet_segment.h"

namespace stokesrods {

double LsbtEdgeLength(double radius) { return radius * std::sqrt(std::exp(1.0)); }

LsbtDiscretizationCheck CheckLsbtDiscretization(const Matrix3X& x, double radius,
                                                double tolerance) {
  SR_ASSERT(x.cols() >= 2, "a rod needs at least 2 nodes");
  LsbtDiscretizationCheck check;
  check.target_edge_length = LsbtEdgeLength(radius);
  double arc_length = 0.0;
  for (Eigen::Index i = 0; i + 1 < x.cols(); ++i) {
    const double edge = (x.col(i + 1) - x.col(i)).norm();
    arc_length += edge;
    const double deviation = std::abs(edge / check.target_edge_length - 1.0);
    if (deviation > tolerance) ++check.edges_outside;
    if (deviation > check.max_relative_deviation || check.worst_edge < 0) {
      check.max_relative_deviation = deviation;
      check.worst_edge = static_cast<int>(i);
    }
  }
  check.fits = check.edges_outside == 0;
  // At most 1e9 (a radius so small that more nodes would be needed is refused all the same; the
  // count stays an int: the fuzzer found 7e8 overflowing 4 N in build_model.cc).
  check.suggested_nodes =
      1 + static_cast<int>(std::min(1e9, std::round(arc_length / check.target_edge_length)));
  return check;
}

void AssembleLsbtMobility(const FluidParams& params, const std::vector<HydroRod>& rods,
                          MatX* mobility) {
  const Eigen::Index total = TotalNodes(rods);
  mobility->setZero(3 * total, 3 * total);
  const double oseen = 1.0 / (8.0 * kPi * params.viscosity);
  // Gather every node once: the Oseen sum runs over all rods alike.
  Matrix3X all(3, total);
  Eigen::Index offset = 0;
  for (const HydroRod& rod : rods) {
    all.middleCols(offset, rod.x->cols()) = *rod.x;
    const Matrix3X tangents = NodeTangents(*rod.x);
    const double local = 1.0 / (4.0 * kPi * params.viscosity * LsbtEdgeLength(rod.radius));
    for (Eigen::Index i = 0; i < rod.x->cols(); ++i) {
      const Vec3 t = tangents.col(i);
      mobility->block<3, 3>(3 * (offset + i), 3 * (offset + i)) =
          local * (Mat3::Identity() - t * t.transpose());
    }
    offset += rod.x->cols();
  }
  for (Eigen::Index q = 0; q < total; ++q) {
    for (Eigen::Index p = q + 1; p < total; ++p) {
      const Vec3 r = all.col(q) - all.col(p);
      SR_ASSERT(r.squaredNorm() > 0.0, "LSBT: two distinct nodes coincide");
      const Mat3 block = oseen * StokesletMatrix(r);
      mobility->block<3, 3>(3 * q, 3 * p) = block;
      mobility->block<3, 3>(3 * p, 3 * q) = block;  // J(r) = J(−r) = J(r)ᵀ
    }
  }
}

}  // namespace stokesrods
