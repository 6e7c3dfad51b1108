#include "stokesrods/fluid/rss_wall.h"

#include "stokesrods/common/assert.h"

namespace stokesrods {

MatX RssWallImageRow(const FluidParams& params, const std::vector<HydroRod>& rods,
                     const Vec3& point) {
  SR_ASSERT(params.wall.has_value(), "RssWallImageRow needs a wall");
  MatX row = MatX::Zero(3, 3 * TotalNodes(rods));
  const double scale = 1.0 / (8.0 * kPi * params.viscosity);
  Eigen::Index first = 0;
  for (const HydroRod& rod : rods) {
    const double eps = params.regularization * rod.radius;
    const VecX lengths = VoronoiLengths(*rod.x);
    for (Eigen::Index j = 0; j + 1 < rod.x->cols(); ++j) {
      const SegmentMobility s =
          StokesletSegmentWallImages(*params.wall, rod.x->col(j), rod.x->col(j + 1), eps, point,
                                     params.far_field_tolerance);
      row.middleCols<3>(3 * (first + j)) += scale / lengths(j) * s.a;
      row.middleCols<3>(3 * (first + j + 1)) += scale / lengths(j + 1) * s.b;
    }
    first += rod.x->cols();
  }
  return row;
}

void AddRssWallImages(const FluidParams& params, const std::vector<HydroRod>& rods,
                      MatX* mobility) {
  const Eigen::Index total = TotalNodes(rods);
  SR_ASSERT(mobility->rows() == 3 * total && mobility->cols() == 3 * total,
            "AddRssWallImages: the mobility has the wrong size");
  std::vector<Vec3> targets;
  for (const HydroRod& rod : rods)
    for (Eigen::Index i = 0; i < rod.x->cols(); ++i) targets.push_back(rod.x->col(i));
#pragma omp parallel for schedule(dynamic, 8)
  for (Eigen::Index t = 0; t < total; ++t)
    mobility->middleRows<3>(3 * t) += RssWallImageRow(params, rods, targets[static_cast<size_t>(t)]);
}

Vec3 RssWallImageVelocityAt(const FluidParams& params, const std::vector<HydroRod>& rods,
                            const VecX& nodal_forces, const Vec3& point) {
  return RssWallImageRow(params, rods, point) * nodal_forces;
}

}  // namespace stokesrods
