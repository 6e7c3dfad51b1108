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
#include <cmath>
#include <cstdint>
#include <utility>

#include <Eigen/Core>

#include "stokesrods/solver/lu_solve_avx512.h"

namespace stokesrods {

#if defined(__GNUC__) && defined(__x86_64__)
namespace {

constexpr int kBlock = kLuBlock;

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
constexpr int kWideBlock = kLuWideBlock;
constexpr int kChunkRows = kLuChunkRows;

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

// The small triangles of a block (w ≤ kBlock = 32 columns; d its diagonal block, leading
// dimension ld; x its w rows) with x held in two registers, as their half-precision twins below
// (LowerTriangleHalf: why). Each row's operations are the fused multiply–adds of the loops they
// replace, in their order: the same bits.
#define SR_F __attribute__((target("avx512f"), always_inline)) inline
// (GCC 12 warns on its own _mm512_undefined_ps in vpermps, GCC bug 105593.)
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
SR_F __mmask16 Lanes(int count) {  // the first min(count, 16) lanes, none if count ≤ 0
  return static_cast<__mmask16>((1u << std::clamp(count, 0, 16)) - 1u);
}
// Lane k of the 32 floats v0, v1 in every lane (the half kernels below take it too).
SR_F __m512 LaneOf(__m512 v0, __m512 v1, int k) {
  return _mm512_permutexvar_ps(_mm512_set1_epi32(k & 15), k < 16 ? v0 : v1);
}
SR_F void LowerTriangle(int w, const float* d, Eigen::Index ld, float* x) {
  const __mmask16 rows0 = Lanes(w), rows1 = Lanes(w - 16);
  __m512 v0 = _mm512_maskz_loadu_ps(rows0, x), v1 = _mm512_maskz_loadu_ps(rows1, x + 16);
  for (int k = 0; k + 1 < w; ++k) {
    const __m512 xk = LaneOf(v0, v1, k);
    const float* column = d + k * ld;
    const auto below0 = static_cast<__mmask16>(rows0 & ~Lanes(k + 1)),
               below1 = static_cast<__mmask16>(rows1 & ~Lanes(k - 15));
    v0 = _mm512_mask3_fnmadd_ps(_mm512_maskz_loadu_ps(below0, column), xk, v0, below0);
    v1 = _mm512_mask3_fnmadd_ps(_mm512_maskz_loadu_ps(below1, column + 16), xk, v1, below1);
  }
  _mm512_mask_storeu_ps(x, rows0, v0);
  _mm512_mask_storeu_ps(x + 16, rows1, v1);
}
SR_F void UpperTriangle(int w, const float* d, Eigen::Index ld, float* x) {
  const __mmask16 rows0 = Lanes(w), rows1 = Lanes(w - 16);
  __m512 v0 = _mm512_maskz_loadu_ps(rows0, x), v1 = _mm512_maskz_loadu_ps(rows1, x + 16);
  for (int k = w - 1; k >= 0; --k) {
    const float* column = d + k * ld;
    const __m512 xk = _mm512_div_ps(LaneOf(v0, v1, k), _mm512_set1_ps(column[k]));
    if (k < 16)
      v0 = _mm512_mask_mov_ps(v0, static_cast<__mmask16>(1u << k), xk);
    else
      v1 = _mm512_mask_mov_ps(v1, static_cast<__mmask16>(1u << (k - 16)), xk);
    const __mmask16 above0 = Lanes(k), above1 = Lanes(k - 16);
    v0 = _mm512_mask3_fnmadd_ps(_mm512_maskz_loadu_ps(above0, column), xk, v0, above0);
    v1 = _mm512_mask3_fnmadd_ps(_mm512_maskz_loadu_ps(above1, column + 16), xk, v1, above1);
  }
  _mm512_mask_storeu_ps(x, rows0, v0);
  _mm512_mask_storeu_ps(x + 16, rows1, v1);
}
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif
#undef SR_F

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
    LowerTriangle(j1 - j0, lu + j0 + j0 * ld, ld, x + j0);
    SubtractPanel(n - j1, j1 - j0, lu + j1 + j0 * ld, ld, x + j0, x + j1);
  }
  // U, blocks from the bottom.
  for (int j1 = n; j1 > 0; j1 -= kBlock) {
    const int j0 = std::max(j1 - kBlock, 0);
    UpperTriangle(j1 - j0, lu + j0 + j0 * ld, ld, x + j0);
    SubtractPanel(j0, j1 - j0, lu + j0 * ld, ld, x + j0, x);
  }
}

