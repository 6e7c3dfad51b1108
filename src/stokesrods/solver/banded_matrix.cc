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

namespace {

// The kernels below work on LAPACK's band storage (see the header): A(i, j) at
// ab[(2kd + i − j) + j·ldab], ldab = 3kd + 1. Each is a template over the half bandwidth, KD > 0
// fixed at compile time (the rods' 10: every inner loop a fixed trip count, unrolled and
// vectorized) or KD = 0 taken from `kd` at run time, inlined into functions cloned for AVX-512,
// AVX2 and the baseline (the build targets baseline x86-64; the loader picks the clone).
// Rows with fewer than KD entries below the diagonal (the last KD) take the run-time loops.

// y[0, count) −= a · x[0, count), with count = KD when the column is whole.
template <int KD>
inline __attribute__((always_inline)) void Axpy(int count, double a, const double* x, double* y) {
  if (KD > 0 && count == KD) {
#pragma omp simd
    for (int i = 0; i < KD; ++i) y[i] -= a * x[i];
  } else {
#pragma omp simd
    for (int i = 0; i < count; ++i) y[i] -= a * x[i];
  }
}

// LU with partial pivoting, the algorithm of LAPACK's dgbtf2 in its storage (U in rows 0..2kd
// with the fill of the row interchanges, the multipliers of L in rows 2kd+1..3kd).
template <int KD>
inline __attribute__((always_inline)) bool FactorizeBand(int n, int kd_runtime, double* ab,
                                                         int* pivots) {
  const int kd = KD > 0 ? KD : kd_runtime, kv = 2 * kd, ldab = 3 * kd + 1;
  auto at = [&](int i, int j) -> double& {
    return ab[(kv + i - j) + static_cast<std::ptrdiff_t>(j) * ldab];
  };
  // The fill region (kd < j − i ≤ 2kd) must start at zero.
  for (int j = kd + 1; j < n; ++j)
    for (int i = std::max(0, j - kv); i < j - kd; ++i) at(i, j) = 0.0;
  bool regular = true;
  int last_column = 0;  // the last column the pivots so far reach
  for (int j = 0; j < n; ++j) {
    const int below = std::min(kd, n - 1 - j);
    double* column = &at(j, j);  // column[i] = A(j + i, j)
    int p = 0;
    for (int i = 1; i <= below; ++i)
      if (std::abs(column[i]) > std::abs(column[p])) p = i;
    pivots[j] = j + p;
    if (column[p] == 0.0) {
      regular = false;
      continue;
    }
    last_column = std::max(last_column, std::min(j + kd + p, n - 1));
    if (p != 0)
      for (int c = j; c <= last_column; ++c) std::swap(at(j, c), at(j + p, c));
    if (below == 0) continue;
    const double inverse_pivot = 1.0 / column[0];
    for (int i = 1; i <= below; ++i) column[i] *= inverse_pivot;
    for (int c = j + 1; c <= last_column; ++c) {
      double* target = &at(j, c);  // target[i] = A(j + i, c)
      if (target[0] != 0.0) Axpy<KD>(below, target[0], column + 1, target + 1);
    }
  }
  return regular;
}

// LU without row interchanges, in the same storage (U in rows kd..2kd, L below; the fill rows
// unused): false as soon as a pivot is not positive or an entry of U grows past twice the largest
// entry of A (`largest`), where the caller factorizes again with pivoting. Positive pivots are
// those of a matrix whose symmetric part is positive definite, as the rods' Newton matrices
// are at time steps where the mass term M/h² dominates (asymmetric by ~1e-6 of their largest
// entry, the frame transport's): elimination without pivoting is then stable, its growth
// bounded by the asymmetry (Golub and Van Loan, "Unsymmetric positive definite linear systems",
// 1979), and the growth is checked anyway. Half the work of the pivoted LU (no fill beyond kd,
// no row swaps), and a U of bandwidth kd for the solves.
template <int KD>
inline __attribute__((always_inline)) bool FactorizeBandUnpivoted(int n, int kd_runtime,
                                                                  double* ab, double largest) {
  const int kd = KD > 0 ? KD : kd_runtime, kv = 2 * kd, ldab = 3 * kd + 1;
  auto at = [&](int i, int j) -> double& {
    return ab[(kv + i - j) + static_cast<std::ptrdiff_t>(j) * ldab];
  };
  const double limit = 2.0 * largest;
  for (int j = 0; j < n; ++j) {
    const int below = std::min(kd, n - 1 - j);
    double* column = &at(j, j);  // column[i] = A(j + i, j)
    if (!(column[0] > 0.0)) return false;
    const double inverse_pivot = 1.0 / column[0];
    for (int i = 1; i <= below; ++i) column[i] *= inverse_pivot;
    for (int c = j + 1; c <= j + below; ++c) {  // the columns row j of U reaches
      double* target = &at(j, c);  // target[i] = A(j + i, c)
      if (!(std::abs(target[0]) <= limit)) return false;
      if (target[0] != 0.0) Axpy<KD>(below, target[0], column + 1, target + 1);
    }
    if (!(column[0] <= limit)) return false;
  }
  return true;
}

// One right-hand side x (n) in place; `inverse_diagonal` holds 1/U(j, j) (a multiplication in
// the chain of dependent updates instead of a division, which took half the solve's time).
// U's bandwidth is 2kd after pivoting, kd without (`KU` = 2 KD or KD; 0 with KD = 0: from
// `pivoted` at run time).
template <int KD, int KU>
inline __attribute__((always_inline)) void SolveBand(int n, int kd_runtime, bool pivoted,
                                                     const double* ab, const int* pivots,
                                                     const double* inverse_diagonal, double* x) {
  const int kd = KD > 0 ? KD : kd_runtime, kv = 2 * kd, ldab = 3 * kd + 1;
  const int ku = KU > 0 ? KU : (pivoted ? kv : kd);
  // L: the row interchanges and multipliers in the order they were made.
  for (int j = 0; j + 1 < n; ++j) {
    const int p = pivots[j];
    if (p != j) std::swap(x[j], x[p]);
    if (x[j] == 0.0) continue;
    const double* column = ab + kv + static_cast<std::ptrdiff_t>(j) * ldab;  // A(j + i, j)
    Axpy<KD>(std::min(kd, n - 1 - j), x[j], column + 1, x + j + 1);
  }
  // U: upper triangular with bandwidth 2kd, by columns from the last.
  for (int j = n - 1; j >= 0; --j) {
    const double* column = ab + static_cast<std::ptrdiff_t>(j) * ldab;  // A(j − kv + r, j)
    x[j] *= inverse_diagonal[j];
    const int top = std::max(0, j - ku);
    Axpy<KU>(j - top, x[j], column + kv + top - j, x + top);
  }
}

// Two systems of the same size, bandwidth and pivoting, one right-hand side each, row by row in
// turn: each system's operations exactly as SolveBand's (the same bits), but two independent
// chains of dependent updates for the CPU to overlap, where one solve after the other leaves it
// waiting on each row's update of the next.
template <int KD, int KU>
inline __attribute__((always_inline)) void SolveBandPair(int n, int kd_runtime, bool pivoted,
                                                         const double* ab_a, const int* pivots_a,
                                                         const double* inverse_diagonal_a,
                                                         double* x_a, const double* ab_b,
                                                         const int* pivots_b,
                                                         const double* inverse_diagonal_b,
                                                         double* x_b) {
  const int kd = KD > 0 ? KD : kd_runtime, kv = 2 * kd, ldab = 3 * kd + 1;
  const int ku = KU > 0 ? KU : (pivoted ? kv : kd);
  auto lower = [&](int j, const double* ab, const int* pivots, double* x) {
    const int p = pivots[j];
    if (p != j) std::swap(x[j], x[p]);
    if (x[j] == 0.0) return;
    const double* column = ab + kv + static_cast<std::ptrdiff_t>(j) * ldab;
    Axpy<KD>(std::min(kd, n - 1 - j), x[j], column + 1, x + j + 1);
  };
  auto upper = [&](int j, const double* ab, const double* inverse_diagonal, double* x) {
    const double* column = ab + static_cast<std::ptrdiff_t>(j) * ldab;
    x[j] *= inverse_diagonal[j];
    const int top = std::max(0, j - ku);
    Axpy<KU>(j - top, x[j], column + kv + top - j, x + top);
  };
  for (int j = 0; j + 1 < n; ++j) {
    lower(j, ab_a, pivots_a, x_a);
    lower(j, ab_b, pivots_b, x_b);
  }
  for (int j = n - 1; j >= 0; --j) {
    upper(j, ab_a, inverse_diagonal_a, x_a);
    upper(j, ab_b, inverse_diagonal_b, x_b);
  }
}

// num_rhs right-hand sides stored by rows (x(i, k) at x[i · num_rhs + k]): each row operation one
// long vector operation across them.
template <int KD>
inline __attribute__((always_inline)) void SolveBandRows(int n, int kd_runtime, bool pivoted,
                                                         const double* ab, const int* pivots,
                                                         const double* inverse_diagonal,
                                                         int num_rhs, double* x) {
  const int kd = KD > 0 ? KD : kd_runtime, kv = 2 * kd, ldab = 3 * kd + 1;
  const int ku = pivoted ? kv : kd;
  auto row = [&](int i) { return x + static_cast<std::ptrdiff_t>(i) * num_rhs; };
  auto subtract = [num_rhs](double a, const double* from, double* to) {
#pragma omp simd
    for (int k = 0; k < num_rhs; ++k) to[k] -= a * from[k];
  };
  for (int j = 0; j + 1 < n; ++j) {
    const int p = pivots[j];
    if (p != j) std::swap_ranges(row(j), row(j) + num_rhs, row(p));
    const double* column = ab + kv + static_cast<std::ptrdiff_t>(j) * ldab;
    for (int i = 1; i <= std::min(kd, n - 1 - j); ++i)
      if (column[i] != 0.0) subtract(column[i], row(j), row(j + i));
  }
  for (int j = n - 1; j >= 0; --j) {
    const double* column = ab + static_cast<std::ptrdiff_t>(j) * ldab;
    for (int k = 0; k < num_rhs; ++k) row(j)[k] *= inverse_diagonal[j];
    for (int i = std::max(0, j - ku); i < j; ++i)
      if (column[kv + i - j] != 0.0) subtract(column[kv + i - j], row(j), row(i));
  }
}

// The rods' half bandwidth (the bending stencil's 11 DOFs), compiled with a fixed trip count.
constexpr int kRodHalfBandwidth = 10;

__attribute__((target_clones("avx512f", "avx2", "default")))
bool Factorize(int n, int kd, double* ab, int* pivots) {
  return kd == kRodHalfBandwidth ? FactorizeBand<kRodHalfBandwidth>(n, kd, ab, pivots)
                                 : FactorizeBand<0>(n, kd, ab, pivots);
}

__attribute__((target_clones("avx512f", "avx2", "default")))
bool FactorizeUnpivoted(int n, int kd, double* ab, double largest) {
  return kd == kRodHalfBandwidth ? FactorizeBandUnpivoted<kRodHalfBandwidth>(n, kd, ab, largest)
                                 : FactorizeBandUnpivoted<0>(n, kd, ab, largest);
}

__attribute__((target_clones("avx512f", "avx2", "default")))
void Solve(int n, int kd, bool pivoted, const double* ab, const int* pivots,
           const double* inverse_diagonal, double* x) {
  if (kd != kRodHalfBandwidth) return SolveBand<0, 0>(n, kd, pivoted, ab, pivots, inverse_diagonal, x);
  if (pivoted)
    return SolveBand<kRodHalfBandwidth, 2 * kRodHalfBandwidth>(n, kd, pivoted, ab, pivots,
                                                               inverse_diagonal, x);
  SolveBand<kRodHalfBandwidth, kRodHalfBandwidth>(n, kd, pivoted, ab, pivots, inverse_diagonal, x);
}

__attribute__((target_clones("avx512f", "avx2", "default")))
void SolvePair(int n, int kd, bool pivoted, const double* ab_a, const int* pivots_a,
               const double* inverse_diagonal_a, double* x_a, const double* ab_b,
               const int* pivots_b, const double* inverse_diagonal_b, double* x_b) {
  if (kd != kRodHalfBandwidth)
    return SolveBandPair<0, 0>(n, kd, pivoted, ab_a, pivots_a, inverse_diagonal_a, x_a, ab_b,
                               pivots_b, inverse_diagonal_b, x_b);
  if (pivoted)
    return SolveBandPair<kRodHalfBandwidth, 2 * kRodHalfBandwidth>(
        n, kd, pivoted, ab_a, pivots_a, inverse_diagonal_a, x_a, ab_b, pivots_b,
        inverse_diagonal_b, x_b);
  SolveBandPair<kRodHalfBandwidth, kRodHalfBandwidth>(n, kd, pivoted, ab_a, pivots_a,
                                                      inverse_diagonal_a, x_a, ab_b, pivots_b,
                                                      inverse_diagonal_b, x_b);
}

__attribute__((target_clones("avx512f", "avx2", "default")))
void SolveRows(int n, int kd, bool pivoted, const double* ab, const int* pivots,
               const double* inverse_diagonal, int num_rhs, double* x) {
  if (kd == kRodHalfBandwidth)
    return SolveBandRows<kRodHalfBandwidth>(n, kd, pivoted, ab, pivots, inverse_diagonal, num_rhs,
                                            x);
  SolveBandRows<0>(n, kd, pivoted, ab, pivots, inverse_diagonal, num_rhs, x);
}

}  // namespace

