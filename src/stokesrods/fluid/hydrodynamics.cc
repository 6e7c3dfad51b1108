#include "stokesrods/fluid/hydrodynamics.h"

#include "stokesrods/common/assert.h"
#include "stokesrods/fluid/lsbt.h"
#include "stokesrods/fluid/rft.h"
#include "stokesrods/fluid/rss.h"
#include "stokesrods/fluid/rss_wall.h"
#include "stokesrods/fluid/stokeslet_segment.h"

namespace stokesrods {

VecX VoronoiLengths(const Matrix3X& x) {
  SR_ASSERT(x.cols() >= 2, "a rod needs at least 2 nodes");
  VecX lengths = VecX::Zero(x.cols());
  for (Eigen::Index i = 0; i + 1 < x.cols(); ++i) {
    const double half_edge = 0.5 * (x.col(i + 1) - x.col(i)).norm();
    lengths(i) += half_edge;
    lengths(i + 1) += half_edge;
  }
  return lengths;
}

Matrix3X NodeTangents(const Matrix3X& x) {
  SR_ASSERT(x.cols() >= 2, "a rod needs at least 2 nodes");
  Matrix3X tangents = Matrix3X::Zero(3, x.cols());
  for (Eigen::Index i = 0; i + 1 < x.cols(); ++i) {
    const Vec3 edge = x.col(i + 1) - x.col(i);
    SR_ASSERT(edge.squaredNorm() > 0.0, "zero-length edge");
    const Vec3 t = edge.normalized();
    tangents.col(i) += t;
    tangents.col(i + 1) += t;
  }
  for (Eigen::Index i = 0; i < x.cols(); ++i) {
    SR_ASSERT(tangents.col(i).squaredNorm() > 0.0, "edges fold back onto each other");
    tangents.col(i).normalize();
  }
  return tangents;
}

Eigen::Index TotalNodes(const std::vector<HydroRod>& rods) {
  Eigen::Index total = 0;
  for (const HydroRod& rod : rods) {
    SR_ASSERT(rod.x != nullptr, "HydroRod without positions");
    total += rod.x->cols();
  }
  return total;
}

void AssembleMobility(const FluidParams& params, const std::vector<HydroRod>& rods,
                      MatX* mobility) {
  SR_ASSERT(params.viscosity > 0.0, "viscosity must be > 0");
  SR_ASSERT(!params.wall || params.model == FluidModel::kRss, "a wall needs the RSS model");
  switch (params.model) {
    case FluidModel::kRss:
      AssembleRssMobility(params, rods, mobility);
      if (params.wall) AddRssWallImages(params, rods, mobility);
      return;
    case FluidModel::kLsbt: AssembleLsbtMobility(params, rods, mobility); return;
    case FluidModel::kRft: AssembleRftMobility(rods, mobility); return;
    case FluidModel::kNone: break;
  }
  SR_ASSERT(false, "AssembleMobility: no fluid model");
}

Vec3 FluidVelocityAt(const FluidParams& params, const std::vector<HydroRod>& rods,
                     const VecX& nodal_forces, const Vec3& point) {
  SR_ASSERT(params.model != FluidModel::kNone, "FluidVelocityAt: no fluid model");
  if (params.model == FluidModel::kRss)
    return RssVelocityAt(params, rods, nodal_forces, point) +
           (params.wall ? RssWallImageVelocityAt(params, rods, nodal_forces, point) : Vec3::Zero());
  SR_ASSERT(!params.wall, "a wall needs the RSS model");
  SR_ASSERT(nodal_forces.size() == 3 * TotalNodes(rods), "force vector of the wrong size");
  Vec3 u = Vec3::Zero();
  Eigen::Index offset = 0;
  for (const HydroRod& rod : rods) {
    for (Eigen::Index p = 0; p < rod.x->cols(); ++p) {
      const Vec3 r = point - rod.x->col(p);
      if (r.squaredNorm() == 0.0) continue;  // the singular self term is left out
      u += StokesletMatrix(r) * nodal_forces.segment<3>(3 * (offset + p));
    }
    offset += rod.x->cols();
  }
  return u / (8.0 * kPi * params.viscosity);
}

}  // namespace stokesrods
