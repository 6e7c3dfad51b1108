// Regularized Stokeslet Segments above a plane wall in the assembled mobility (fluid/rss_wall.h,
// AssembleMobility with FluidParams::wall): against the segment-by-segment reference, no slip on
// the wall from the assembled operator, and the sideways drift of a helix spun near a wall.
#include "stokesrods/fluid/rss_wall.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include <Eigen/LU>

#include "stokesrods/fluid/hydrodynamics.h"
#include "stokesrods/fluid/wall.h"

namespace stokesrods {
namespace {

constexpr double kMu = 1.0;  // [Pa·s]

// A helix of `turns` turns of radius R and pitch λ with its axis along `axis` (unit) through
// `center`, N nodes.
Matrix3X Helix(const Vec3& center, const Vec3& axis, double radius, double pitch, double turns,
               int n, double phase0 = 0.0) {
  const Vec3 e1 = axis.unitOrthogonal(), e2 = axis.cross(e1);
  Matrix3X x(3, n);
  const double length = turns * pitch;
  for (int i = 0; i < n; ++i) {
    const double s = length * i / (n - 1.0) - 0.5 * length, phase = phase0 + 2.0 * kPi * s / pitch;
    x.col(i) = center + s * axis + radius * (std::cos(phase) * e1 + std::sin(phase) * e2);
  }
  return x;
}

FluidParams WallParams(const Wall& wall) {
  FluidParams p;
  p.model = FluidModel::kRss;
  p.viscosity = kMu;
  p.regularization = 1.02;
  p.wall = wall;
  return p;
}

Wall TiltedWall() {
  Wall w;
  w.point = Vec3(0.01, -0.02, -0.03);
  w.normal = Vec3(0.1, -0.2, 1.0).normalized();
  return w;
}

TEST(RssWall, AssembledMobilityEqualsTheSegmentBySegmentReference) {
  const Wall wall = TiltedWall();
  const Matrix3X a = Helix(Vec3(0, 0, 0.02), Vec3(1, 0, 0), 0.01, 0.05, 1.0, 21);
  const Matrix3X b = Helix(Vec3(0, 0.03, 0.03), Vec3(0, 1, 0.2).normalized(), 0.008, 0.04, 1.0, 17);
  const std::vector<HydroRod> rods = {{&a, 1e-3}, {&b, 8e-4}};
  const FluidParams params = WallParams(wall);
  MatX m;
  AssembleMobility(params, rods, &m);
  // Reference: every segment's StokesletSegmentNearWall at every node, densities f = F/Λ.
  const Eigen::Index total = TotalNodes(rods);
  MatX reference = MatX::Zero(3 * total, 3 * total);
  std::vector<Vec3> targets;
  for (const HydroRod& rod : rods)
    for (Eigen::Index i = 0; i < rod.x->cols(); ++i) targets.push_back(rod.x->col(i));
  for (Eigen::Index t = 0; t < total; ++t) {
    Eigen::Index first = 0;
    for (const HydroRod& rod : rods) {
      const VecX lengths = VoronoiLengths(*rod.x);
      for (Eigen::Index j = 0; j + 1 < rod.x->cols(); ++j) {
        const SegmentMobility s = StokesletSegmentNearWall(
            wall, rod.x->col(j), rod.x->col(j + 1), 1.02 * rod.radius, targets[static_cast<size_t>(t)]);
        reference.block<3, 3>(3 * t, 3 * (first + j)) += s.a / lengths(j);
        reference.block<3, 3>(3 * t, 3 * (first + j + 1)) += s.b / lengths(j + 1);
      }
      first += rod.x->cols();
    }
  }
  reference /= 8.0 * kPi * kMu;
  EXPECT_LT((m - reference).norm(), 1e-12 * reference.norm());
}

// The images to a tolerance (the Krylov path's far_field_tolerance): each pair by the fewest Gauss
// points whose WallImageRuleError meets it. The images' part (with the wall minus without, both at
// the same tolerance) against the round-off one, Frobenius, relative to it: below the tolerance.
TEST(RssWall, ImagesToATolerance) {
  const Wall wall = TiltedWall();
  const Matrix3X a = Helix(Vec3(0, 0, 0.02), Vec3(1, 0, 0), 0.01, 0.05, 1.0, 21);
  const Matrix3X b = Helix(Vec3(0, 0.03, 0.03), Vec3(0, 1, 0.2).normalized(), 0.008, 0.04, 1.0, 17);
  const std::vector<HydroRod> rods = {{&a, 1e-3}, {&b, 8e-4}};
  auto images = [&](double tolerance) {
    FluidParams params = WallParams(wall);
    params.far_field_tolerance = tolerance;
    MatX with, without;
    AssembleMobility(params, rods, &with);
    params.wall.reset();
    AssembleMobility(params, rods, &without);
    return MatX(with - without);
  };
  const MatX exact = images(0.0);
  for (const double tolerance : {1e-8, 1e-5}) {
    const double error = (images(tolerance) - exact).norm() / exact.norm();
    std::printf("  tolerance %.0e: images' relative error %.2e\n", tolerance, error);
    EXPECT_LT(error, tolerance);
    EXPECT_GT(error, 0.0);  // fewer points were taken
  }
}

TEST(RssWall, TheSolvedFlowVanishesOnTheWall) {
  const Wall wall = TiltedWall();
  const Matrix3X x = Helix(Vec3(0, 0, 0.0), Vec3(1, 0, 0), 0.01, 0.05, 2.0, 41);
  const std::vector<HydroRod> rods = {{&x, 1e-3}};
  const FluidParams params = WallParams(wall);
  MatX m;
  AssembleMobility(params, rods, &m);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  VecX velocity(m.rows());
  for (Eigen::Index i = 0; i < velocity.size(); ++i) velocity(i) = u(rng);
  const VecX forces = m.partialPivLu().solve(velocity);
  // No slip at the rod's nodes (what was solved) and on the wall (what the images give).
  EXPECT_LT((FluidVelocityAt(params, rods, forces, x.col(7)) - velocity.segment<3>(21)).norm(), 1e-10);
  const Vec3 t1 = wall.normal.unitOrthogonal(), t2 = wall.normal.cross(t1);
  double worst = 0.0, nearby = 0.0;
  for (int k = 0; k < 50; ++k) {
    const Vec3 on_wall = wall.point + 0.1 * u(rng) * t1 + 0.1 * u(rng) * t2;
    worst = std::max(worst, FluidVelocityAt(params, rods, forces, on_wall).norm());
    nearby = std::max(nearby, FluidVelocityAt(params, rods, forces, on_wall + 0.01 * wall.normal).norm());
  }
  std::printf("flow on the wall: max |u| = %.2e m/s; 1 cm above it: %.2e m/s\n", worst, nearby);
  EXPECT_LT(worst, 1e-12 * velocity.lpNorm<Eigen::Infinity>());
  EXPECT_GT(nearby, 1e-3 * velocity.lpNorm<Eigen::Infinity>());  // the flow itself is not zero
}

// The velocity (U, Ω) of a rigid helix spun at ω about its axis `axis` through `center`, free to
// move otherwise (no force, no torque across the axis): 𝕄 F = G V, (F, T) = Gᵀ F.
Vec6 SpunHelixVelocity(const FluidParams& params, const Matrix3X& x, double radius,
                       const Vec3& center, const Vec3& axis, double omega) {
  const std::vector<HydroRod> rods = {{&x, radius}};
  MatX m;
  AssembleMobility(params, rods, &m);
  MatX g(3 * x.cols(), 6);
  for (Eigen::Index i = 0; i < x.cols(); ++i)
    for (int c = 0; c < 3; ++c) {
      g.block<3, 1>(3 * i, c) = Vec3::Unit(c);
      g.block<3, 1>(3 * i, 3 + c) = Vec3::Unit(c).cross(Vec3(x.col(i) - center));
    }
  const Mat6 resistance = g.transpose() * m.partialPivLu().solve(g);
  // Unknowns: U (3) and the two angular velocities across the axis; Ω = ω a + β1 b1 + β2 b2.
  const Vec3 b1 = axis.unitOrthogonal(), b2 = axis.cross(b1);
  Eigen::Matrix<double, 6, 5> basis = Eigen::Matrix<double, 6, 5>::Zero();
  basis.topLeftCorner<3, 3>().setIdentity();
  basis.block<3, 1>(3, 3) = b1;
  basis.block<3, 1>(3, 4) = b2;
  Vec6 spin = Vec6::Zero();
  spin.tail<3>() = omega * axis;
  // The conditions: F = 0 and T · b1 = T · b2 = 0.
  Eigen::Matrix<double, 5, 6> rows = Eigen::Matrix<double, 5, 6>::Zero();
  rows.topLeftCorner<3, 3>().setIdentity();
  rows.block<1, 3>(3, 3) = b1.transpose();
  rows.block<1, 3>(4, 3) = b2.transpose();
  const Eigen::Matrix<double, 5, 5> a = rows * resistance * basis;
  const Eigen::Matrix<double, 5, 1> free = a.partialPivLu().solve(-rows * resistance * spin);
  return spin + basis * free;
}

// The sideways velocity (along y) of a 2-turn helix spun at ω = 1 rad/s about its axis +x through
// (0, 0, height), averaged over its phase about the axis (8 phases: the velocity of a finite
// helix at one instant depends on where its ends point) [m/s]. `params` with or without a wall.
double MeanSidewaysVelocity(const FluidParams& params, double height) {
  const double radius = 0.01, pitch = 0.05, r0 = 5e-4;
  const Vec3 axis = Vec3::UnitX(), center(0.0, 0.0, height);
  double sum = 0.0;
  constexpr int kPhases = 8;
  for (int p = 0; p < kPhases; ++p) {
    const Matrix3X x = Helix(center, axis, radius, pitch, 2.0, 81, 2.0 * kPi * p / kPhases);
    sum += SpunHelixVelocity(params, x, r0, center, axis, 1.0)(1);
  }
  return sum / kPhases;
}

// A helix spun about its axis parallel to a wall rolls along the wall: the part nearer the wall
// meets more resistance, so the fluid pushes it the way a wheel would roll (Lauga, DiLuzio,
// Whitesides & Stone 2006, Biophys J 90:400, their Fig. 2: the circling of E. coli near
// surfaces). Axis +x at height H above the wall z = 0, ω = +1 rad/s: rolling is −y.
TEST(RssWall, ASpunHelixNearAWallDriftsTheWayItWouldRoll) {
  FluidParams free_space = WallParams(Wall{});
  free_space.wall.reset();
  const double unbounded = MeanSidewaysVelocity(free_space, 0.0);
  std::printf("no wall: mean sideways velocity %.3e m/s\n", unbounded);
  EXPECT_LT(std::abs(unbounded), 1e-12);  // by symmetry, over the phases
  double previous = 0.0;
  for (double height : {0.08, 0.04, 0.02, 0.015}) {  // [m], axis above the wall
    const double drift = MeanSidewaysVelocity(WallParams(Wall{}), height);
    std::printf("H/R = %.1f: mean sideways drift %.3e m/s = %.3e ωR\n", height / 0.01, drift,
                drift / 0.01);
    EXPECT_LT(drift, 0.0) << "H = " << height;       // the rolling direction, −y
    EXPECT_LT(drift, previous) << "H = " << height;  // and growing as the wall nears
    previous = drift;
  }
}

}  // namespace
}  // namespace stokesrods