bool HasLuSolveAvx512() {
  static const bool has = __builtin_cpu_supports("avx512f");
  return has;
}

// HALF PRECISION. The factors of preconditioners whose solves stream them from memory (a hundred
// rods' blocks, 15 MB in single precision; the coarse level's E, 23 MB) kept in half precision:
// half the bytes per solve. Each kernel above has its twin here that widens 16 entries at a time
// (vcvtph2ps) as it loads them; the arithmetic and its order are those of the single-precision
// kernels on the rounded factors.
#define SR_HALF __attribute__((target("avx512f,avx512bw,avx512vl,f16c")))
// (GCC 12's avx512fintrin.h warns on its own _mm512_undefined_ps in vcvtph2ps, GCC bug 105593.)
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
namespace {

SR_HALF inline __m512 LoadHalf(__mmask16 m, const std::uint16_t* p) {
  return _mm512_cvtph_ps(_mm256_maskz_loadu_epi16(m, p));
}
SR_HALF inline float HalfToFloat(std::uint16_t h) { return _cvtsh_ss(h); }

// y[0, count) −= x · c[0, count), count ≤ 32 (the small triangles of the blocks).
SR_HALF inline void AxpyHalfShort(int count, const std::uint16_t* c, float x, float* y) {
  const __m512 xv = _mm512_set1_ps(x);
  for (int i = 0; i < count; i += 16) {
    const __mmask16 m = Lanes(count - i);
    const __m512 yv = _mm512_maskz_loadu_ps(m, y + i);
    _mm512_mask_storeu_ps(y + i, m, _mm512_fnmadd_ps(LoadHalf(m, c + i), xv, yv));
  }
}

// A block's triangles (w ≤ kBlock = 32 columns; d its diagonal block, leading dimension ld; x its
// w rows) with x held in two registers: each column's update takes x_k from its lane, so the
// chain from one column to the next stays in registers instead of passing through memory (x_k
// stored, then loaded again: 58 % of a 195 × 195 solve from cache went there, bench_step
// BM_BlockSolves). Each row's operations are AxpyHalfShort's, in its order: the same bits.
// L (unit diagonal), from the left: x_i −= L_ik x_k for k < i < w.
SR_HALF inline void LowerTriangleHalf(int w, const std::uint16_t* d, Eigen::Index ld, float* x) {
  const __mmask16 rows0 = Lanes(w), rows1 = Lanes(w - 16);
  __m512 v0 = _mm512_maskz_loadu_ps(rows0, x), v1 = _mm512_maskz_loadu_ps(rows1, x + 16);
  for (int k = 0; k + 1 < w; ++k) {
    const __m512 xk = LaneOf(v0, v1, k);
    const std::uint16_t* column = d + k * ld;
    const auto below0 = static_cast<__mmask16>(rows0 & ~Lanes(k + 1)),
               below1 = static_cast<__mmask16>(rows1 & ~Lanes(k - 15));
    v0 = _mm512_mask3_fnmadd_ps(LoadHalf(below0, column), xk, v0, below0);
    v1 = _mm512_mask3_fnmadd_ps(LoadHalf(below1, column + 16), xk, v1, below1);
  }
  _mm512_mask_storeu_ps(x, rows0, v0);
  _mm512_mask_storeu_ps(x + 16, rows1, v1);
}
// U, from the right: x_k /= U_kk, then x_i −= U_ik x_k for i < k.
SR_HALF inline void UpperTriangleHalf(int w, const std::uint16_t* d, Eigen::Index ld, float* x) {
  const __mmask16 rows0 = Lanes(w), rows1 = Lanes(w - 16);
  __m512 v0 = _mm512_maskz_loadu_ps(rows0, x), v1 = _mm512_maskz_loadu_ps(rows1, x + 16);
  for (int k = w - 1; k >= 0; --k) {
    const std::uint16_t* column = d + k * ld;
    const __m512 xk = _mm512_div_ps(LaneOf(v0, v1, k), _mm512_set1_ps(HalfToFloat(column[k])));
    if (k < 16)
      v0 = _mm512_mask_mov_ps(v0, static_cast<__mmask16>(1u << k), xk);
    else
      v1 = _mm512_mask_mov_ps(v1, static_cast<__mmask16>(1u << (k - 16)), xk);
    const __mmask16 above0 = Lanes(k), above1 = Lanes(k - 16);
    v0 = _mm512_mask3_fnmadd_ps(LoadHalf(above0, column), xk, v0, above0);
    v1 = _mm512_mask3_fnmadd_ps(LoadHalf(above1, column + 16), xk, v1, above1);
  }
  _mm512_mask_storeu_ps(x, rows0, v0);
  _mm512_mask_storeu_ps(x + 16, rows1, v1);
}

// SubtractPanel on half-precision columns.
SR_HALF inline void SubtractPanelHalf(int rows, int cols, const std::uint16_t* p, Eigen::Index ld,
                                      const float* x, float* y) {
  for (int i0 = 0; i0 < rows; i0 += 64) {
    const __mmask16 m0 = Lanes(rows - i0), m1 = Lanes(rows - i0 - 16), m2 = Lanes(rows - i0 - 32),
                    m3 = Lanes(rows - i0 - 48);
    float* out = y + i0;
    __m512 a0 = _mm512_maskz_loadu_ps(m0, out), a1 = _mm512_maskz_loadu_ps(m1, out + 16),
           a2 = _mm512_maskz_loadu_ps(m2, out + 32), a3 = _mm512_maskz_loadu_ps(m3, out + 48);
    for (int j = 0; j < cols; ++j) {
      const __m512 xj = _mm512_set1_ps(x[j]);
      const std::uint16_t* column = p + j * ld + i0;
      a0 = _mm512_fnmadd_ps(LoadHalf(m0, column), xj, a0);
      a1 = _mm512_fnmadd_ps(LoadHalf(m1, column + 16), xj, a1);
      a2 = _mm512_fnmadd_ps(LoadHalf(m2, column + 32), xj, a2);
      a3 = _mm512_fnmadd_ps(LoadHalf(m3, column + 48), xj, a3);
    }
    _mm512_mask_storeu_ps(out, m0, a0);
    _mm512_mask_storeu_ps(out + 16, m1, a1);
    _mm512_mask_storeu_ps(out + 32, m2, a2);
    _mm512_mask_storeu_ps(out + 48, m3, a3);
  }
}

// SubtractColumns on half-precision columns: y[0, rows) −= Σ_j x_j p(:, j), four columns per pass.
SR_HALF inline void SubtractColumnsHalf(int rows, int cols, const std::uint16_t* p, Eigen::Index ld,
                                        const float* x, float* y) {
  int j = 0;
  for (; j + 4 <= cols; j += 4) {
    const __m512 x0 = _mm512_set1_ps(x[j]), x1 = _mm512_set1_ps(x[j + 1]),
                 x2 = _mm512_set1_ps(x[j + 2]), x3 = _mm512_set1_ps(x[j + 3]);
    const std::uint16_t *c0 = p + j * ld, *c1 = c0 + ld, *c2 = c1 + ld, *c3 = c2 + ld;
    for (int i = 0; i < rows; i += 16) {
      const __mmask16 m = Lanes(rows - i);
      __m512 a = _mm512_maskz_loadu_ps(m, y + i);
      a = _mm512_fnmadd_ps(LoadHalf(m, c0 + i), x0, a);
      a = _mm512_fnmadd_ps(LoadHalf(m, c1 + i), x1, a);
      a = _mm512_fnmadd_ps(LoadHalf(m, c2 + i), x2, a);
      a = _mm512_fnmadd_ps(LoadHalf(m, c3 + i), x3, a);
      _mm512_mask_storeu_ps(y + i, m, a);
    }
  }
  for (; j < cols; ++j) {
    const __m512 xj = _mm512_set1_ps(x[j]);
    const std::uint16_t* column = p + j * ld;
    for (int i = 0; i < rows; i += 16) {
      const __mmask16 m = Lanes(rows - i);
      const __m512 a = _mm512_maskz_loadu_ps(m, y + i);
      _mm512_mask_storeu_ps(y + i, m, _mm512_fnmadd_ps(LoadHalf(m, column + i), xj, a));
    }
  }
}

// A tile's chunk (lu_solve_avx512.h, LuPanels): y[0, rows) −= Σ_j x_j p(:, j), rows ≤
// kLuChunkRows, the chunk column-major with leading dimension `rows` (consecutive memory). The
// rows' sums stay in eight registers while the columns stream past in the order they are stored:
// each row takes the operations of SubtractColumnsHalf, in its order (the same bits), but with
// eight independent chains instead of one per 16 rows and a single pass over the chunk.
SR_HALF inline void SubtractChunkHalf(int rows, int cols, const std::uint16_t* p, const float* x,
                                      float* y) {
  static_assert(kLuChunkRows == 128, "eight registers of 16 rows");
  constexpr int kPrefetchColumns = 16;
  // Written out register by register: with the sums in an array GCC kept them on the stack.
  const __mmask16 m0 = Lanes(rows), m1 = Lanes(rows - 16), m2 = Lanes(rows - 32),
                  m3 = Lanes(rows - 48), m4 = Lanes(rows - 64), m5 = Lanes(rows - 80),
                  m6 = Lanes(rows - 96), m7 = Lanes(rows - 112);
  __m512 a0 = _mm512_maskz_loadu_ps(m0, y), a1 = _mm512_maskz_loadu_ps(m1, y + 16),
         a2 = _mm512_maskz_loadu_ps(m2, y + 32), a3 = _mm512_maskz_loadu_ps(m3, y + 48),
         a4 = _mm512_maskz_loadu_ps(m4, y + 64), a5 = _mm512_maskz_loadu_ps(m5, y + 80),
         a6 = _mm512_maskz_loadu_ps(m6, y + 96), a7 = _mm512_maskz_loadu_ps(m7, y + 112);
  for (int j = 0; j < cols; ++j) {
    const __m512 xj = _mm512_set1_ps(x[j]);
    const std::uint16_t* c = p + static_cast<std::ptrdiff_t>(j) * rows;
    const char* ahead = reinterpret_cast<const char*>(c + kPrefetchColumns * rows);
    for (int line = 0; line < 4; ++line) _mm_prefetch(ahead + 64 * line, _MM_HINT_T0);
    a0 = _mm512_fnmadd_ps(LoadHalf(m0, c), xj, a0);
    a1 = _mm512_fnmadd_ps(LoadHalf(m1, c + 16), xj, a1);
    a2 = _mm512_fnmadd_ps(LoadHalf(m2, c + 32), xj, a2);
    a3 = _mm512_fnmadd_ps(LoadHalf(m3, c + 48), xj, a3);
    a4 = _mm512_fnmadd_ps(LoadHalf(m4, c + 64), xj, a4);
    a5 = _mm512_fnmadd_ps(LoadHalf(m5, c + 80), xj, a5);
    a6 = _mm512_fnmadd_ps(LoadHalf(m6, c + 96), xj, a6);
    a7 = _mm512_fnmadd_ps(LoadHalf(m7, c + 112), xj, a7);
  }
  _mm512_mask_storeu_ps(y, m0, a0);
  _mm512_mask_storeu_ps(y + 16, m1, a1);
  _mm512_mask_storeu_ps(y + 32, m2, a2);
  _mm512_mask_storeu_ps(y + 48, m3, a3);
  _mm512_mask_storeu_ps(y + 64, m4, a4);
  _mm512_mask_storeu_ps(y + 80, m5, a5);
  _mm512_mask_storeu_ps(y + 96, m6, a6);
  _mm512_mask_storeu_ps(y + 112, m7, a7);
}

SR_HALF void LuSolveHalfParallel(int n, const std::uint16_t* lu, const int* pivots, float u_scale,
                                 float* x) {
  for (int i = 0; i < n; ++i)
    if (pivots[i] - 1 != i) std::swap(x[i], x[pivots[i] - 1]);
  const LuPanels panels = HalfFactorLayout(n);  // tiles (lu_solve_avx512.h)
#pragma omp parallel
  {
    for (int j0 = 0; j0 < n; j0 += kWideBlock) {  // L (unit diagonal), from the top
      const int j1 = std::min(j0 + kWideBlock, n), w = j1 - j0;
      const std::uint16_t* d = lu + panels.LowerDiagonal(j0);
      const std::ptrdiff_t ld = panels.DiagonalStride(w);
#pragma omp single
      for (int k = 0; k < w; ++k)
        SubtractColumnsHalf(w - k - 1, 1, d + k + 1 + k * ld, ld, x + j0 + k, x + j0 + k + 1);
#pragma omp for schedule(static)
      for (int r = j1; r < n; r += kChunkRows) {
        const int rows = std::min(kChunkRows, n - r);
        SubtractChunkHalf(rows, w, lu + panels.LowerChunk(j0, j1, r), x + j0, x + r);
      }
    }
#pragma omp for schedule(static)
    for (int i = 0; i < n; ++i) x[i] *= u_scale;
    for (int j1 = n; j1 > 0; j1 -= kWideBlock) {  // U, from the bottom
      const int j0 = std::max(j1 - kWideBlock, 0), w = j1 - j0;
      const std::uint16_t* d = lu + panels.UpperDiagonal(j0, j1);
      const std::ptrdiff_t ld = panels.DiagonalStride(w);
#pragma omp single
      for (int k = w - 1; k >= 0; --k) {
        x[j0 + k] /= HalfToFloat(d[k + k * ld]);
        SubtractColumnsHalf(k, 1, d + k * ld, ld, x + j0 + k, x + j0);
      }
#pragma omp for schedule(static)
      for (int r = 0; r < j0; r += kChunkRows) {
        const int rows = std::min(kChunkRows, j0 - r);
        SubtractChunkHalf(rows, w, lu + panels.UpperChunk(j0, j1, r), x + j0, x + r);
      }
    }
  }
}

}  // namespace

