#include "stokesrods/solver/banded_matrix.h"

#include <gtest/gtest.h>

#include <random>

namespace stokesrods {
namespace {

TEST(BandedMatrix, SolvesLikeADenseLuIncludingIndefiniteMatrices) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const int n = 57, kd = 10;
  BandedMatrix a(n, kd);
  for (int i = 0; i < n; ++i)
    for (int j = std::max(0, i - kd); j <= std::min(n - 1, i + kd); ++j) a(i, j) = u(rng);
  const MatX dense = a.ToDense();
  VecX b = VecX::Random(n);
  VecX y = VecX::Zero(n);
  a.MultiplyAdd(b, &y);
  EXPECT_LT((y - dense * b).norm(), 1e-13 * y.norm());
  ASSERT_TRUE(a.Factorize());
  VecX x = b;
  a.Solve(&x);
  EXPECT_LT((dense * x - b).norm(), 1e-10 * b.norm());
}

TEST(BandedMatrix, FixDofMakesAnIdentityRowAndColumn) {
  BandedMatrix a(5, 1);
  for (int i = 0; i < 5; ++i) a(i, i) = 2.0;
  for (int i = 0; i + 1 < 5; ++i) a(i, i + 1) = a(i + 1, i) = -1.0;
  a.FixDof(2);
  const MatX d = a.ToDense();
  EXPECT_EQ(d(2, 1), 0.0);
  EXPECT_EQ(d(1, 2), 0.0);
  EXPECT_EQ(d(2, 2), 1.0);
  EXPECT_EQ(d(3, 4), -1.0);
}

TEST(BandedMatrix, ReportsASingularMatrix) {
  BandedMatrix a(4, 1);
  EXPECT_FALSE(a.Factorize());
}

}  // namespace
}  // namespace stokesrods
