#include "stokesrods/solver/banded_matrix.h"

#include <gtest/gtest.h>

#include <Eigen/LU>

#include <random>
#include <vector>

extern "C" {
void dgbtrf_(const int* m, const int* n, const int* kl, const int* ku, double* ab,
             const int* ldab, int* ipiv, int* info);
void dgbtrs_(const char* trans, const int* n, const int* kl, const int* ku, const int* nrhs,
             const double* ab, const int* ldab, const int* ipiv, double* b, const int* ldb,
             int* info, std::size_t trans_len);
}

namespace stokesrods {
namespace {

// LAPACK's banded LU of the same matrix: the reference our own factorization replaces.
MatX SolveWithLapack(const MatX& dense, int kd, const MatX& b) {
  const int n = static_cast<int>(dense.rows()), ldab = 3 * kd + 1, nrhs = static_cast<int>(b.cols());
  std::vector<double> ab(static_cast<std::size_t>(ldab) * n, 0.0);
  for (int j = 0; j < n; ++j)
    for (int i = std::max(0, j - kd); i <= std::min(n - 1, j + kd); ++i)
      ab[static_cast<std::size_t>(2 * kd + i - j + j * ldab)] = dense(i, j);
  std::vector<int> pivots(static_cast<std::size_t>(n));
  int info = 0;
  dgbtrf_(&n, &n, &kd, &kd, ab.data(), &ldab, pivots.data(), &info);
  EXPECT_EQ(info, 0);
  MatX x = b;
  const char trans = 'N';
  dgbtrs_(&trans, &n, &kd, &kd, &nrhs, ab.data(), &ldab, pivots.data(), x.data(), &n, &info, 1);
  return x;
}

// Random band entries; with `zero_diagonal` every diagonal entry is 0, so each column must pivot.
BandedMatrix RandomBanded(int n, int kd, bool zero_diagonal, std::mt19937* rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  BandedMatrix a(n, kd);
  const int k = a.half_bandwidth();
  for (int i = 0; i < n; ++i)
    for (int j = std::max(0, i - k); j <= std::min(n - 1, i + k); ++j)
      a(i, j) = (zero_diagonal && i == j) ? 0.0 : u(*rng);
  return a;
}

TEST(BandedMatrix, FactorsLikeLapackAndADenseLuForManySizesAndRightHandSides) {
  std::mt19937 rng(11);
  for (int n : {1, 2, 5, 10, 11, 12, 21, 40, 130}) {
    for (int kd : {1, 3, 10}) {
      for (bool zero_diagonal : {false, true}) {
        if (zero_diagonal && n == 1) continue;  // a 1×1 zero is singular
        BandedMatrix a = RandomBanded(n, kd, zero_diagonal, &rng);
        const MatX dense = a.ToDense();
        const Eigen::FullPivLU<MatX> reference(dense);
        if (reference.rank() < n) continue;
        const MatX b = MatX::Random(n, 7);  // 7 at once: the row-wise path; one by one below
        const MatX lapack = SolveWithLapack(dense, a.half_bandwidth(), b);
        ASSERT_TRUE(a.Factorize()) << "n = " << n << ", kd = " << kd;
        MatX x = b;
        a.Solve(&x);
        for (int k = 0; k < b.cols(); ++k) {
          VecX one = b.col(k);
          a.Solve(&one);
          EXPECT_LT((one - lapack.col(k)).norm(), 1e-9 * lapack.col(k).norm()) << "n = " << n;
        }
        const double scale = reference.solve(b).norm();
        // Same pivots, same operations up to their order: agreement near rounding, far below
        // the dense residual that would reveal a wrong factor.
        EXPECT_LT((x - lapack).norm(), 1e-9 * scale) << "n = " << n << ", kd = " << kd;
        EXPECT_LT((dense * x - b).norm(), 1e-10 * b.norm() * (1.0 + dense.norm() * scale))
            << "n = " << n << ", kd = " << kd;
      }
    }
  }
}

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

// A rod's Newton matrix at a time step is symmetric positive definite up to ~1e-6 of its
// largest entry (the mass term M/h² over the stiffness, the frame transport's asymmetry): this
// one, a positive definite band plus a 1e-6 asymmetry, is factorized without row interchanges,
// and solves as LAPACK's pivoted LU and the dense LU do.
TEST(BandedMatrix, FactorsAPositiveDefiniteMatrixWithoutPivoting) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (const int n : {1, 11, 259}) {
    const int kd = 10;
    BandedMatrix a(n, kd);
    const int k = a.half_bandwidth();
    for (int i = 0; i < n; ++i)
      for (int j = std::max(0, i - k); j < i; ++j) a(i, j) = a(j, i) = u(rng);
    for (int i = 0; i < n; ++i) a(i, i) = 2.0 * k + 1.0;  // diagonally dominant: definite
    for (int i = 0; i < n; ++i)
      for (int j = std::max(0, i - k); j <= std::min(n - 1, i + k); ++j) a(i, j) += 1e-6 * u(rng);
    const MatX dense = a.ToDense();
    const MatX b = MatX::Random(n, 5);
    const MatX lapack = SolveWithLapack(dense, k, b);
    ASSERT_TRUE(a.Factorize());
    EXPECT_FALSE(a.pivoted()) << "n = " << n;
    MatX x = b;
    a.Solve(&x);  // several right-hand sides at once
    VecX one = b.col(0);
    a.Solve(&one);
    EXPECT_LT((x - lapack).norm(), 1e-13 * lapack.norm()) << "n = " << n;
    EXPECT_LT((one - lapack.col(0)).norm(), 1e-13 * lapack.col(0).norm()) << "n = " << n;
    EXPECT_LT((dense * x - b).norm(), 1e-13 * b.norm()) << "n = " << n;
  }
}

// A definite band (diagonally dominant, slightly asymmetric): factorized without pivoting.
BandedMatrix DefiniteBanded(int n, int kd, std::mt19937* rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  BandedMatrix a(n, kd);
  const int k = a.half_bandwidth();
  for (int i = 0; i < n; ++i)
    for (int j = std::max(0, i - k); j <= std::min(n - 1, i + k); ++j)
      a(i, j) = i == j ? 2.0 * k + 1.0 : u(*rng);
  return a;
}

// SolveEach, two systems a row at a time where they match, against each matrix's own Solve: the
// same bits, whether the pair is pivoted or not, of the rods' bandwidth or another, of equal or
// different sizes (one after the other then), with an odd count (the last alone).
TEST(BandedMatrix, SolveEachGivesEachMatrixsOwnSolveBitForBit) {
  std::mt19937 rng(9);
  for (const int kd : {10, 3}) {
    for (const bool pivoted : {false, true}) {
      for (const std::vector<int>& sizes :
           std::vector<std::vector<int>>{{259, 259}, {259, 259, 259}, {259, 131}, {2, 2}}) {
        std::vector<BandedMatrix> matrices;
        for (const int n : sizes) {
          matrices.push_back(pivoted ? RandomBanded(n, kd, true, &rng)
                                     : DefiniteBanded(n, kd, &rng));
          ASSERT_TRUE(matrices.back().Factorize());
          ASSERT_EQ(matrices.back().pivoted(), pivoted);
        }
        std::vector<VecX> each, own;
        for (const int n : sizes) {
          each.push_back(VecX::Random(n));
          own.push_back(each.back());
        }
        each[0][0] = 0.0;  // a zero entry: the lower solve skips its column
        own[0][0] = 0.0;
        std::vector<const BandedMatrix*> pointers;
        std::vector<double*> rhs;
        for (std::size_t k = 0; k < sizes.size(); ++k) {
          pointers.push_back(&matrices[k]);
          rhs.push_back(each[k].data());
          matrices[k].Solve(&own[k]);
        }
        SolveEach(pointers.data(), rhs.data(), static_cast<int>(sizes.size()));
        for (std::size_t k = 0; k < sizes.size(); ++k)
          EXPECT_EQ(each[k], own[k]) << "kd " << kd << ", pivoted " << pivoted << ", system " << k;
      }
    }
  }
}

// Where elimination without interchanges meets a pivot that is not positive (an indefinite
// matrix: here a negative diagonal entry in row 40 of an otherwise definite one) or its factors
// grow (a positive definite symmetric part with a large skew part: [[1e-3, 1], [−1, 1]] grows
// U(1, 1) to 1001), the matrix is factorized again from its entries with partial pivoting and
// solves as the dense LU does.
TEST(BandedMatrix, FallsBackToPivotingWhereThePivotsAreNotPositiveOrGrow) {
  const int n = 60, kd = 3;
  BandedMatrix indefinite(n, kd);
  for (int i = 0; i < n; ++i) {
    indefinite(i, i) = i == 40 ? -3.0 : 4.0;
    if (i + 1 < n) indefinite(i, i + 1) = indefinite(i + 1, i) = -1.0;
  }
  BandedMatrix skew(2, 1);
  skew(0, 0) = 1e-3, skew(0, 1) = 1.0, skew(1, 0) = -1.0, skew(1, 1) = 1.0;
  for (BandedMatrix* a : {&indefinite, &skew}) {
    const MatX dense = a->ToDense();
    const VecX b = VecX::LinSpaced(a->size(), 1.0, 2.0);
    ASSERT_TRUE(a->Factorize());
    EXPECT_TRUE(a->pivoted()) << "size " << a->size();
    VecX x = b;
    a->Solve(&x);
    EXPECT_LT((x - dense.lu().solve(b)).norm(), 1e-13 * x.norm()) << "size " << a->size();
  }
}

// One matrix assembled and factorized again and again, as a rod's Newton matrix is at every
// step: nothing of an earlier factorization (the pivoting's fill rows, the kept copy of A) may
// leak into the next. Alternating matrices that need pivoting (zero diagonals), that do not
// (definite), and again, each solves bit for bit as a fresh matrix with the same entries does.
TEST(BandedMatrix, ReassembledAfterAPivotedFactorizationSolvesAsAFreshMatrix) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const int n = 64, kd = 10;
  BandedMatrix reused(n, kd);
  for (const bool pivot : {true, false, true, true, false, false, true}) {
    BandedMatrix fresh(n, kd);
    reused.SetZero();
    for (int i = 0; i < n; ++i)
      for (int j = std::max(0, i - kd); j <= std::min(n - 1, i + kd); ++j) {
        const double v = i == j ? (pivot ? 0.0 : 2.0 * kd + 1.0) : u(rng);
        reused(i, j) = fresh(i, j) = v;
      }
    ASSERT_TRUE(reused.Factorize());
    ASSERT_TRUE(fresh.Factorize());
    EXPECT_EQ(reused.pivoted(), pivot);
    VecX x = VecX::LinSpaced(n, 1.0, 2.0), y = x;
    reused.Solve(&x);
    fresh.Solve(&y);
    for (int i = 0; i < n; ++i) EXPECT_EQ(x(i), y(i)) << "pivoting " << pivot << ", entry " << i;
  }
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
