#include "stokesrods/solver/dense_lu.h"

#include <type_traits>
#include <utility>

#include "stokesrods/common/assert.h"
#include "stokesrods/solver/lu_solve_avx512.h"

extern "C" {
void sgetrf_(const int* m, const int* n, float* a, const int* lda, int* ipiv, int* info);
void dgetrf_(const int* m, const int* n, double* a, const int* lda, int* ipiv, int* info);
void sgetrs_(const char* trans, const int* n, const int* nrhs, const float* a, const int* lda,
             const int* ipiv, float* b, const int* ldb, int* info, std::size_t trans_len);
void dgetrs_(const char* trans, const int* n, const int* nrhs, const double* a, const int* lda,
             const int* ipiv, double* b, const int* ldb, int* info, std::size_t trans_len);
}

namespace stokesrods {
namespace {

void Getrf(int n, float* a, int* ipiv, int* info) { sgetrf_(&n, &n, a, &n, ipiv, info); }
void Getrf(int n, double* a, int* ipiv, int* info) { dgetrf_(&n, &n, a, &n, ipiv, info); }
void Getrs(int n, const float* a, const int* ipiv, float* b, int* info) {
  const int one = 1;
  sgetrs_("N", &n, &one, a, &n, ipiv, b, &n, info, 1);
}
void Getrs(int n, const double* a, const int* ipiv, double* b, int* info) {
  const int one = 1;
  dgetrs_("N", &n, &one, a, &n, ipiv, b, &n, info, 1);
}

}  // namespace

template <typename Scalar>
bool DenseLu<Scalar>::Compute(Matrix a, LuStorage storage) {
  SR_ASSERT(a.rows() == a.cols(), "DenseLu: the matrix must be square");
  SR_ASSERT((storage == LuStorage::kNative || std::is_same_v<Scalar, float>),
            "DenseLu: half precision storage is for single precision factors");
  lu_ = std::move(a);
  half_.clear();
  n_ = lu_.rows();
  const int n = static_cast<int>(n_);
  pivots_.resize(static_cast<std::size_t>(n));
  if (n == 0) return true;
  int info = 0;
  Getrf(n, lu_.data(), pivots_.data(), &info);
  SR_ASSERT(info >= 0, "DenseLu: bad argument to getrf");
  if constexpr (std::is_same_v<Scalar, float>) {
    if (info == 0 && storage == LuStorage::kHalf && (HasLuSolveHalfAvx512() || HasLuSolveAvx2())) {
      half_.resize(static_cast<std::size_t>(lu_.size()));
      const bool converted = HasLuSolveHalfAvx512()
                                 ? ConvertLuToHalf(n, lu_.data(), half_.data(), &half_scale_)
                                 : ConvertLuToHalfF16c(n, lu_.data(), half_.data(), &half_scale_);
      if (converted)
        lu_ = Matrix();  // the single-precision factors are not kept
      else
        half_.clear();
    }
  }
  return info == 0;
}

template <typename Scalar>
void DenseLu<Scalar>::Solve(Vector* b, bool use_lapack) const {
  SR_ASSERT(b->size() == n_, "DenseLu: right-hand side of the wrong size");
  const int n = static_cast<int>(n_);
  if (n == 0) return;
  if constexpr (std::is_same_v<Scalar, float>) {
    if (!half_.empty()) {
      if (HasLuSolveHalfAvx512())
        return LuSolveHalfAvx512(n, half_.data(), pivots_.data(), half_scale_, b->data());
      return LuSolveHalfAvx2(n, half_.data(), pivots_.data(), half_scale_, b->data());
    }
    if (!use_lapack && HasLuSolveAvx512())
      return LuSolveAvx512(n, lu_.data(), pivots_.data(), b->data());
    // On AVX2 getrs is faster from the parallel panels' size on (bench_step BM_FloatLuSolve, an
    // AMD EPYC, one thread: n = 390 23.8 → 19.7 µs, n = 2400 1229 against 1611 µs).
    if (!use_lapack && HasLuSolveAvx2() && n < kParallelLuSolve)
      return LuSolveAvx2(n, lu_.data(), pivots_.data(), b->data());
  }
  int info = 0;
  Getrs(n, lu_.data(), pivots_.data(), b->data(), &info);
  SR_ASSERT(info == 0, "DenseLu: bad argument to getrs");
}

template <typename Scalar>
void DenseLu<Scalar>::Prefetch() const {
  const char* p = half_.empty() ? reinterpret_cast<const char*>(lu_.data())
                                : reinterpret_cast<const char*>(half_.data());
  const std::size_t bytes = half_.empty() ? sizeof(Scalar) * static_cast<std::size_t>(lu_.size())
                                          : sizeof(std::uint16_t) * half_.size();
  for (std::size_t b = 0; b < bytes; b += 64) __builtin_prefetch(p + b, 0, 2);
}

template class DenseLu<float>;
template class DenseLu<double>;

}  // namespace stokesrods
