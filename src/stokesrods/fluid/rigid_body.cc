#include "stokesrods/fluid/rigid_body.h"

#include <cmath>

#include <Eigen/LU>

#include "stokesrods/common/assert.h"
#include "stokesrods/fluid/rss.h"
#include "stokesrods/fluid/rss_wall.h"
#include "stokesrods/fluid/stokeslet_segment.h"

namespace stokesrods {
namespace {

// The rotation about e_z × a that takes e_z to the unit vector a (Rodrigues:
// I + [v]× + [v]×²/(1 + c), v = e_z × a, c = a_z), a half-turn about e_x for a = −e_z. Near that
// case 1/(1 + c) is taken as (1 − c)/|v|², free of cancellation. (Eigen's
// Quaternion::FromTwoVectors gives the same rotation, but its SVD for the antiparallel case took
// a quarter of this file's compile time.)
Mat3 TurnZTo(const Vec3& a) {
  const double c = a.z(), s2 = a.x() * a.x() + a.y() * a.y();
  if (s2 == 0.0) return c > 0.0 ? Mat3::Identity() : Mat3(Vec3(1.0, -1.0, -1.0).asDiagonal());
  Mat3 k;  // [v]×, v = (−a_y, a_x, 0)
  k << 0.0, 0.0, a.x(), 0.0, 0.0, a.y(), -a.x(), -a.y(), 0.0;
  return Mat3::Identity() + k + (c >= 0.0 ? 1.0 / (1.0 + c) : (1.0 - c) / s2) * (k * k);
}

}  // namespace

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

BodySurface SpheroidSurface(const Vec3& center, double radius, double half_length, const Vec3& axis,
                            int n, double blob_over_spacing) {
  SR_ASSERT(radius > 0.0 && half_length > 0.0 && axis.norm() > 0.0, "spheroid: bad semi-axes or axis");
  const double b = radius, a = half_length;
  double area = 4.0 * kPi * b * b;  // a sphere
  if (a > b) {         // prolate: 2πb²(1 + a/(b e) asin e), e² = 1 − b²/a²
    const double e = std::sqrt(1.0 - b * b / (a * a));
    area = 2.0 * kPi * b * b * (1.0 + a / (b * e) * std::asin(e));
  } else if (a < b) {  // oblate: 2πb²(1 + (1 − e²)/e atanh e), e² = 1 − a²/b²
    const double e = std::sqrt(1.0 - a * a / (b * b));
    area = 2.0 * kPi * b * b * (1.0 + (1.0 - e * e) / e * std::atanh(e));
  }
  Matrix3X unit = FibonacciSphere(n);
  unit.row(0) *= b;
  unit.row(1) *= b;
  unit.row(2) *= a;
  const Mat3 turn = TurnZTo(axis.normalized());
  BodySurface s;
  s.points = (turn * unit).colwise() + center;
  s.regularization = blob_over_spacing * std::sqrt(area / n);
  s.center = center;
  return s;
}

MatX PointStokesletMobility(const BodySurface& surface, double viscosity, const Wall* wall) {
  SR_ASSERT(viscosity > 0.0 && surface.regularization > 0.0, "mobility needs μ > 0 and ε > 0");
  const Eigen::Index n = surface.points.cols();
  MatX m(3 * n, 3 * n);
  const double scale = 1.0 / (8.0 * kPi * viscosity);
#pragma omp parallel for schedule(static)
  for (Eigen::Index j = 0; j < n; ++j)
    for (Eigen::Index i = 0; i < n; ++i)
      m.block<3, 3>(3 * i, 3 * j) =
          scale * PointBlobMatrix(wall, surface.points.col(i), surface.points.col(j),
                                  surface.regularization);
  return m;
}

Mat6 RigidResistance(const BodySurface& surface, const Vec3& center, double viscosity,
                     const Wall* wall) {
  const Eigen::Index n = surface.points.cols();
  const Eigen::PartialPivLU<MatX> lu(PointStokesletMobility(surface, viscosity, wall));
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

MatX AssembleMobilityWithBodies(const FluidParams& params, const std::vector<HydroRod>& rods,
                                const std::vector<BodySurface>& bodies) {
  SR_ASSERT(params.model == FluidModel::kRss, "bodies need the RSS fluid model");
  const Eigen::Index rod_nodes = rods.empty() ? 0 : TotalNodes(rods);
  Eigen::Index total = rod_nodes;
  for (const BodySurface& b : bodies) total += b.points.cols();
  MatX m = MatX::Zero(3 * total, 3 * total);
  if (!rods.empty()) {
    MatX rod_block;
    AssembleMobility(params, rods, &rod_block);  // with the wall's images if any
    m.topLeftCorner(3 * rod_nodes, 3 * rod_nodes) = rod_block;
  }
  const double scale = 1.0 / (8.0 * kPi * params.viscosity);
  // All body points in one list, each with its blob.
  Matrix3X points(3, total - rod_nodes);
  VecX eps(total - rod_nodes);
  Eigen::Index k = 0;
  for (const BodySurface& b : bodies) {
    points.middleCols(k, b.points.cols()) = b.points;
    eps.segment(k, b.points.cols()).setConstant(b.regularization);
    k += b.points.cols();
  }
  // Rod nodes in one list.
  Matrix3X nodes(3, rod_nodes);
  k = 0;
  for (const HydroRod& rod : rods) {
    nodes.middleCols(k, rod.x->cols()) = *rod.x;
    k += rod.x->cols();
  }
  // Body blobs at rod nodes and at body points (Blakelets with a wall).
  const Wall* wall = params.wall ? &*params.wall : nullptr;
#pragma omp parallel for schedule(static)
  for (Eigen::Index j = 0; j < points.cols(); ++j) {
    const Eigen::Index col = 3 * (rod_nodes + j);
    for (Eigen::Index i = 0; i < rod_nodes; ++i)
      m.block<3, 3>(3 * i, col) = scale * PointBlobMatrix(wall, nodes.col(i), points.col(j), eps(j));
    for (Eigen::Index i = 0; i < points.cols(); ++i)
      m.block<3, 3>(3 * (rod_nodes + i), col) =
          scale * PointBlobMatrix(wall, points.col(i), points.col(j), eps(j));
  }
  // Rod segments at body points: A_a f_a + A_b f_b with f = F/Λ (as in rss.cc).
  Eigen::Index first = 0;
  for (const HydroRod& rod : rods) {
    const double rod_eps = params.regularization * rod.radius;
    const VecX lengths = VoronoiLengths(*rod.x);
    for (Eigen::Index i = 0; i < points.cols(); ++i)
      for (Eigen::Index s = 0; s + 1 < rod.x->cols(); ++s) {
        const SegmentMobility a =
            StokesletSegment(rod.x->col(s), rod.x->col(s + 1), rod_eps, points.col(i));
        m.block<3, 3>(3 * (rod_nodes + i), 3 * (first + s)) += scale / lengths(s) * a.a;
        m.block<3, 3>(3 * (rod_nodes + i), 3 * (first + s + 1)) += scale / lengths(s + 1) * a.b;
      }
    first += rod.x->cols();
  }
  if (params.wall && !rods.empty())
    for (Eigen::Index i = 0; i < points.cols(); ++i)
      m.block(3 * (rod_nodes + i), 0, 3, 3 * rod_nodes) += RssWallImageRow(params, rods, points.col(i));
  return m;
}

MatX AssembleBorderedMobility(const FluidParams& params, const std::vector<HydroRod>& rods,
                              const std::vector<BodySurface>& bodies) {
  const MatX m = AssembleMobilityWithBodies(params, rods, bodies);
  int free = 0;
  for (const BodySurface& b : bodies) free += b.free ? 1 : 0;
  if (free == 0) return m;
  MatX out = MatX::Zero(m.rows() + 6 * free, m.cols() + 6 * free);
  out.topLeftCorner(m.rows(), m.cols()) = m;
  Eigen::Index point = rods.empty() ? 0 : TotalNodes(rods), mode = m.rows();
  for (const BodySurface& b : bodies) {
    if (b.free) {
      for (Eigen::Index j = 0; j < b.points.cols(); ++j) {
        const Vec3 r = b.points.col(j) - b.center;
        for (int c = 0; c < 3; ++c) {
          const Vec3 rotation = Vec3::Unit(c).cross(r);
          out.block<3, 1>(3 * (point + j), mode + c) = Vec3::Unit(c);
          out.block<3, 1>(3 * (point + j), mode + 3 + c) = rotation;
          out.block<1, 3>(mode + c, 3 * (point + j)) = Vec3::Unit(c).transpose();
          out.block<1, 3>(mode + 3 + c, 3 * (point + j)) = rotation.transpose();
        }
      }
      mode += 6;
    }
    point += b.points.cols();
  }
  return out;
}

Vec3 BodyBlobVelocityAt(const FluidParams& params, const std::vector<BodySurface>& bodies,
                        const VecX& forces, const Vec3& point) {
  const Wall* wall = params.wall ? &*params.wall : nullptr;
  Vec3 u = Vec3::Zero();
  Eigen::Index j = 0;
  for (const BodySurface& b : bodies)
    for (Eigen::Index i = 0; i < b.points.cols(); ++i, ++j)
      u += PointBlobMatrix(wall, point, b.points.col(i), b.regularization) * forces.segment<3>(3 * j);
  SR_ASSERT(forces.size() == 3 * j, "BodyBlobVelocityAt: forces of the wrong size");
  return u / (8.0 * kPi * params.viscosity);
}

Vec6 RigidSwimmerVelocity(const FluidParams& params, const std::vector<HydroRod>& rods,
                          const BodySurface& body, const Vec3& center, const Vec3& motor_axis,
                          const Vec3& motor_point, double omega) {
  const MatX m = AssembleMobilityWithBodies(params, rods, {body});
  const Eigen::Index n = m.rows() / 3, rod_nodes = n - body.points.cols();
  Matrix3X x(3, n);  // every point: rod nodes, then the body's
  Eigen::Index k = 0;
  for (const HydroRod& rod : rods) {
    x.middleCols(k, rod.x->cols()) = *rod.x;
    k += rod.x->cols();
  }
  x.rightCols(body.points.cols()) = body.points;
  MatX g(3 * n, 6);  // rigid motions about the centre
  VecX w = VecX::Zero(3 * n);  // the motor's relative motion of the rods
  for (Eigen::Index i = 0; i < n; ++i) {
    const Vec3 r = x.col(i) - center;
    for (int c = 0; c < 3; ++c) {
      g.block<3, 1>(3 * i, c) = Vec3::Unit(c);
      g.block<3, 1>(3 * i, 3 + c) = Vec3::Unit(c).cross(r);
    }
    if (i < rod_nodes) w.segment<3>(3 * i) = motor_axis.cross(x.col(i) - motor_point);
  }
  const Eigen::PartialPivLU<MatX> lu(m);
  const MatX mg = lu.solve(g);    // 𝕄⁻¹ G
  const VecX mw = lu.solve(w);    // 𝕄⁻¹ w
  const Mat6 resistance = g.transpose() * mg;
  const Vec6 drive = g.transpose() * mw;
  return -resistance.partialPivLu().solve(omega * drive);
}

}  // namespace stokesrods
