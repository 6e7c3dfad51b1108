// SolveGmres (solver/gmres.h) against a direct solve: its stopping tests, restarts, the product
// it returns from the Arnoldi relation, and the absolute test in the largest component.
#include "stokesrods/solver/gmres.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <Eigen/LU>

namespace stokesrods {
namespace {

// A nonsymmetric matrix with eigenvalues spread over [1, 10] and a random coupling: GMRES needs
// many iterations on it, so the stopping tests decide where it ends.
MatX SpreadMatrix(int n, std::mt19937* rng) {
  std::normal_distribution<double> normal;
  MatX a(n, n);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) a(i, j) = 0.3 * normal(*rng) / std::sqrt(static_cast<double>(n));
  for (int i = 0; i < n; ++i) a(i, i) += 1.0 + 9.0 * i / (n - 1);
  return a;
}

VecX RandomVector(int n, std::mt19937* rng) {
  std::normal_distribution<double> normal;
  VecX v(n);
  for (int i = 0; i < n; ++i) v(i) = normal(*rng);
  return v;
}

LinearOperator Product(const MatX& a) {
  return [&a](const VecX& x, VecX* y) { *y = a * x; };
}

TEST(Gmres, MeetsTheRelativeToleranceWithRestartsAndReturnsItsProduct) {
  std::mt19937 rng(3);
  const int n = 200;
  const MatX a = SpreadMatrix(n, &rng);
  const VecX b = RandomVector(n, &rng);
  // The inverse of the diagonal as a preconditioner, to check it is applied on the right.
  const VecX inverse_diagonal = a.diagonal().cwiseInverse();
  const LinearOperator jacobi = [&](const VecX& x, VecX* y) { *y = inverse_diagonal.cwiseProduct(x); };
  for (const int restart : {50, 5}) {
    for (const bool preconditioned : {false, true}) {
      VecX x, ax;
      const GmresReport report = SolveGmres(Product(a), preconditioned ? jacobi : LinearOperator{},
                                            b, {.tolerance = 1e-10, .restart = restart}, &x, &ax);
      ASSERT_TRUE(report.converged) << restart << " " << preconditioned;
      const double true_residual = (b - a * x).norm() / b.norm();
      EXPECT_LE(true_residual, 1e-10 * (1.0 + 1e-3)) << restart << " " << preconditioned;
      EXPECT_NEAR(report.relative_residual, true_residual, 1e-12);
      EXPECT_LT((ax - a * x).norm(), 1e-12 * b.norm());
      EXPECT_LT((x - a.partialPivLu().solve(b)).norm(), 1e-8 * x.norm());
    }
  }
}

TEST(Gmres, AbsoluteToleranceInTheLargestComponentStopsSoonerAndHoldsIt) {
  std::mt19937 rng(11);
  const int n = 400;
  const MatX a = SpreadMatrix(n, &rng);
  const VecX b = RandomVector(n, &rng);
  const double tolerance = 1e-6 * b.lpNorm<Eigen::Infinity>();
  VecX x_two, x_max;
  const GmresReport two = SolveGmres(Product(a), {}, b,
                                     {.tolerance = 1e-14, .absolute_tolerance = tolerance}, &x_two);
  const GmresReport max = SolveGmres(
      Product(a), {}, b,
      {.tolerance = 1e-14, .absolute_tolerance = tolerance, .absolute_in_max_norm = true}, &x_max);
  ASSERT_TRUE(two.converged);
  ASSERT_TRUE(max.converged);
  // Each holds its bound by a true product, not only by the Arnoldi estimate.
  EXPECT_LE((b - a * x_two).norm(), tolerance);
  EXPECT_LE((b - a * x_max).lpNorm<Eigen::Infinity>(), tolerance);
  // The 2-norm of a residual spread over 400 components is ~20 times its largest one's.
  EXPECT_LT(max.iterations, two.iterations);
  // Not so early that the 2-norm test would have been met as well.
  EXPECT_GT((b - a * x_max).norm(), tolerance);
}

// G x of the solution from the products' sides (a 120 × 200 G applied with A in each product):
// the same as G applied to the returned x, to rounding, across restarts and from a non-zero
// initial guess, and with one product per iteration (G never applied to x itself).
TEST(Gmres, GivesTheSideMapOfItsSolutionFromTheProducts) {
  std::mt19937 rng(5);
  const int n = 200;
  const MatX a = SpreadMatrix(n, &rng);
  const MatX g = MatX::Random(120, n);
  const VecX b = RandomVector(n, &rng);
  int products = 0;
  const LinearOperatorWithSide with_side = [&](const VecX& x, VecX* y, VecX* side) {
    *y = a * x;
    if (side) *side = g * x;
    ++products;
  };
  for (const int restart : {50, 4}) {
    for (const bool guess : {false, true}) {
      VecX x = guess ? VecX(RandomVector(n, &rng)) : VecX(), ax, gx;
      products = 0;
      const GmresReport report =
          SolveGmres(with_side, {}, b, {.tolerance = 1e-10, .restart = restart}, &x, &ax, &gx);
      ASSERT_TRUE(report.converged);
      EXPECT_EQ(products, report.iterations + (guess ? 1 : 0));
      ASSERT_EQ(gx.size(), 120);
      EXPECT_LT((gx - g * x).norm(), 1e-12 * (g * x).norm())
          << "restart " << restart << ", guess " << guess;
    }
  }
}

TEST(Gmres, ZeroRightHandSideGivesZero) {
  VecX x = VecX::Ones(3);
  const MatX a = MatX::Identity(3, 3);
  const GmresReport report = SolveGmres(Product(a), {}, VecX::Zero(3), {}, &x);
  EXPECT_TRUE(report.converged);
  EXPECT_EQ(report.iterations, 0);
  EXPECT_TRUE(x.isZero(0.0));
}

}  // namespace
}  // namespace stokesrods
