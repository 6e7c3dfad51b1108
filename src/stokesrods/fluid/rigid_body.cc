#include "stokesrods/fluid/rigid_body.h"

#include <cmath>

#include <Eigen/LU>

#include "stokesrods/common/assert.h"
#include "stokesrods/fluid/stokeslet_segment.h"

namespace stokesrods {

Matrix3X FibonacciSphere(int n) {
  SR_ASSERT(n >= 2, "a sphere needs at least 2 points");
  const double golden_angle = kPi * (3.0 - std::sqrt(5.0));
  Matrix3X p(3, n);
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / n;  // equal-area bands
    const double rho = std::sqrt(1.0 - z * z), phi = golden_angle * i;
    p.col(i) = Vec3(rho * std::cos(phi), rho * std::sin(phi), z);
  }
  return p;
}

BodySurface SphereSurface(const Vec3& center, double radius, int n, double blob_over_spacing) {
  SR_ASSERT(radius > 0.0 && blob_over_spacing > 0.0, "sphere: radius and blob must be > 0");
  BodySurface s;
  s.points = (radius * FibonacciSphere(n)).colwise() + center;
  s.regularization = blob_over_spacing * std::sqrt(4.0 * kPi * radius * radius / n);
  return s;
}

MatX PointStokesletMobility(const BodySurface& surface, double viscosity) {
  SR_ASSERT(viscosity > 0.0 && surface.regularization > 0.0, "mobility needs μ > 0 and ε > 0");
  const Eigen::Index n = surface.points.cols();
  MatX m(3 * n, 3 * n);
  const double scale = 1.0 / (8.0 * kPi * viscosity);
#pragma omp parallel for schedule(static)
  for (Eigen::Index j = 0; j < n; ++j)
    for (Eigen::Index i = 0; i < n; ++i)
      m.block<3, 3>(3 * i, 3 * j) =
          scale * RegularizedStokesletMatrix(surface.points.col(i) - surface.points.col(j),
                                             surface.regularization);
  return m;
}

Mat6 RigidResistance(const BodySurface& surface, const Vec3& center, double viscosity) {
  const Eigen::Index n = surface.points.cols();
  const Eigen::PartialPivLU<MatX> lu(PointStokesletMobility(surface, viscosity));
  MatX velocities(3 * n, 6);  // the six unit rigid motions at the points
  for (Eigen::Index i = 0; i < n; ++i) {
    const Vec3 r = surface.points.col(i) - center;
    for (int k = 0; k < 3; ++k) {
      velocities.block<3, 1>(3 * i, k) = Vec3::Unit(k);
      velocities.block<3, 1>(3 * i, 3 + k) = Vec3::Unit(k).cross(r);
    }
  }
  const MatX forces = lu.solve(velocities);
  Mat6 resistance = Mat6::Zero();
  for (int mode = 0; mode < 6; ++mode)
    for (Eigen::Index i = 0; i < n; ++i) {
      const Vec3 f = forces.block<3, 1>(3 * i, mode);
      resistance.block<3, 1>(0, mode) += f;
      resistance.block<3, 1>(3, mode) += (surface.points.col(i) - center).cross(f);
    }
  return resistance;
}

}  // namespace stokesrods
