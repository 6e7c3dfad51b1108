// ThinSvd (LAPACK dgesdd) by the properties that define the SVD, on tall, wide, square and
// rank-deficient matrices; PseudoInverse by the four Moore–Penrose conditions; Eigenvalues
// (dgeev) on matrices whose eigenvalues are known.
#include "stokesrods/solver/dense_spectral.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <complex>
#include <random>
#include <vector>

namespace stokesrods {
namespace {

Eigen::MatrixXd Random(int m, int n, std::mt19937* rng) {
  std::normal_distribution<double> normal;
  Eigen::MatrixXd a(m, n);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < m; ++i) a(i, j) = normal(*rng);
  return a;
}

double Deviation(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).cwiseAbs().maxCoeff();
}

TEST(DenseSvd, FactorsAreOrthonormalOrderedAndReproduceTheMatrix) {
  std::mt19937 rng(5);
  for (const auto& [m, n] : {std::pair{7, 7}, std::pair{40, 9}, std::pair{9, 40},
                             std::pair{168, 168}, std::pair{1, 5}}) {
    const Eigen::MatrixXd a = Random(m, n, &rng);
    Eigen::MatrixXd u, v;
    Eigen::VectorXd s;
    ASSERT_TRUE(ThinSvd(a, &u, &s, &v));
    const int k = std::min(m, n);
    ASSERT_EQ(u.rows(), m);
    ASSERT_EQ(u.cols(), k);
    ASSERT_EQ(v.rows(), n);
    ASSERT_EQ(v.cols(), k);
    ASSERT_EQ(s.size(), k);
    const double scale = s[0];
    EXPECT_LT(Deviation(u * s.asDiagonal() * v.transpose(), a), 1e-13 * scale * k)
        << m << "×" << n;
    EXPECT_LT(Deviation(u.transpose() * u, Eigen::MatrixXd::Identity(k, k)), 1e-13 * k);
    EXPECT_LT(Deviation(v.transpose() * v, Eigen::MatrixXd::Identity(k, k)), 1e-13 * k);
    for (int i = 0; i < k; ++i) {
      EXPECT_GE(s[i], 0.0);
      if (i > 0) {
        EXPECT_LE(s[i], s[i - 1]);
      }
    }
  }
}

TEST(DenseSvd, SingularValuesOfAScaledPermutationAreItsEntriesSorted) {
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(4, 4);
  a(0, 2) = 3.0, a(1, 0) = -7.0, a(2, 3) = 0.5, a(3, 1) = 2.0;
  Eigen::MatrixXd u, v;
  Eigen::VectorXd s;
  ASSERT_TRUE(ThinSvd(a, &u, &s, &v));
  const Eigen::Vector4d expected(7.0, 3.0, 2.0, 0.5);
  EXPECT_LT((s - expected).cwiseAbs().maxCoeff(), 1e-14);
}

TEST(DenseSvd, PseudoInverseMeetsTheMoorePenroseConditions) {
  std::mt19937 rng(11);
  const Eigen::MatrixXd a = Random(12, 3, &rng) * Random(3, 8, &rng);  // rank 3
  const Eigen::MatrixXd p = PseudoInverse(a, 1e-12);
  ASSERT_EQ(p.rows(), 8);
  ASSERT_EQ(p.cols(), 12);
  const double norm = a.cwiseAbs().maxCoeff(), inverse_norm = p.cwiseAbs().maxCoeff();
  EXPECT_LT(Deviation(a * p * a, a), 1e-12 * norm);
  EXPECT_LT(Deviation(p * a * p, p), 1e-12 * inverse_norm);
  const Eigen::MatrixXd ap = a * p, pa = p * a;
  EXPECT_LT(Deviation(ap, ap.transpose()), 1e-12);
  EXPECT_LT(Deviation(pa, pa.transpose()), 1e-12);
  // Without the cutoff the three round-off singular values would be inverted: the result is
  // then far from the pseudo-inverse.
  EXPECT_GT(Deviation(PseudoInverse(a, 0.0), p), 1e3 * inverse_norm);
}

