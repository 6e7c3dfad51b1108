#include "stokesrods/solver/dense_lu.h"

#include <algorithm>
#include <type_traits>
#include <utility>

#include "stokesrods/common/assert.h"
#include "stokesrods/solver/blas.h"
#include "stokesrods/solver/lu_solve_avx512.h"

extern "C" {
void sgetrf_(const int* m, const int* n, float* a, const int* lda, int* ipiv, int* info);
void dgetrf_(const int* m, const int* n, double* a, const int* lda, int* ipiv, int* info);
void slaswp_(const int* n, float* a, const int* lda, const int* k1, const int* k2, const int* ipiv,
             const int* incx);
void dlaswp_(const int* n, double* a, const int* lda, const int* k1, const int* k2,
             const int* ipiv, const int* incx);
void strsm_(const char* side, const char* uplo, const char* transa, const char* diag, const int* m,
            const int* n, const float* alpha, const float* a, const int* lda, float* b,
            const int* ldb, std::size_t, std::size_t, std::size_t, std::size_t);
void dtrsm_(const char* side, const char* uplo, const char* transa, const char* diag, const int* m,
            const int* n, const double* alpha, const double* a, const int* lda, double* b,
            const int* ldb, std::size_t, std::size_t, std::size_t, std::size_t);
void sgetrs_(const char* trans, const int* n, const int* nrhs, const float* a, const int* lda,
             const int* ipiv, float* b, const int* ldb, int* info, std::size_t trans_len);
void dgetrs_(const char* trans, const int* n, const int* nrhs, const double* a, const int* lda,
             const int* ipiv, double* b, const int* ldb, int* info, std::size_t trans_len);
}

