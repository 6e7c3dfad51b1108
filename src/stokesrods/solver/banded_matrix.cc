#include "stokesrods/solver/banded_matrix.h"

#include <algorithm>

#include "stokesrods/common/assert.h"

extern "C" {
void dgbtrf_(const int* m, const int* n, const int* kl, const int* ku, double* ab,
             const int* ldab, int* ipiv, int* info);
void dgbtrs_(const char* trans, const int* n, const int* kl, const int* ku, const int* nrhs,
             const double* ab, const int* ldab, const int* ipiv, double* b, const int* ldb,
             int* info, std::size_t trans_len);
}

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

bool BandedMatrix::Factorize() {
  SR_ASSERT(!factorized_, "matrix factorized twice");
  int info = 0;
  dgbtrf_(&n_, &n_, &kd_, &kd_, ab_.data(), &ldab_, pivots_.data(), &info);
  factorized_ = true;
  return info == 0;
}

void BandedMatrix::Solve(double* b, int num_rhs) const {
  SR_ASSERT(factorized_, "Solve before Factorize");
  int info = 0;
  const char trans = 'N';
  dgbtrs_(&trans, &n_, &kd_, &kd_, &num_rhs, ab_.data(), &ldab_, pivots_.data(), b, &n_, &info,
          1);
  SR_ASSERT(info == 0, "dgbtrs failed");
}

}  // namespace stokesrods