TEST(DenseSvd, InverseOfAnInvertibleMatrix) {
  std::mt19937 rng(3);
  const Eigen::MatrixXd a = Random(20, 20, &rng) + 10.0 * Eigen::MatrixXd::Identity(20, 20);
  EXPECT_LT(Deviation(PseudoInverse(a, 0.0) * a, Eigen::MatrixXd::Identity(20, 20)), 1e-13);
}

// Q diag(λ) Qᵀ with Q from the SVD of a random matrix: the λ back, in increasing order.
TEST(DenseSpectral, SymmetricEigenvaluesOfAMatrixBuiltFromThem) {
  std::mt19937 rng(13);
  Eigen::MatrixXd q, v;
  Eigen::VectorXd s;
  ASSERT_TRUE(ThinSvd(Random(9, 9, &rng), &q, &s, &v));
  Eigen::VectorXd lambda(9);
  lambda << 4.0, -2.0, 0.0, 1e-6, 7.5, -2.0, 3.0, -9.0, 0.5;
  const Eigen::MatrixXd a = q * lambda.asDiagonal() * q.transpose();
  const Eigen::VectorXd w = SymmetricEigenvalues(a);
  std::sort(lambda.begin(), lambda.end());
  ASSERT_EQ(w.size(), 9);
  EXPECT_LT((w - lambda).cwiseAbs().maxCoeff(), 1e-13 * 9.0);
}

// A block upper triangular matrix (1 × 1 and 2 × 2 diagonal blocks [[a, −b], [b, a]], whose
// eigenvalues are a ± ib; random entries above), its rows and columns permuted alike: the same
// eigenvalues, in a matrix no longer triangular.
TEST(DenseSpectral, EigenvaluesOfAPermutedQuasiTriangularMatrix) {
  std::mt19937 rng(7);
  const std::vector<std::complex<double>> expected = {
      {3.0, 0.0}, {-1.5, 0.0}, {0.25, 2.0}, {0.25, -2.0}, {-4.0, 0.5}, {-4.0, -0.5}, {1e-3, 0.0}};
  const int n = static_cast<int>(expected.size());
  Eigen::MatrixXd t = Eigen::MatrixXd::Zero(n, n);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < j; ++i) t(i, j) = uniform(rng);
  for (int i = 0; i < n; ++i) {
    if (expected[static_cast<size_t>(i)].imag() > 0.0) {  // a pair: the block at (i, i)
      const double a = expected[static_cast<size_t>(i)].real();
      const double b = expected[static_cast<size_t>(i)].imag();
      t(i, i) = a, t(i, i + 1) = -b, t(i + 1, i) = b, t(i + 1, i + 1) = a;
      ++i;
    } else {
      t(i, i) = expected[static_cast<size_t>(i)].real();
    }
  }
  const std::vector<int> order = {4, 0, 6, 2, 5, 1, 3};
  Eigen::MatrixXd a(n, n);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      a(i, j) = t(order[static_cast<size_t>(i)], order[static_cast<size_t>(j)]);
  const Eigen::VectorXcd lambda = Eigenvalues(a);
  ASSERT_EQ(lambda.size(), n);
  std::vector<bool> used(static_cast<size_t>(n), false);
  for (const std::complex<double>& e : expected) {  // each expected value matched once
    int best = -1;
    for (int k = 0; k < n; ++k)
      if (!used[static_cast<size_t>(k)] && (best < 0 || std::abs(lambda[k] - e) <
                                                             std::abs(lambda[best] - e)))
        best = k;
    used[static_cast<size_t>(best)] = true;
    EXPECT_LT(std::abs(lambda[best] - e), 1e-12) << e;
  }
}

}  // namespace
}  // namespace stokesrods