// Written here rather than called: at half bandwidth 10 each of LAPACK's level-2 calls (idamax,
// dswap, dscal, dger per column; dtbsv and dger per solve) moves a few dozen numbers, and the
// call overhead was ~10× the arithmetic (callgrind: 270k instructions per solve of a 260-DOF rod
// against ~8k multiply–adds). Checked against LAPACK and a dense LU in
// tests/solver/banded_matrix_test.cc.
bool BandedMatrix::Factorize() {
  SR_ASSERT(!factorized_, "matrix factorized twice");
  factorized_ = true;
  // Without pivoting where that is stable (FactorizeBandUnpivoted), else from the kept copy with
  // partial pivoting.
  // The largest |entry| of A: the storage holds zeros outside it (Resize, SetZero), scanned in
  // four interleaved runs (one chain of max would cost its latency per entry).
  double largest[4] = {0.0, 0.0, 0.0, 0.0};
  const std::size_t stored = ab_.size();
  for (std::size_t k = 0; k + 4 <= stored; k += 4)
    for (int lane = 0; lane < 4; ++lane) {
      const double v = std::abs(ab_[k + static_cast<std::size_t>(lane)]);
      largest[lane] = v > largest[lane] ? v : largest[lane];
    }
  for (std::size_t k = stored / 4 * 4; k < stored; ++k)
    largest[0] = std::max(largest[0], std::abs(ab_[k]));
  original_ = ab_;
  pivoted_ = !stokesrods::FactorizeUnpivoted(
      n_, kd_, ab_.data(), std::max(std::max(largest[0], largest[1]), std::max(largest[2], largest[3])));
  bool regular = true;
  if (pivoted_) {
    std::swap(ab_, original_);
    regular = stokesrods::Factorize(n_, kd_, ab_.data(), pivots_.data());
  } else {
    for (int j = 0; j < n_; ++j) pivots_[static_cast<std::size_t>(j)] = j;
  }
  inverse_diagonal_.resize(static_cast<std::size_t>(n_));
  for (int j = 0; j < n_; ++j) inverse_diagonal_[static_cast<std::size_t>(j)] = 1.0 / (*this)(j, j);
  return regular;
}