SR_HALF bool RoundLuToHalfAvx512(int n, const float* lu, std::uint16_t* half, float* u_scale) {
  const Eigen::Index ld = n;
  float largest = 0.0f;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i <= j; ++i) largest = std::max(largest, std::abs(lu[i + j * ld]));
  if (!std::isfinite(largest)) return false;
  const float scale = largest > 0.0f ? std::ldexp(1.0f, 14 - std::ilogb(largest)) : 1.0f;
  const __m512i lane = _mm512_set_epi32(15, 14, 13, 12, 11, 10, 9, 8, 7, 6, 5, 4, 3, 2, 1, 0);
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; i += 16) {
      const __mmask16 m = Lanes(n - i);
      // Rows i … i + 15 of column j: U (row ≤ j) scaled, L as it is.
      const __mmask16 upper =
          _mm512_cmple_epi32_mask(_mm512_add_epi32(lane, _mm512_set1_epi32(i)), _mm512_set1_epi32(j));
      __m512 v = _mm512_maskz_loadu_ps(m, lu + i + j * ld);
      v = _mm512_mask_mul_ps(v, upper, v, _mm512_set1_ps(scale));
      _mm256_mask_storeu_epi16(half + i + j * ld, m,
                               _mm512_cvtps_ph(v, _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC));
    }
  }
  *u_scale = scale;
  return true;
}

