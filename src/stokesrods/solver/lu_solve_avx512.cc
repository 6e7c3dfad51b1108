// x ← A⁻¹ x for A = P L U as LAPACK's sgetrf leaves it (column-major, leading dimension n, 1-based
// pivots), for one right-hand side, on AVX-512 (solver/dense_lu.h). OpenBLAS's sgetrs for one
// vector goes through strsv: 12.1 µs on the 390 × 390 preconditioner of Fig. 1, 8.7 µs here
// (bench_step BM_FloatLuSolve, one thread). The triangles are solved by blocks of kBlock columns:
// the small triangle of the block by columns, then the rows below (L) or above (U) updated by the
// block's panel, 64 rows at a time in four registers of 16 floats, the panel's columns streamed
// once. The same arithmetic as the
// substitution, in another order: equal to getrs within single-precision rounding (tested).
#include <immintrin.h>

#include <algorithm>
#include <utility>

#include <Eigen/Core>

#include "stokesrods/solver/lu_solve_avx512.h"

namespace stokesrods {

#if defined(__GNUC__) && defined(__x86_64__)
namespace {

constexpr int kBlock = 32;

// y[0, rows) −= P x, P (rows × cols, column-major, leading dimension ld), the rows in chunks of
// 64 (the last masked).
__attribute__((target("avx512f"), always_inline)) inline void SubtractPanel(
    int rows, int cols, const float* p, Eigen::Index ld, const float* x, float* y) {
  for (int i0 = 0; i0 < rows; i0 += 64) {
    auto mask = [&](int b) {
      const int left = std::clamp(rows - i0 - 16 * b, 0, 16);
      return static_cast<__mmask16>((1u << left) - 1u);
    };
    const __mmask16 m0 = mask(0), m1 = mask(1), m2 = mask(2), m3 = mask(3);
    float* out = y + i0;
    __m512 a0 = _mm512_maskz_loadu_ps(m0, out), a1 = _mm512_maskz_loadu_ps(m1, out + 16),
           a2 = _mm512_maskz_loadu_ps(m2, out + 32), a3 = _mm512_maskz_loadu_ps(m3, out + 48);
    for (int j = 0; j < cols; ++j) {  // four accumulators by name: GCC keeps them in registers
      const __m512 xj = _mm512_set1_ps(x[j]);
      const float* column = p + j * ld + i0;
      a0 = _mm512_fnmadd_ps(_mm512_maskz_loadu_ps(m0, column), xj, a0);
      a1 = _mm512_fnmadd_ps(_mm512_maskz_loadu_ps(m1, column + 16), xj, a1);
      a2 = _mm512_fnmadd_ps(_mm512_maskz_loadu_ps(m2, column + 32), xj, a2);
      a3 = _mm512_fnmadd_ps(_mm512_maskz_loadu_ps(m3, column + 48), xj, a3);
    }
    _mm512_mask_storeu_ps(out, m0, a0);
    _mm512_mask_storeu_ps(out + 16, m1, a1);
    _mm512_mask_storeu_ps(out + 32, m2, a2);
    _mm512_mask_storeu_ps(out + 48, m3, a3);
  }
}

// Large n (the coarse level's E, 2400 × 2400 on 100 helices: 23 MB of factors, streamed from
// memory at every solve): by blocks of kWideBlock columns, the small triangle on one thread, then
// the rows below (L) or above (U) in chunks of kChunkRows over the OpenMP threads, each chunk
// updated column by column of the block: every column's segment is read once, contiguously (the
// 64-row panels above read 32 columns at once, 2.3× slower than getrs at n = 2400). Fixed chunks:
// the result does not depend on the thread count.
constexpr int kWideBlock = 128;
constexpr int kChunkRows = 1024;
constexpr int kParallelLuSolve = 1024;  // n from which LuSolveAvx512 takes this one

__attribute__((target("avx512f"))) inline void SubtractColumns(int rows, int cols, const float* p,
                                                               Eigen::Index ld, const float* x,
                                                               float* y) {
  int j = 0;
  for (; j + 4 <= cols; j += 4) {  // four columns per pass over y: four streams in flight
    const float x0 = x[j], x1 = x[j + 1], x2 = x[j + 2], x3 = x[j + 3];
    const float *c0 = p + j * ld, *c1 = c0 + ld, *c2 = c1 + ld, *c3 = c2 + ld;
#pragma omp simd
    for (int i = 0; i < rows; ++i) y[i] = y[i] - c0[i] * x0 - c1[i] * x1 - c2[i] * x2 - c3[i] * x3;
  }
  for (; j < cols; ++j) {
    const float xj = x[j];
    const float* column = p + j * ld;
#pragma omp simd
    for (int i = 0; i < rows; ++i) y[i] -= column[i] * xj;
  }
}

__attribute__((target("avx512f"))) void LuSolveAvx512Parallel(int n, const float* lu,
                                                              const int* pivots, float* x) {
  for (int i = 0; i < n; ++i)
    if (pivots[i] - 1 != i) std::swap(x[i], x[pivots[i] - 1]);
  const Eigen::Index ld = n;
#pragma omp parallel
  {
    for (int j0 = 0; j0 < n; j0 += kWideBlock) {  // L (unit diagonal), from the top
      const int j1 = std::min(j0 + kWideBlock, n);
#pragma omp single
      for (int j = j0; j < j1; ++j)
        SubtractColumns(j1 - j - 1, 1, lu + j + 1 + j * ld, ld, x + j, x + j + 1);
#pragma omp for schedule(static)
      for (int r = j1; r < n; r += kChunkRows)
        SubtractColumns(std::min(kChunkRows, n - r), j1 - j0, lu + r + j0 * ld, ld, x + j0, x + r);
    }
    for (int j1 = n; j1 > 0; j1 -= kWideBlock) {  // U, from the bottom
      const int j0 = std::max(j1 - kWideBlock, 0);
#pragma omp single
      for (int j = j1 - 1; j >= j0; --j) {
        x[j] /= lu[j + j * ld];
        SubtractColumns(j - j0, 1, lu + j0 + j * ld, ld, x + j, x + j0);
      }
#pragma omp for schedule(static)
      for (int r = 0; r < j0; r += kChunkRows)
        SubtractColumns(std::min(kChunkRows, j0 - r), j1 - j0, lu + r + j0 * ld, ld, x + j0, x + r);
    }
  }
}

}  // namespace

__attribute__((target("avx512f"))) void LuSolveAvx512(int n, const float* lu, const int* pivots,
                                                      float* x) {
  if (n >= kParallelLuSolve) return LuSolveAvx512Parallel(n, lu, pivots, x);
  for (int i = 0; i < n; ++i)
    if (pivots[i] - 1 != i) std::swap(x[i], x[pivots[i] - 1]);
  const Eigen::Index ld = n;
  // L (unit diagonal), blocks from the top.
  for (int j0 = 0; j0 < n; j0 += kBlock) {
    const int j1 = std::min(j0 + kBlock, n);
    for (int j = j0; j < j1; ++j) {
      const float xj = x[j];
      const float* column = lu + j * ld;
#pragma omp simd
      for (int i = j + 1; i < j1; ++i) x[i] -= column[i] * xj;
    }
    SubtractPanel(n - j1, j1 - j0, lu + j1 + j0 * ld, ld, x + j0, x + j1);
  }
  // U, blocks from the bottom.
  for (int j1 = n; j1 > 0; j1 -= kBlock) {
    const int j0 = std::max(j1 - kBlock, 0);
    for (int j = j1 - 1; j >= j0; --j) {
      const float* column = lu + j * ld;
      const float xj = x[j] / column[j];
      x[j] = xj;
#pragma omp simd
      for (int i = j0; i < j; ++i) x[i] -= column[i] * xj;
    }
    SubtractPanel(j0, j1 - j0, lu + j0 * ld, ld, x + j0, x);
  }
}

bool HasLuSolveAvx512() {
  static const bool has = __builtin_cpu_supports("avx512f");
  return has;
}

#else
void LuSolveAvx512(int, const float*, const int*, float*) {}
bool HasLuSolveAvx512() { return false; }
#endif

}  // namespace stokesrods