void BandedMatrix::Solve(double* b, int num_rhs) const {
  SR_ASSERT(factorized_, "Solve before Factorize");
  if (num_rhs >= 4) {  // many right-hand sides: row by row, each row operation one long vector
    SolveManyRows(b, num_rhs);
    return;
  }
  for (int k = 0; k < num_rhs; ++k)
    stokesrods::Solve(n_, kd_, pivoted_, ab_.data(), pivots_.data(), inverse_diagonal_.data(),
                      b + static_cast<std::ptrdiff_t>(k) * n_);
}

void SolveEach(const BandedMatrix* const* matrices, double* const* rhs, int count) {
  int k = 0;
  for (; k + 1 < count; k += 2) {
    const BandedMatrix& a = *matrices[k];
    const BandedMatrix& b = *matrices[k + 1];
    SR_ASSERT(a.factorized_ && b.factorized_, "Solve before Factorize");
    if (a.n_ != b.n_ || a.kd_ != b.kd_ || a.pivoted_ != b.pivoted_) {
      a.Solve(rhs[k], 1);
      b.Solve(rhs[k + 1], 1);
      continue;
    }
    SolvePair(a.n_, a.kd_, a.pivoted_, a.ab_.data(), a.pivots_.data(), a.inverse_diagonal_.data(),
              rhs[k], b.ab_.data(), b.pivots_.data(), b.inverse_diagonal_.data(), rhs[k + 1]);
  }
  if (k < count) matrices[k]->Solve(rhs[k], 1);
}

void BandedMatrix::SolveManyRows(double* b, int num_rhs) const {
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  Eigen::Map<MatX> columns(b, n_, num_rhs);
  RowMajor x = columns;
  SolveRows(n_, kd_, pivoted_, ab_.data(), pivots_.data(), inverse_diagonal_.data(), num_rhs,
            x.data());
  columns = x;
}

}  // namespace stokesrods