SR_HALF void LuSolveHalfAvx512(int n, const std::uint16_t* lu, const int* pivots, float u_scale,
                               float* x, PrefetchSpan then) {
  if (n >= kParallelLuSolve) return LuSolveHalfParallel(n, lu, pivots, u_scale, x);
  SpreadPrefetch spread(then, 2 * ((n + kBlock - 1) / kBlock));
  for (int i = 0; i < n; ++i)
    if (pivots[i] - 1 != i) std::swap(x[i], x[pivots[i] - 1]);
  const Eigen::Index ld = n;
  for (int j0 = 0; j0 < n; j0 += kBlock) {  // L (unit diagonal), blocks from the top
    const int j1 = std::min(j0 + kBlock, n);
    spread.Next();
    LowerTriangleHalf(j1 - j0, lu + j0 + j0 * ld, ld, x + j0);
    SubtractPanelHalf(n - j1, j1 - j0, lu + j1 + j0 * ld, ld, x + j0, x + j1);
  }
  for (int i = 0; i < n; ++i) x[i] *= u_scale;  // U's factors are scaled: U' x = scale y
  for (int j1 = n; j1 > 0; j1 -= kBlock) {  // U, blocks from the bottom
    const int j0 = std::max(j1 - kBlock, 0);
    spread.Next();
    UpperTriangleHalf(j1 - j0, lu + j0 + j0 * ld, ld, x + j0);
    SubtractPanelHalf(j0, j1 - j0, lu + j0 * ld, ld, x + j0, x);
  }
}

#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

// (F16C is not asked: every CPU with AVX-512 F has it, and clang 14's __builtin_cpu_supports
// does not know the name.)
bool HasLuSolveHalfAvx512() {
  static const bool has = __builtin_cpu_supports("avx512f") &&
                          __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512vl");
  return has;
}
#undef SR_HALF

#else
void LuSolveAvx512(int, const float*, const int*, float*) {}
bool HasLuSolveAvx512() { return false; }
bool RoundLuToHalfAvx512(int, const float*, std::uint16_t*, float*) { return false; }
void LuSolveHalfAvx512(int, const std::uint16_t*, const int*, float, float*) {}
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

bool HasLuSolveHalfAvx512() { return false; }
#endif

}  // namespace stokesrods