namespace stokesrods {
namespace {

// The LAPACK and BLAS calls of one column-major matrix with leading dimension ld.
void Getrf(int m, int n, float* a, int ld, int* ipiv, int* info) { sgetrf_(&m, &n, a, &ld, ipiv, info); }
void Getrf(int m, int n, double* a, int ld, int* ipiv, int* info) { dgetrf_(&m, &n, a, &ld, ipiv, info); }
template <typename Scalar>
void Laswp(int n, Scalar* a, int ld, int k1, int k2, const int* ipiv) {
  const int one = 1;
  if constexpr (std::is_same_v<Scalar, float>)
    slaswp_(&n, a, &ld, &k1, &k2, ipiv, &one);
  else
    dlaswp_(&n, a, &ld, &k1, &k2, ipiv, &one);
}
// b = L⁻¹ b, L unit lower triangular (m × m), b m × n.
template <typename Scalar>
void TrsmUnitLower(int m, int n, const Scalar* l, int ld, Scalar* b) {
  const Scalar one = 1;
  if constexpr (std::is_same_v<Scalar, float>)
    strsm_("L", "L", "N", "U", &m, &n, &one, l, &ld, b, &ld, 1, 1, 1, 1);
  else
    dtrsm_("L", "L", "N", "U", &m, &n, &one, l, &ld, b, &ld, 1, 1, 1, 1);
}
// c −= a b, a m × k, b k × n.
template <typename Scalar>
void GemmSubtract(int m, int n, int k, const Scalar* a, const Scalar* b, Scalar* c, int ld) {
  Gemm(m, n, k, Scalar(-1), a, ld, b, ld, Scalar(1), c, ld);
}

// The LU with partial pivoting of a (n × n) by LAPACK's right-looking blocked algorithm (that of
// getrf), each panel of kPanel columns by getrf itself and the rest of each step over fixed
// blocks of kColumns columns spread over the OpenMP threads: a block's row interchanges,
// triangular solve and product are each one single-threaded BLAS call whose shape does not
// depend on the thread count, so the factors are the same bits on one thread or two (the BLAS
// runs on one: solver/blas.h), where getrf alone would leave the second core idle (E of the
// coarse level at a hundred helices, 2400 × 2400, 178 ms at every rebuild: docs/performance.md,
// session 27). info as getrf's: the first exactly zero pivot (1-based), or 0.
template <typename Scalar>
void BlockedGetrf(int n, Scalar* a, int* ipiv, int* info) {
  constexpr int kPanel = 128, kColumns = 128;
  *info = 0;
  for (int k = 0; k < n; k += kPanel) {
    const int nb = std::min(kPanel, n - k), m = n - k;
    int panel_info = 0;
    Getrf(m, nb, a + k + static_cast<std::ptrdiff_t>(k) * n, n, ipiv + k, &panel_info);
    if (panel_info > 0 && *info == 0) *info = panel_info + k;
    for (int i = k; i < k + nb; ++i) ipiv[i] += k;  // rows of the whole matrix (1-based)
    // The panel's interchanges on the columns left of it and right of it; right of it also
    // U₁₂ = L₁₁⁻¹ A₁₂ and A₂₂ −= L₂₁ U₁₂, column block by column block.
    const int left_blocks = (k + kColumns - 1) / kColumns;
    const int right_first = k + nb, right_blocks = (n - right_first + kColumns - 1) / kColumns;
    const int blocks = left_blocks + right_blocks;
#pragma omp parallel for schedule(static) if (blocks > 1)
    for (int b = 0; b < blocks; ++b) {
      const bool right = b >= left_blocks;
      const int j0 = right ? right_first + (b - left_blocks) * kColumns : b * kColumns;
      const int w = std::min(kColumns, (right ? n : k) - j0);
      Scalar* column = a + static_cast<std::ptrdiff_t>(j0) * n;
      Laswp(w, column, n, k + 1, k + nb, ipiv);
      if (!right) continue;
      TrsmUnitLower(nb, w, a + k + static_cast<std::ptrdiff_t>(k) * n, n, column + k);
      if (m > nb)
        GemmSubtract(m - nb, w, nb, a + (k + nb) + static_cast<std::ptrdiff_t>(k) * n, column + k,
                     column + k + nb, n);
    }
  }
}

template <typename Scalar>
void Factor(int n, Scalar* a, int* ipiv, int* info) {
  if (n >= kBlockedLuFrom) return BlockedGetrf(n, a, ipiv, info);
  Getrf(n, n, a, n, ipiv, info);
}
void Getrs(int n, const float* a, const int* ipiv, float* b, int* info) {
  const int one = 1;
  sgetrs_("N", &n, &one, a, &n, ipiv, b, &n, info, 1);
}
void Getrs(int n, const double* a, const int* ipiv, double* b, int* info) {
  const int one = 1;
  dgetrs_("N", &n, &one, a, &n, ipiv, b, &n, info, 1);
}

}  // namespace

void LuFactor(int n, float* a, int* ipiv, int* info) { Factor(n, a, ipiv, info); }
void LuFactor(int n, double* a, int* ipiv, int* info) { Factor(n, a, ipiv, info); }

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
  LuFactor(n, lu_.data(), pivots_.data(), &info);
  SR_ASSERT(info >= 0, "DenseLu: bad argument to getrf");
  if constexpr (std::is_same_v<Scalar, float>) {
    if (info == 0 && storage == LuStorage::kHalf && (HasLuSolveHalfAvx512() || HasLuSolveAvx2())) {
      half_.resize(HalfFactorLayout(n).Size());
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
    if (!half_.empty()) return SolveHalf(b, {});
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
void DenseLu<Scalar>::SolveHalf(Vector* b, PrefetchSpan then) const {
  if constexpr (std::is_same_v<Scalar, float>) {
    const int n = static_cast<int>(n_);
    if (HasLuSolveHalfAvx512())
      return LuSolveHalfAvx512(n, half_.data(), pivots_.data(), half_scale_, b->data(), then);
    return LuSolveHalfAvx2(n, half_.data(), pivots_.data(), half_scale_, b->data(), then);
  }
}

template <typename Scalar>
void DenseLu<Scalar>::SolveThenPrefetch(Vector* b, const DenseLu& next) const {
  if (half_.empty() || n_ >= kParallelLuSolve) {  // the solve would not spread it
    next.Prefetch();
    return Solve(b);
  }
  SR_ASSERT(b->size() == n_, "DenseLu: right-hand side of the wrong size");
  SolveHalf(b, next.FactorBytes());
}

template <typename Scalar>
PrefetchSpan DenseLu<Scalar>::FactorBytes() const {
  return half_.empty() ? PrefetchSpan{reinterpret_cast<const char*>(lu_.data()),
                                      sizeof(Scalar) * static_cast<std::size_t>(lu_.size())}
                       : PrefetchSpan{reinterpret_cast<const char*>(half_.data()),
                                      sizeof(std::uint16_t) * half_.size()};
}

template <typename Scalar>
void DenseLu<Scalar>::Prefetch() const {
  const PrefetchSpan span = FactorBytes();
  for (std::size_t b = 0; b < span.bytes; b += 64) __builtin_prefetch(span.first + b, 0, 2);
}

template class DenseLu<float>;
template class DenseLu<double>;

}  // namespace stokesrods
