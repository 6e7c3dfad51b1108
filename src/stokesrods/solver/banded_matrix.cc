#include "stokesrods/solver/banded_matrix.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>

#include "stokesrods/common/assert.h"

namespace stokesrods {

void BandedMatrix::Resize(int size, int half_bandwidth) {
  n_ = size;
  kd_ = std::min(half_bandwidth, std::max(size - 1, 0));
  ldab_ = 3 * kd_ + 1;
  ab_.assign(static_cast<std::size_t>(ldab_) * n_, 0.0);
  pivots_.assign(n_, 0);
  factorized_ = false;
}

void BandedMatrix::SetZero() {
  std::fill(ab_.begin(), ab_.end(), 0.0);
  factorized_ = false;
}

void BandedMatrix::FixDof(int k) {
  for (int j = std::max(0, k - kd_); j <= std::min(n_ - 1, k + kd_); ++j) {
    (*this)(k, j) = 0.0;
    (*this)(j, k) = 0.0;
  }
  (*this)(k, k) = 1.0;
}

void BandedMatrix::MultiplyAdd(const VecX& x, VecX* y) const {
  SR_ASSERT(!factorized_, "MultiplyAdd on a factorized matrix");
  for (int j = 0; j < n_; ++j) {
    const int lo = std::max(0, j - kd_), hi = std::min(n_ - 1, j + kd_);
    for (int i = lo; i <= hi; ++i) (*y)(i) += (*this)(i, j) * x(j);
  }
}

MatX BandedMatrix::ToDense() const {
  MatX a = MatX::Zero(n_, n_);
  for (int j = 0; j < n_; ++j)
    for (int i = std::max(0, j - kd_); i <= std::min(n_ - 1, j + kd_); ++i) a(i, j) = (*this)(i, j);
  return a;
}

// LU with partial pivoting, the algorithm of LAPACK's dgbtf2 in its storage (U in rows 0..2kd
// with the fill of the row interchanges, the multipliers of L in rows 2kd+1..3kd). Written here
// rather than called: at half bandwidth 10 each of LAPACK's level-2 calls (idamax, dswap, dscal,
// dger per column; dtbsv and dger per solve) moves a few dozen numbers, and the call overhead
// was ~10× the arithmetic (callgrind: 270k instructions per solve of a 260-DOF rod against ~8k
// multiply–adds). Checked against a dense LU in tests/solver/banded_matrix_test.cc.
bool BandedMatrix::Factorize() {
  SR_ASSERT(!factorized_, "matrix factorized twice");
  factorized_ = true;
  const int kv = 2 * kd_;  // the row of the diagonal in the band storage
  // The fill region (kd < j − i ≤ 2kd) must start at zero.
  for (int j = kd_ + 1; j < n_; ++j)
    for (int i = std::max(0, j - kv); i < j - kd_; ++i) (*this)(i, j) = 0.0;
  bool regular = true;
  int last_column = 0;  // the last column the pivots so far reach
  for (int j = 0; j < n_; ++j) {
    const int below = std::min(kd_, n_ - 1 - j);
    double* column = &ab_[static_cast<std::size_t>(kv + j * ldab_)];  // column[i] = A(j + i, j)
    int p = 0;
    for (int i = 1; i <= below; ++i)
      if (std::abs(column[i]) > std::abs(column[p])) p = i;
    pivots_[static_cast<std::size_t>(j)] = j + p;
    if (column[p] == 0.0) {
      regular = false;
      continue;
    }
    last_column = std::max(last_column, std::min(j + kd_ + p, n_ - 1));
    if (p != 0)
      for (int c = j; c <= last_column; ++c) std::swap((*this)(j, c), (*this)(j + p, c));
    if (below == 0) continue;
    const double inverse_pivot = 1.0 / column[0];
    for (int i = 1; i <= below; ++i) column[i] *= inverse_pivot;
    for (int c = j + 1; c <= last_column; ++c) {
      double* target = &(*this)(j, c);  // target[i] = A(j + i, c)
      const double a_jc = target[0];
      if (a_jc == 0.0) continue;
      Eigen::Map<VecX>(target + 1, below) -= a_jc * Eigen::Map<const VecX>(column + 1, below);
    }
  }
  return regular;
}

void BandedMatrix::Solve(double* b, int num_rhs) const {
  SR_ASSERT(factorized_, "Solve before Factorize");
  if (num_rhs >= 4) {  // many right-hand sides: row by row, each row operation one long vector
    SolveManyRows(b, num_rhs);
    return;
  }
  const int kv = 2 * kd_;
  for (int k = 0; k < num_rhs; ++k) {
    double* x = b + static_cast<std::ptrdiff_t>(k) * n_;
    // L: the row interchanges and multipliers in the order they were made.
    for (int j = 0; j + 1 < n_; ++j) {
      const int p = pivots_[static_cast<std::size_t>(j)];
      if (p != j) std::swap(x[j], x[p]);
      const double xj = x[j];
      if (xj == 0.0) continue;
      const int below = std::min(kd_, n_ - 1 - j);
      const double* column = &ab_[static_cast<std::size_t>(kv + j * ldab_)];  // A(j + i, j)
      Eigen::Map<VecX>(x + j + 1, below) -= xj * Eigen::Map<const VecX>(column + 1, below);
    }
    // U: upper triangular with bandwidth 2kd, by columns from the last.
    for (int j = n_ - 1; j >= 0; --j) {
      const double* column = &ab_[static_cast<std::size_t>(j * ldab_)];  // A(j − kv + r, j)
      x[j] /= column[kv];
      const double xj = x[j];
      const int top = std::max(0, j - kv);
      Eigen::Map<VecX>(x + top, j - top) -= xj * Eigen::Map<const VecX>(column + kv + top - j, j - top);
    }
  }
}

void BandedMatrix::SolveManyRows(double* b, int num_rhs) const {
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  Eigen::Map<MatX> columns(b, n_, num_rhs);
  RowMajor x = columns;
  const int kv = 2 * kd_;
  for (int j = 0; j + 1 < n_; ++j) {
    const int p = pivots_[static_cast<std::size_t>(j)];
    if (p != j) x.row(j).swap(x.row(p));
    const double* column = &ab_[static_cast<std::size_t>(kv + j * ldab_)];
    for (int i = 1; i <= std::min(kd_, n_ - 1 - j); ++i)
      if (column[i] != 0.0) x.row(j + i) -= column[i] * x.row(j);
  }
  for (int j = n_ - 1; j >= 0; --j) {
    const double* column = &ab_[static_cast<std::size_t>(j * ldab_)];
    x.row(j) /= column[kv];
    for (int i = std::max(0, j - kv); i < j; ++i)
      if (column[kv + i - j] != 0.0) x.row(i) -= column[kv + i - j] * x.row(j);
  }
  columns = x;
}

}  // namespace stokesrods
