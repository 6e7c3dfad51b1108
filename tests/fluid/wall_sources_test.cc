// The wall as sources behind the matrix-free operator (fluid/wall_sources.h): the images' rule
// error against its calibration, and the products against the dense mobility with the wall
// (AssembleMobility / AssembleBorderedMobility at round-off), rods alone and rods with bodies.
#include "stokesrods/fluid/wall_sources.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "common/product_error.h"
#include "stokesrods/fluid/mobility_sources.h"
#include "stokesrods/fluid/rigid_body.h"
#include "stokesrods/fluid/wall.h"
#include "stokesrods/rod/geometry.h"

namespace stokesrods {
namespace {

double Frobenius(const SegmentMobility& s) {
  return std::sqrt(s.a.squaredNorm() + s.b.squaredNorm());
}

// The n-point rule on the images of random segments (length 1, ε = 0.05 or 0.3, at heights up
// to δ*) at targets about δ* from the mirrored segment: worst relative error (Frobenius) over the
// pairs, which WallImageRuleError must bound (it is twice the calibration's worst case).
TEST(WallImages, RuleErrorIsBoundedByItsCalibration) {
  const Wall wall;  // z = 0
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> sym(-1.0, 1.0), unit(0.0, 1.0);
  for (int n = 2; n <= kWallImageRuleMaxPoints; ++n) {
    double worst = 0.0;  // error / bound
    for (const double delta : {1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0}) {
      for (int trial = 0; trial < 300; ++trial) {
        const double eps = trial % 2 ? 0.05 : 0.3;
        Vec3 dir(sym(rng), sym(rng), sym(rng));
        dir.normalize();
        const Vec3 xa(0.0, 0.0, 0.01 + unit(rng) * delta);
        Vec3 xb = xa + dir;
        if (xb.z() <= 0.005) xb.z() = 0.01 - xb.z();
        Vec3 mid = 0.5 * (xa + xb);
        mid.z() = -mid.z();
        Vec3 r(sym(rng), sym(rng), sym(rng));
        const Vec3 p = mid + delta * (0.9 + 0.2 * unit(rng)) * r.normalized();
        if (p.z() <= 0.0) continue;
        const double d = WallImageDelta(wall, xa, xb, eps, p);
        const SegmentMobility exact = StokesletSegmentWallImages(wall, xa, xb, eps, p);
        const SegmentMobility rule = StokesletSegmentWallImagesGauss(wall, xa, xb, eps, p, n);
        const double error =
            std::sqrt((rule.a - exact.a).squaredNorm() + (rule.b - exact.b).squaredNorm()) /
            Frobenius(exact);
        worst = std::max(worst, error / WallImageRuleError(n, d));
      }
    }
    std::printf("  %d points: worst error / bound %.2f\n", n, worst);
    EXPECT_LT(worst, 1.0);
    EXPECT_GT(worst, 0.1);  // the bound is not loose by more than 10x
  }
}

// Two helices beside the wall x = x_min − 1.5 mm (the first helix's rod surface 0.5 mm from it,
// about 0.1 segment lengths: targets near its mirror image), the second 3 helix radii out; with
// bodies, a free sphere (radius 8 mm, 3.5 mm from the wall) carrying the first helix and a fixed sphere beside the second.
struct Scene {
  std::vector<Matrix3X> x;
  std::vector<HydroRod> rods;
  std::vector<BodySurface> bodies;
  Wall wall;
};

Scene MakeScene(bool with_bodies) {
  Scene s;
  s.x.push_back(HelixNodes(HelixGeometry{}));
  HelixGeometry other;
  other.base = Vec3(0.03, 0.0, 0.0);
  s.x.push_back(HelixNodes(other));
  for (const Matrix3X& x : s.x) s.rods.push_back({&x, 1e-3});
  s.wall.point = Vec3(s.x[0].row(0).minCoeff() - 1.5e-3, 0.0, 0.0);
  s.wall.normal = Vec3::UnitX();
  if (with_bodies) {
    BodySurface cell = SphereSurface(Vec3(0.0, 0.0, 0.0081), 0.008, 200, 0.3);
    cell.free = true;
    cell.center = Vec3(0.0, 0.0, 0.0081);
    s.bodies.push_back(cell);
    BodySurface beside = SphereSurface(Vec3(0.06, 0.0, -0.1), 0.015, 150, 0.3);
    beside.center = Vec3(0.06, 0.0, -0.1);
    s.bodies.push_back(beside);
  }
  return s;
}

double WorstWallProductError(const Scene& s, const MobilityOptions& options) {
  FluidParams exact;  // round-off
  exact.wall = s.wall;
  MatX dense;
  if (s.bodies.empty())
    AssembleMobility(exact, s.rods, &dense);
  else
    dense = AssembleBorderedMobility(exact, s.rods, s.bodies);
  FluidParams free_space;
  free_space.far_field_tolerance = options.tolerance;
  std::unique_ptr<MobilityOperator> op = MakeMobilityOperator(free_space, options);
  if (!s.bodies.empty()) op = MakeMobilityWithBodySources(free_space, options, std::move(op));
  FluidParams params = free_space;
  params.wall = s.wall;
  op = MakeMobilityWithWallImages(params, options, std::move(op));
  op->UpdateWithBodies(s.rods, s.bodies);
  EXPECT_EQ(op->size(), dense.rows());
  // The self blocks with the images, exact.
  const MatX self = op->SelfBlock(0);
  const Eigen::Index n0 = self.rows();
  EXPECT_LT((self - dense.topLeftCorner(n0, n0)).norm(), 1e-10 * self.norm());
  return WorstProductError(*op, dense, 5);
}

// As the free operator (mobility_operator_test.cc): the far field's accuracy
// max(tolerance, fast_sum_tolerance) bounds each pair, images included; allowed 10 × it.
TEST(WallImages, MatrixFreeProductsMatchTheDenseMobility) {
  const MobilityOptions defaults;
  for (const bool with_bodies : {false, true}) {
    const Scene s = MakeScene(with_bodies);
    for (const double tolerance : {1e-8, 1e-5, defaults.fast_sum_tolerance}) {
      const double error = WorstWallProductError(s, DirectSumOptions(tolerance));
      std::printf("  %s, tolerance %.0e: product error %.2e\n",
                  with_bodies ? "rods + bodies" : "rods", tolerance, error);
      EXPECT_LT(error, 10.0 * tolerance);
    }
  }
}

// The scene needs the near part: at the first helix's node nearest the wall, the images of its
// own segments by the far rule alone miss by far more than the tolerances above.
TEST(WallImages, TheSceneHasNearImagePairs) {
  const Scene s = MakeScene(false);
  const Matrix3X& x = s.x[0];
  Eigen::Index i = 0;
  x.row(0).minCoeff(&i);
  const Eigen::Index j = std::min<Eigen::Index>(i, x.cols() - 2);
  const double eps = FluidParams{}.regularization * 1e-3;
  for (const double tolerance : {1e-8, 1e-4}) {
    const NearFarSplit split = ChooseWallImageSplit(tolerance);
    const SegmentMobility exact = StokesletSegmentWallImages(s.wall, x.col(j), x.col(j + 1), eps, x.col(i));
    const SegmentMobility rule =
        StokesletSegmentWallImagesGauss(s.wall, x.col(j), x.col(j + 1), eps, x.col(i), split.gauss_points);
    const double error =
        std::sqrt((rule.a - exact.a).squaredNorm() + (rule.b - exact.b).squaredNorm()) / Frobenius(exact);
    std::printf("  tolerance %.0e: %d points, near radius %.2f, rule alone at the nearest pair %.2e\n",
                tolerance, split.gauss_points, split.near_delta, error);
    EXPECT_GT(error, 10.0 * tolerance);
  }
}

}  // namespace
}  // namespace stokesrods
