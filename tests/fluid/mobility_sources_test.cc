// Cell bodies as sources behind the matrix-free operator (fluid/mobility_sources.h) against the
// dense bordered mobility (AssembleBorderedMobility at round-off), product by product: two helices
// 3R apart, one clamped at the bottom of a free sphere, the other beside a fixed sphere, so that
// segments lie near body points (the near blocks) and far from them (the Gauss rule).
#include "stokesrods/fluid/mobility_sources.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>

#include "common/product_error.h"
#include "stokesrods/fluid/rigid_body.h"
#include "stokesrods/rod/geometry.h"
#include "stokesrods/solver/gmres.h"

namespace stokesrods {
namespace {

struct Scene {
  std::vector<Matrix3X> x;
  std::vector<HydroRod> rods;
  std::vector<BodySurface> bodies;
};

Scene MakeScene() {
  Scene s;
  s.x.push_back(HelixNodes(HelixGeometry{}));  // node 0 at the origin, the helix below it
  HelixGeometry other;
  other.base = Vec3(0.03, 0.0, 0.0);
  s.x.push_back(HelixNodes(other));
  for (const Matrix3X& x : s.x) s.rods.push_back({&x, 1e-3});
  BodySurface cell = SphereSurface(Vec3(0.0, 0.0, 0.0201), 0.02, 200, 0.3);
  cell.free = true;
  cell.center = Vec3(0.0, 0.0, 0.0201);
  s.bodies.push_back(cell);
  BodySurface beside = SphereSurface(Vec3(0.06, 0.0, -0.1), 0.015, 150, 0.3);
  beside.center = Vec3(0.06, 0.0, -0.1);
  s.bodies.push_back(beside);
  return s;
}

// max over random forces (and free-body motions) of |𝕄_mf f − 𝕄 f|_∞ / |𝕄 f|_∞.
double WorstSceneProductError(const MobilityOptions& options) {
  const Scene s = MakeScene();
  FluidParams exact;  // round-off
  exact.far_field_tolerance = 0.0;
  const MatX dense = AssembleBorderedMobility(exact, s.rods, s.bodies);
  FluidParams params;
  params.far_field_tolerance = options.tolerance;
  const auto op = MakeMobilityWithBodySources(params, options, MakeMobilityOperator(params, options));
  op->UpdateWithBodies(s.rods, s.bodies);
  EXPECT_EQ(op->size(), dense.rows());
  return WorstProductError(*op, dense, 11);
}

// As the rods' own matrix-free operator (mobility_operator_test.cc): the far field's accuracy
// max(tolerance, fast_sum_tolerance) bounds each pair; allowed 10 × it.
TEST(MobilityWithBodySources, MatchesTheDenseBorderedMobility) {
  const MobilityOptions defaults;
  for (const double tolerance : {1e-8, 1e-5, defaults.fast_sum_tolerance}) {
    const MobilityOptions options = DirectSumOptions(tolerance);
    const double error = WorstSceneProductError(options);
    std::printf("  tolerance %.0e: product error %.2e\n", tolerance, error);
    EXPECT_LT(error, 10.0 * tolerance);
  }
}

// The same with every point sum by the FMM (the tree forced, no direct fallback): the bodies'
// points are sources and targets of the rods' fast sum (rods' Gauss points and body points at
// the body points, body points at the rod nodes), at the bodies' default far field (1e-5, the
// sum in double: io/build_model.cc; measured 7.2e-6, 1.2e-10 at 1e-8); allowed 10 × it.
TEST(MobilityWithBodySources, MatchesTheDenseBorderedMobilityThroughTheFmm) {
  constexpr double kTolerance = 1e-5;
  MobilityOptions options = DirectSumOptions(kTolerance);
  options.direct_sum_below = 0.0;
  options.fast_sum_by_cost = false;
  const double error = WorstSceneProductError(options);
  std::printf("  FMM, tolerance %.0e: product error %.2e\n", kTolerance, error);
  EXPECT_LT(error, 10.0 * kTolerance);
}

// A whole solve with the operator: the free sphere pulled along z by 1 mN beside the two fixed
// helices and the fixed sphere (no slip on all of them), [𝕄 G; Gᵀ 0][f; V] = [0; −L], by GMRES
// with the matrix-free products (block-Jacobi preconditioner: each rod's self block, each body's
// bordered block) against the dense LU. V agrees to the products' accuracy: measured 2.4e-10
// relative at 1e-8, allowed 10 × the tolerance, as the products.
TEST(MobilityWithBodySources, SolvesTheSettlingSphereAsTheDenseOperator) {
  const Scene s = MakeScene();
  FluidParams exact;
  exact.far_field_tolerance = 0.0;
  const MatX dense = AssembleBorderedMobility(exact, s.rods, s.bodies);
  MobilityOptions options;
  options.kind = MobilityKind::kMatrixFree;
  options.fast_sum_tolerance = options.tolerance = 1e-8;
  options.direct_sum_below = 1e12;
  FluidParams params;
  params.far_field_tolerance = options.tolerance;
  const auto op = MakeMobilityWithBodySources(params, options, MakeMobilityOperator(params, options));
  op->UpdateWithBodies(s.rods, s.bodies);
  const Eigen::Index n = dense.rows();
  VecX b = VecX::Zero(n);
  b(n - 4) = -1e-3;  // the free sphere's z force row: Gᵀ f + L = 0
  const VecX reference = dense.partialPivLu().solve(b);
  // Blocks: rods' nodes, then each body's points (the free one with its six rows).
  std::vector<std::pair<Eigen::Index, Eigen::Index>> ranges;
  for (int r = 0; r < op->num_rods(); ++r)
    ranges.push_back({3 * op->node_offset(r), 3 * (op->node_offset(r + 1) - op->node_offset(r))});
  const Eigen::Index first_body = 3 * op->node_offset(op->num_rods());
  ranges.push_back({first_body, 3 * s.bodies[0].points.cols()});
  ranges.push_back({first_body + 3 * s.bodies[0].points.cols(), 3 * s.bodies[1].points.cols()});
  std::vector<Eigen::PartialPivLU<MatX>> blocks;
  for (const auto& [first, size] : ranges) blocks.emplace_back(dense.block(first, first, size, size));
  // The free body's block with its border rows and columns (its points and the last six).
  const Eigen::Index pts = 3 * s.bodies[0].points.cols();
  MatX bordered(pts + 6, pts + 6);
  std::vector<Eigen::Index> index;
  for (Eigen::Index k = 0; k < pts; ++k) index.push_back(first_body + k);
  for (Eigen::Index k = 0; k < 6; ++k) index.push_back(n - 6 + k);
  for (std::size_t i = 0; i < index.size(); ++i)
    for (std::size_t j = 0; j < index.size(); ++j) bordered(i, j) = dense(index[i], index[j]);
  const Eigen::PartialPivLU<MatX> free_block(bordered);
  const LinearOperator apply = [&](const VecX& x, VecX* y) { op->Apply(x, y); };
  const LinearOperator precondition = [&](const VecX& x, VecX* y) {
    *y = x;
    for (std::size_t k = 0; k + 2 < ranges.size(); ++k)
      y->segment(ranges[k].first, ranges[k].second) = blocks[k].solve(x.segment(ranges[k].first, ranges[k].second));
    y->segment(ranges.back().first, ranges.back().second) =
        blocks.back().solve(x.segment(ranges.back().first, ranges.back().second));
    VecX local(pts + 6);
    for (std::size_t i = 0; i < index.size(); ++i) local(static_cast<Eigen::Index>(i)) = x(index[i]);
    local = free_block.solve(local);
    for (std::size_t i = 0; i < index.size(); ++i) (*y)(index[i]) = local(static_cast<Eigen::Index>(i));
  };
  VecX solution = VecX::Zero(n);
  const GmresReport g = SolveGmres(apply, precondition, b, {.tolerance = 1e-12, .max_iterations = 400}, &solution);
  const Vec6 v = solution.tail<6>(), v_ref = reference.tail<6>();
  const double error = (v - v_ref).norm() / v_ref.norm();
  std::printf("  settling sphere: U_z = %.6e m/s (dense %.6e), relative error of V %.2e after %d "
              "GMRES products\n", v(2), v_ref(2), error, g.iterations);
  EXPECT_TRUE(g.converged);
  EXPECT_LT(error, 10.0 * options.tolerance);
  EXPECT_GT(v_ref(2), 0.0);  // it moves along the pull
}

}  // namespace
}  // namespace stokesrods
