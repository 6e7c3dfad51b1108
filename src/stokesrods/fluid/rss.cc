#include "stokesrods/fluid/rss.h"

#include <vector>

#include "stokesrods/common/assert.h"
#include "stokesrods/fluid/stokeslet_segment.h"

namespace stokesrods {

void AssembleRssDensityMobility(const FluidParams& params, const std::vector<HydroRod>& rods,
                                MatX* density_mobility) {
  const Eigen::Index total = TotalNodes(rods);
  density_mobility->setZero(3 * total, 3 * total);
  const double scale = 1.0 / (8.0 * kPi * params.viscosity);
  std::vector<const Matrix3X*> node_rod;  // rod of each global node, and its column
  std::vector<Eigen::Index> node_col;
  for (const HydroRod& rod : rods)
    for (Eigen::Index i = 0; i < rod.x->cols(); ++i) {
      node_rod.push_back(rod.x);
      node_col.push_back(i);
    }
  // Each target writes its own three rows: targets in parallel.
#pragma omp parallel for schedule(dynamic, 8)
  for (Eigen::Index target = 0; target < total; ++target) {
    const Vec3 point = node_rod[static_cast<size_t>(target)]->col(node_col[static_cast<size_t>(target)]);
    Eigen::Index source = 0;  // global index of the source rod's first node
    for (const HydroRod& rod : rods) {
      const double eps = params.regularization * rod.radius;
      for (Eigen::Index j = 0; j + 1 < rod.x->cols(); ++j) {
        const SegmentMobility s = StokesletSegment(rod.x->col(j), rod.x->col(j + 1), eps, point,
                                                   params.far_field_tolerance);
        density_mobility->block<3, 3>(3 * target, 3 * (source + j)) += scale * s.a;
        density_mobility->block<3, 3>(3 * target, 3 * (source + j + 1)) += scale * s.b;
      }
      source += rod.x->cols();
    }
  }
}

void AssembleRssMobility(const FluidParams& params, const std::vector<HydroRod>& rods,
                         MatX* mobility) {
  AssembleRssDensityMobility(params, rods, mobility);
  Eigen::Index offset = 0;
  for (const HydroRod& rod : rods) {
    const VecX lengths = VoronoiLengths(*rod.x);
    for (Eigen::Index j = 0; j < rod.x->cols(); ++j) {
      mobility->middleCols<3>(3 * (offset + j)) /= lengths(j);
    }
    offset += rod.x->cols();
  }
}

Vec3 RssVelocityAt(const FluidParams& params, const std::vector<HydroRod>& rods,
                   const VecX& nodal_forces, const Vec3& point) {
  SR_ASSERT(nodal_forces.size() == 3 * TotalNodes(rods), "RSS: force vector of the wrong size");
  Vec3 u = Vec3::Zero();
  Eigen::Index offset = 0;
  for (const HydroRod& rod : rods) {
    const double eps = params.regularization * rod.radius;
    const VecX lengths = VoronoiLengths(*rod.x);
    for (Eigen::Index j = 0; j + 1 < rod.x->cols(); ++j) {
      const SegmentMobility s = StokesletSegment(rod.x->col(j), rod.x->col(j + 1), eps, point);
      const Vec3 fa = nodal_forces.segment<3>(3 * (offset + j)) / lengths(j);
      const Vec3 fb = nodal_forces.segment<3>(3 * (offset + j + 1)) / lengths(j + 1);
      u += s.a * fa + s.b * fb;
    }
    offset += rod.x->cols();
  }
  return u / (8.0 * kPi * params.viscosity);
}

}  // namespace stokesrods
