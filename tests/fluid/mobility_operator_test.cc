// The matrix-free RSS operator (exact near pairs minus the far sum's Gauss rule, vectorized rows
// of rss_rows.h; Gauss far field by the direct sum or the FMM) against the dense reference 𝕄
// (rss.h at round-off), product by product, on geometries with near pairs within and between
// rods: two helices 3R apart, a straight rod lying across a helix 0.6 mm off its surface, and
// helices with coarse (5-node) and fine (195-node) discretizations side by side.
#include <algorithm>
#include "stokesrods/fluid/mobility_operator.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include <Eigen/Geometry>

#include "common/product_error.h"
#include "stokesrods/fluid/rss.h"
#include "stokesrods/rod/geometry.h"

namespace stokesrods {
namespace {

// max over random forces of |𝕄_mf F − 𝕄 F|_∞ / |𝕄 F|_∞.
double WorstRodsProductError(const std::vector<HydroRod>& rods, const MobilityOptions& options) {
  FluidParams exact;  // round-off
  MatX dense;
  AssembleRssMobility(exact, rods, &dense);
  FluidParams params;
  params.far_field_tolerance = options.tolerance;
  const auto op = MakeMobilityOperator(params, options);
  op->Update(rods);
  return WorstProductError(*op, dense, 7);
}

struct Geometry {
  std::vector<Matrix3X> x;
  std::vector<double> radius;
  std::vector<HydroRod> Rods() const {
    std::vector<HydroRod> rods;
    for (std::size_t r = 0; r < x.size(); ++r) rods.push_back({&x[r], radius[r]});
    return rods;
  }
};

Geometry CloseRods() {
  Geometry g;
  g.x.push_back(HelixNodes(HelixGeometry{}));
  HelixGeometry shifted;
  shifted.base = Vec3(0.03, 0.0, 0.0);
  g.x.push_back(HelixNodes(shifted));
  Matrix3X across = StraightNodes(40, 0.1, Vec3(-0.05, 0.0, 0.0));
  across = (Eigen::AngleAxisd(0.5 * kPi, Vec3::UnitY()).toRotationMatrix() * across).eval();
  across.colwise() += Vec3(0.0, g.x[0](1, 10) + 0.0026, g.x[0](2, 10));
  g.x.push_back(across);
  HelixGeometry coarse;
  coarse.nodes = 5;
  coarse.base = Vec3(0.0, 0.03, 0.0);
  g.x.push_back(HelixNodes(coarse));
  HelixGeometry fine;
  fine.nodes = 195;
  fine.base = Vec3(0.03, 0.03, 0.0);
  g.x.push_back(HelixNodes(fine));
  g.radius = {1e-3, 1e-3, 2e-3, 1e-3, 1e-3};
  return g;
}

// Direct far sum: the far field's accuracy max(tolerance, fast_sum_tolerance) bounds each pair;
// the measured product error is 1.3e-10 at 1e-8, 1.7e-7 at 1e-5 (relative, ∞-norm) and 2.9e-6
// at the defaults (1e-8, 1e-4: two Gauss points, the sum in single precision); allowed: 10 × it.
TEST(MatrixFreeMobility, MatchesTheDenseOperatorWithTheDirectSum) {
  const Geometry g = CloseRods();
  const MobilityOptions defaults;
  for (const double tolerance : {1e-8, 1e-5, defaults.fast_sum_tolerance}) {
    const MobilityOptions options = DirectSumOptions(tolerance);
    const double error = WorstRodsProductError(g.Rods(), options);
    std::printf("  direct far sum, tolerance %.0e: product error %.2e\n", tolerance, error);
    EXPECT_LT(error, 10.0 * tolerance);
  }
}

// The FMM far sum forced on (fast_sum_tolerance 1e-4 → p = 4; the split then takes 1e-4 too):
// measured 3.3e-4 relative in the ∞-norm (the FMM's own error is 3–6e-5 relative per node to
// Σ|S||g|, a larger normalizer); allowed 1e-3.
TEST(MatrixFreeMobility, MatchesTheDenseOperatorWithTheFmm) {
  const Geometry g = CloseRods();
  MobilityOptions options;
  options.kind = MobilityKind::kMatrixFree;
  options.direct_sum_below = 0.0;
  options.fast_sum_by_cost = false;
  const double error = WorstRodsProductError(g.Rods(), options);
  std::printf("  FMM far sum (p = 4): product error %.2e\n", error);
  EXPECT_LT(error, 1e-3);
}

// Ten of the paper's helices on a ring, neighbours `spacing` helix radii apart (the bench's ring10
// at 3).
Geometry HelixRing(double spacing) {
  Geometry g;
  const HelixGeometry helix;
  const double ring = spacing * helix.helix_radius / (2.0 * std::sin(kPi / 10.0));
  for (int k = 0; k < 10; ++k) {
    HelixGeometry placed = helix;
    placed.base = ring * Vec3(std::cos(2.0 * kPi * k / 10.0), std::sin(2.0 * kPi * k / 10.0), 0.0);
    g.x.push_back(HelixNodes(placed));
    g.radius.push_back(1e-3);
  }
  return g;
}

// The split with one more Gauss point and its smaller near zone (3 points, δ = 1.72 at 1e-4)
// against the fewest points (2, δ = 5.77): both within the far field's accuracy of the dense 𝕄.
TEST(MatrixFreeMobility, BothSplitsOfTheCostModelMatchTheDenseOperator) {
  const Geometry g = CloseRods();
  for (const double max_delta : {12.0, 2.0}) {
    MobilityOptions options = DirectSumOptions(MobilityOptions{}.fast_sum_tolerance);
    options.split_by_cost = false;
    options.fast_sum_near_delta = max_delta;
    const double error = WorstRodsProductError(g.Rods(), options);
    std::printf("  largest near radius %.0f: product error %.2e\n", max_delta, error);
    EXPECT_LT(error, 10.0 * options.fast_sum_tolerance);
  }
}

// The cost model (mobility_operator.cc) takes 3 points where many near pairs between rods make
// the 2-point rule's large near zone expensive (helices 3R apart on a ring: 17 250 near blocks
// against 3 190) and 2 points where the rods are apart (8R: mostly each rod's own near pairs), with
// 3 points on every rod (far_rule_by_distance off; with it, 3 points cost less at 8R too: the
// next test). It decides at the first Update and again only after ForgetHistory (a restart
// point).
TEST(MatrixFreeMobility, TheSplitIsChosenByCostAtTheFirstUpdateAndAtRestartPoints) {
  const Geometry close = HelixRing(3.0), apart = HelixRing(8.0);
  MobilityOptions options;
  options.kind = MobilityKind::kMatrixFree;
  options.far_rule_by_distance = false;
  const auto op = MakeMobilityOperator(FluidParams{}, options);
  op->Update(close.Rods());
  EXPECT_EQ(op->cost_counts().gauss_points, 3);
  op->Update(apart.Rods());
  EXPECT_EQ(op->cost_counts().gauss_points, 3);  // not a restart point: kept
  op->ForgetHistory();
  op->Update(apart.Rods());
  EXPECT_EQ(op->cost_counts().gauss_points, 2);
  // The chosen split is as accurate as the fixed ones.
  EXPECT_LT(WorstRodsProductError(close.Rods(), options), 10.0 * options.fast_sum_tolerance);
}

// The far rule by distance (fluid/far_rule_sum.h): on the ring 3R apart (3 points) and 8R apart,
// the chunks far from a group of targets take fewer points: fewer kernel evaluations (measured at
// 1e-4, 3 points: 0.80 of 3 points everywhere at 3R, 0.71 at 8R; at 1e-8, 6 points, the sum in
// double, rules 2 … 6: 0.68 and 0.57), the products as close to the dense 𝕄 as with n points
// everywhere (1.5e-6 / 1.7e-6 against 2.3e-6 / 2.1e-6 at 1e-4; 7.6e-11 / 5.6e-11 against 3.7e-11
// at 1e-8; allowed 10 × the tolerance, as above), and the two operators within the far field's
// accuracy of each other (2.1e-6, 3.0e-6; 7.3e-11, 6.1e-11).
TEST(MatrixFreeMobility, FewerPointsOnFarChunksKeepTheAccuracy) {
  for (const double spacing : {3.0, 8.0}) {
    const Geometry g = HelixRing(spacing);
    for (const double tolerance : {MobilityOptions{}.fast_sum_tolerance, 1e-8}) {
      MobilityOptions uniform = DirectSumOptions(tolerance);
      uniform.split_by_cost = false;
      uniform.fast_sum_near_delta = 2.0;  // 3 points at 1e-4
      uniform.far_rule_by_distance = false;
      MobilityOptions by_distance = uniform;
      by_distance.far_rule_by_distance = true;
      FluidParams params;
      params.far_field_tolerance = tolerance;
      const auto a = MakeMobilityOperator(params, uniform);
      const auto b = MakeMobilityOperator(params, by_distance);
      a->Update(g.Rods());
      b->Update(g.Rods());
      ASSERT_GT(a->cost_counts().gauss_points, 2);
      ASSERT_EQ(a->cost_counts().gauss_points, b->cost_counts().gauss_points);
      const double ratio = b->cost_counts().far_sum_cost / a->cost_counts().far_sum_cost;
      const double error = WorstRodsProductError(g.Rods(), by_distance);
      const double error_uniform = WorstRodsProductError(g.Rods(), uniform);
      // The two operators against each other.
      std::mt19937 rng(4);
      std::normal_distribution<double> normal;
      double worst = 0.0;
      for (int trial = 0; trial < 5; ++trial) {
        VecX f(a->size());
        for (Eigen::Index k = 0; k < f.size(); ++k) f(k) = normal(rng);
        VecX ua, ub;
        a->Apply(f, &ua);
        b->Apply(f, &ub);
        worst = std::max(worst, (ub - ua).cwiseAbs().maxCoeff() / ua.cwiseAbs().maxCoeff());
      }
      std::printf("  ring %.0fR, tolerance %.0e, %d points: far pairs %.2f of uniform, product "
                  "error %.2e (uniform %.2e), between them %.2e\n",
                  spacing, tolerance, a->cost_counts().gauss_points, ratio, error, error_uniform,
                  worst);
      EXPECT_LT(ratio, 0.9);
      EXPECT_LT(error, 10.0 * tolerance);
      EXPECT_LT(worst, 10.0 * tolerance);
    }
  }
}

// The ring 3R apart with every helix turned by `angle` about its own axis (z).
Geometry TurnedRing(double angle) {
  Geometry g = HelixRing(3.0);
  for (Matrix3X& x : g.x) {
    const Vec3 base(x(0, 0) - HelixGeometry{}.helix_radius, x(1, 0), 0.0);
    x = ((Eigen::AngleAxisd(angle, Vec3::UnitZ()).toRotationMatrix() *
          (x.colwise() - base)).colwise() + base).eval();
  }
  return g;
}

// The near corrections reused across Updates (fluid/mobility_reuse.h on their values, at the
// reuse tolerance 1e-4): on the ring 3R apart turning as Fig. 1 does at h = 1 ms (1.6e-3 rad per
// Update), most Updates extrapolate (measured: 9 of 120 compute the blocks; the pattern of near
// pairs between the helices changes 5 times, and each change is taken into the history (REMAP):
// the targets whose near segments changed get their blocks at the held geometries; before
// REMAP each change restarted the history, and 29 of 120 computed them), and the products stay
// within the tolerance of the same operator computing them at every Update (relative 2-norm;
// the near blocks carry the largest part of each node's velocity, their error is measured and
// kept below 1e-4 relative in the Frobenius norm: allowed 1.5 × it, as the dense 𝕄's reuse).
// Where a helix jumps next to another (off the line the history extrapolates along: JUMPS) and
// after ForgetHistory (a restart point), the next Update computes them again: the products are
// then those of the operator without reuse, bit for bit.
TEST(MatrixFreeMobility, NearCorrectionsAreReusedWithinTheTolerance) {
  MobilityOptions options;
  options.kind = MobilityKind::kMatrixFree;
  MobilityOptions reused = options;
  reused.reuse_tolerance = 1e-4;
  const auto fresh = MakeMobilityOperator(FluidParams{}, options);
  const auto op = MakeMobilityOperator(FluidParams{}, reused);
  std::mt19937 rng(3);
  const int n = 3 * 10 * HelixGeometry{}.nodes;
  const VecX f = VecX::NullaryExpr(n, [&] { return std::uniform_real_distribution<double>(-1, 1)(rng); });
  double worst = 0.0;
  VecX u, u_fresh;
  for (int k = 0; k < 120; ++k) {
    const Geometry g = TurnedRing(1.6e-3 * k);
    fresh->Update(g.Rods());
    op->Update(g.Rods());
    fresh->Apply(f, &u_fresh);
    op->Apply(f, &u);
    worst = std::max(worst, (u - u_fresh).norm() / u_fresh.norm());
  }
  const MobilityReuseStats stats = op->reuse_stats();
  std::printf("  %ld of %ld Updates computed the near blocks, %ld pattern changes remapped; "
              "products within %.2e; largest measured %.2e\n",
              stats.assemblies, stats.updates, stats.remaps, worst, stats.largest_error);
  EXPECT_EQ(stats.updates, 120);
  EXPECT_GE(stats.remaps, 3);
  EXPECT_LT(stats.assemblies, 120 / 8);
  EXPECT_GT(worst, 0.0);
  EXPECT_LT(worst, 1.5e-4);
  EXPECT_LT(stats.largest_error, 1.5e-4);

  Geometry moved = TurnedRing(1.6e-3 * 120);
  moved.x[1].colwise() += 0.5 * (moved.x[0].col(0) - moved.x[1].col(0));  // new near pairs
  for (const bool forget : {false, true}) {
    if (forget) op->ForgetHistory(), fresh->ForgetHistory();
    const long before = op->reuse_stats().assemblies;
    fresh->Update(moved.Rods());
    op->Update(moved.Rods());
    fresh->Apply(f, &u_fresh);
    op->Apply(f, &u);
    EXPECT_EQ(op->reuse_stats().assemblies, before + 1) << "forget " << forget;
    EXPECT_EQ((u - u_fresh).cwiseAbs().maxCoeff(), 0.0) << "forget " << forget;
  }
}

}  // namespace
}  // namespace stokesrods
