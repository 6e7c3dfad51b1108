// y = A x with A stored in single precision (by columns) and x, y and every sum in double
// (solver/blas.h): the exact product of the matrix as stored, to double rounding. The matrix streams
// half the bytes of a double one (a 390 × 390 𝕄 then fits the 1 MB L2 cache); the sums stay double
// so that a Newton residual formed with it is as accurate as with a double matrix.
//
// AVX-512 (F and VL): 64 rows at a time in eight accumulators of eight rows, a column at a time
// (its 64 entries converted by vcvtps2pd, times the broadcast x_j); the last rows masked. AVX2
// with FMA: the same with 48 rows in twelve accumulators of four. Elsewhere a portable loop. Each
// row's sum runs over the columns in order, whatever the rows around it: the result does not
// depend on how rows are split over threads (and the two vector paths, both fused multiply–adds
// in the same order, give the same bits).
//
// MEASURED (AMD EPYC without AVX-512, one thread, Fig. 1 at h = 1 ms: 390 × 390): the portable
// loop, which GCC vectorizes for SSE2 only, was 43 % of the step (perf); see docs/performance.md
// for the step with the AVX2 kernel.
#include <immintrin.h>

#include <algorithm>

#include "stokesrods/solver/blas.h"

namespace stokesrods {
namespace {

#if defined(__GNUC__) && defined(__x86_64__)
#define SR_HAVE_AVX512_MIXED 1
// GCC 12's intrinsics headers start some conversions from an undefined register (bug 105593).
#if !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif

// Rows [0, 8 · blocks) of a column block, the last block masked by `last`.
template <int kBlocks>
__attribute__((target("avx512f,avx512vl"), always_inline)) inline void MixedBlockAvx512(
    int blocks, __mmask8 last, int cols, const float* a, Eigen::Index lda, const double* x,
    double* y) {
  __m512d sum[kBlocks];
  for (int b = 0; b < kBlocks; ++b) sum[b] = _mm512_setzero_pd();
  for (int j = 0; j < cols; ++j) {
    const __m512d xj = _mm512_set1_pd(x[j]);
    const float* column = a + j * lda;
    for (int b = 0; b < kBlocks; ++b) {
      if (b >= blocks) break;
      const __mmask8 m = b + 1 == blocks ? last : static_cast<__mmask8>(0xff);
      sum[b] = _mm512_fmadd_pd(_mm512_cvtps_pd(_mm256_maskz_loadu_ps(m, column + 8 * b)), xj,
                               sum[b]);
    }
  }
  for (int b = 0; b < blocks; ++b)
    _mm512_mask_storeu_pd(y + 8 * b, b + 1 == blocks ? last : static_cast<__mmask8>(0xff),
                          sum[b]);
}

__attribute__((target("avx512f,avx512vl"))) void MixedGemvAvx512(
    Eigen::Index rows, int cols, const float* a, Eigen::Index lda, const double* x, double* y) {
  constexpr int kBlocks = 8;  // 64 rows: eight accumulators in registers
  Eigen::Index i = 0;
  for (; i + 8 * kBlocks <= rows; i += 8 * kBlocks)
    MixedBlockAvx512<kBlocks>(kBlocks, 0xff, cols, a + i, lda, x, y + i);
  if (i < rows) {
    const auto left = static_cast<int>(rows - i), blocks = (left + 7) / 8;
    const auto last = static_cast<__mmask8>((1u << (left - 8 * (blocks - 1))) - 1u);
    MixedBlockAvx512<kBlocks>(blocks, last, cols, a + i, lda, x, y + i);
  }
}

#if !defined(__clang__)
#pragma GCC diagnostic pop
#endif

bool HasAvx512Mixed() {
  static const bool has =
      __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl");
  return has;
}

// Rows [0, 4 · blocks) of a column block, the last block's lanes chosen by `last` (32-bit lanes
// for the floats read, 64-bit for the doubles written).
template <int kBlocks>
__attribute__((target("avx2,fma"), always_inline)) inline void MixedBlockAvx2(
    int blocks, __m128i last, __m256i last_out, int cols, const float* a, Eigen::Index lda,
    const double* x, double* y) {
  __m256d sum[kBlocks];
  for (int b = 0; b < kBlocks; ++b) sum[b] = _mm256_setzero_pd();
  for (int j = 0; j < cols; ++j) {
    const __m256d xj = _mm256_set1_pd(x[j]);
    const float* column = a + j * lda;
    for (int b = 0; b < kBlocks; ++b) {
      if (b >= blocks) break;
      const __m128 v = b + 1 == blocks ? _mm_maskload_ps(column + 4 * b, last)
                                       : _mm_loadu_ps(column + 4 * b);
      sum[b] = _mm256_fmadd_pd(_mm256_cvtps_pd(v), xj, sum[b]);
    }
  }
  for (int b = 0; b + 1 < blocks; ++b) _mm256_storeu_pd(y + 4 * b, sum[b]);
  _mm256_maskstore_pd(y + 4 * (blocks - 1), last_out, sum[blocks - 1]);
}

__attribute__((target("avx2,fma"))) void MixedGemvAvx2(Eigen::Index rows, int cols,
                                                       const float* a, Eigen::Index lda,
                                                       const double* x, double* y) {
  constexpr int kBlocks = 12;  // 48 rows: twelve accumulators of the sixteen registers
  const __m128i all = _mm_set1_epi32(-1);
  const __m256i all_out = _mm256_set1_epi64x(-1);
  Eigen::Index i = 0;
  for (; i + 4 * kBlocks <= rows; i += 4 * kBlocks)
    MixedBlockAvx2<kBlocks>(kBlocks, all, all_out, cols, a + i, lda, x, y + i);
  if (i < rows) {
    const auto left = static_cast<int>(rows - i), blocks = (left + 3) / 4;
    const int lanes = left - 4 * (blocks - 1);  // 1 … 4 in the last block
    const __m128i last = _mm_cmpgt_epi32(_mm_set1_epi32(lanes), _mm_setr_epi32(0, 1, 2, 3));
    const __m256i last_out =
        _mm256_cmpgt_epi64(_mm256_set1_epi64x(lanes), _mm256_setr_epi64x(0, 1, 2, 3));
    MixedBlockAvx2<kBlocks>(blocks, last, last_out, cols, a + i, lda, x, y + i);
  }
}

bool HasAvx2Mixed() {
  static const bool has = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  return has;
}
#endif

void MixedGemvPortable(Eigen::Index rows, int cols, const float* a, Eigen::Index lda,
                       const double* x, double* y) {
  std::fill(y, y + rows, 0.0);
  for (int j = 0; j < cols; ++j)
    for (Eigen::Index i = 0; i < rows; ++i) y[i] += static_cast<double>(a[i + j * lda]) * x[j];
}

}  // namespace

void GemvRowsMixed(const Eigen::MatrixXf& a, Eigen::Index first, Eigen::Index rows,
                   const double* x, double* y, MixedGemvPath path) {
  const auto cols = static_cast<int>(a.cols());
#ifdef SR_HAVE_AVX512_MIXED
  if (path == MixedGemvPath::kWidest && HasAvx512Mixed())
    return MixedGemvAvx512(rows, cols, a.data() + first, a.rows(), x, y);
  if (path != MixedGemvPath::kPortable && HasAvx2Mixed())
    return MixedGemvAvx2(rows, cols, a.data() + first, a.rows(), x, y);
#endif
  MixedGemvPortable(rows, cols, a.data() + first, a.rows(), x, y);
}

}  // namespace stokesrods
