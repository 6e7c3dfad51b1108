// The blocked substitutions of lu_solve_avx512.cc on AVX2 with FMA and F16C, for CPUs without
// AVX-512 (there DenseLu<float> otherwise solves by getrs, whose strsv runs a column at a time,
// and keeps kHalf factors in single precision). One template over the factors' type, float or
// IEEE half (widened eight at a time by vcvtph2ps as they are read); vectors of eight, four of
// them per pass of SubtractPanel (32 rows), and the rows past the last whole vector one by one
// (no masked loads: AVX2 has none for halves). Each row's operations are those of the AVX-512
// kernels, fused multiply–adds in the same order.
#include <immintrin.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <type_traits>
#include <utility>

#include <Eigen/Core>

#include "stokesrods/common/cpu_features.h"
#include "stokesrods/solver/lu_solve_avx512.h"

namespace stokesrods {

#if defined(__GNUC__) && defined(__x86_64__)
#define SR_AVX2 __attribute__((target("avx2,fma,f16c")))
#define SR_AVX2_INLINE __attribute__((target("avx2,fma,f16c"), always_inline)) inline
namespace {

constexpr int kRound = _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC;

// Eight entries widened to single precision.
SR_AVX2_INLINE __m256 Load8(const float* p) { return _mm256_loadu_ps(p); }
SR_AVX2_INLINE __m256 Load8(const std::uint16_t* p) {
  return _mm256_cvtph_ps(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p)));
}
SR_AVX2_INLINE float ToFloat(float v) { return v; }
SR_AVX2_INLINE float ToFloat(std::uint16_t h) { return _cvtsh_ss(h); }

// y[0, count) −= x · c[0, count) (the small triangles of the blocks, a column's rows): whole
// vectors of eight, the last rows one by one by the same fused multiply–add.
template <class E>
SR_AVX2_INLINE void AxpyShort(int count, const E* c, float x, float* y) {
  const __m256 xv = _mm256_set1_ps(x);
  int i = 0;
  for (; i + 8 <= count; i += 8)
    _mm256_storeu_ps(y + i, _mm256_fnmadd_ps(Load8(c + i), xv, _mm256_loadu_ps(y + i)));
  for (; i < count; ++i) y[i] = std::fma(-ToFloat(c[i]), x, y[i]);
}

// y[0, rows) −= P x, P (rows × cols, column-major, leading dimension ld): 32 rows at a time in
// four accumulators, the panel's columns streamed once; then whole vectors of eight; the last
// rows one by one. Each row's sum runs over the columns in order.
template <class E>
SR_AVX2_INLINE void SubtractPanel(int rows, int cols, const E* p, Eigen::Index ld, const float* x,
                                  float* y) {
  int i0 = 0;
  for (; i0 + 32 <= rows; i0 += 32) {
    float* out = y + i0;
    __m256 a0 = _mm256_loadu_ps(out), a1 = _mm256_loadu_ps(out + 8),
           a2 = _mm256_loadu_ps(out + 16), a3 = _mm256_loadu_ps(out + 24);
    for (int j = 0; j < cols; ++j) {
      const __m256 xj = _mm256_set1_ps(x[j]);
      const E* column = p + j * ld + i0;
      a0 = _mm256_fnmadd_ps(Load8(column), xj, a0);
      a1 = _mm256_fnmadd_ps(Load8(column + 8), xj, a1);
      a2 = _mm256_fnmadd_ps(Load8(column + 16), xj, a2);
      a3 = _mm256_fnmadd_ps(Load8(column + 24), xj, a3);
    }
    _mm256_storeu_ps(out, a0);
    _mm256_storeu_ps(out + 8, a1);
    _mm256_storeu_ps(out + 16, a2);
    _mm256_storeu_ps(out + 24, a3);
  }
  for (; i0 + 8 <= rows; i0 += 8) {
    __m256 a = _mm256_loadu_ps(y + i0);
    for (int j = 0; j < cols; ++j)
      a = _mm256_fnmadd_ps(Load8(p + j * ld + i0), _mm256_set1_ps(x[j]), a);
    _mm256_storeu_ps(y + i0, a);
  }
  for (; i0 < rows; ++i0) {
    float a = y[i0];
    for (int j = 0; j < cols; ++j) a = std::fma(-ToFloat(p[j * ld + i0]), x[j], a);
    y[i0] = a;
  }
}

// y[0, rows) −= Σ_j x_j p(:, j), four columns per pass over y (the parallel solve's chunks).
template <class E>
SR_AVX2_INLINE void SubtractColumns(int rows, int cols, const E* p, Eigen::Index ld,
                                    const float* x, float* y) {
  int j = 0;
  for (; j + 4 <= cols; j += 4) {
    const __m256 x0 = _mm256_set1_ps(x[j]), x1 = _mm256_set1_ps(x[j + 1]),
                 x2 = _mm256_set1_ps(x[j + 2]), x3 = _mm256_set1_ps(x[j + 3]);
    const E *c0 = p + j * ld, *c1 = c0 + ld, *c2 = c1 + ld, *c3 = c2 + ld;
    int i = 0;
    for (; i + 8 <= rows; i += 8) {
      __m256 a = _mm256_loadu_ps(y + i);
      a = _mm256_fnmadd_ps(Load8(c0 + i), x0, a);
      a = _mm256_fnmadd_ps(Load8(c1 + i), x1, a);
      a = _mm256_fnmadd_ps(Load8(c2 + i), x2, a);
      a = _mm256_fnmadd_ps(Load8(c3 + i), x3, a);
      _mm256_storeu_ps(y + i, a);
    }
    for (; i < rows; ++i) {
      float a = std::fma(-ToFloat(c0[i]), x[j], y[i]);
      a = std::fma(-ToFloat(c1[i]), x[j + 1], a);
      a = std::fma(-ToFloat(c2[i]), x[j + 2], a);
      y[i] = std::fma(-ToFloat(c3[i]), x[j + 3], a);
    }
  }
  for (; j < cols; ++j) AxpyShort(rows, p + j * ld, x[j], y);
}

// A tile's chunk (LuPanels: column-major, leading dimension `rows`, consecutive memory): y[0,
// rows) −= Σ_j x_j p(:, j), 64 rows at a time in eight accumulators over all the chunk's columns,
// the next columns prefetched ahead (the first pass brings in whole columns; the later passes
// find them in cache); the rows past the last 64 by SubtractColumns. Each row's operations are
// SubtractColumns' in its order (the same bits), and those of the AVX-512 SubtractChunkHalf.
template <class E>
SR_AVX2_INLINE void SubtractChunk(int rows, int cols, const E* p, const float* x, float* y) {
  constexpr int kPrefetchColumns = 16;  // as the AVX-512 kernel's (4 KB of halves ahead)
  const std::ptrdiff_t column_bytes = static_cast<std::ptrdiff_t>(rows) * sizeof(E);
  int i0 = 0;
  for (; i0 + 64 <= rows; i0 += 64) {
    float* out = y + i0;
    __m256 a0 = _mm256_loadu_ps(out), a1 = _mm256_loadu_ps(out + 8),
           a2 = _mm256_loadu_ps(out + 16), a3 = _mm256_loadu_ps(out + 24),
           a4 = _mm256_loadu_ps(out + 32), a5 = _mm256_loadu_ps(out + 40),
           a6 = _mm256_loadu_ps(out + 48), a7 = _mm256_loadu_ps(out + 56);
    for (int j = 0; j < cols; ++j) {
      const E* column = p + static_cast<std::ptrdiff_t>(j) * rows;
      if (i0 == 0) {
        const char* ahead = reinterpret_cast<const char*>(column + kPrefetchColumns * rows);
        for (std::ptrdiff_t b = 0; b < column_bytes; b += 64) _mm_prefetch(ahead + b, _MM_HINT_T0);
      }
      const __m256 xj = _mm256_set1_ps(x[j]);
      const E* c = column + i0;
      a0 = _mm256_fnmadd_ps(Load8(c), xj, a0);
      a1 = _mm256_fnmadd_ps(Load8(c + 8), xj, a1);
      a2 = _mm256_fnmadd_ps(Load8(c + 16), xj, a2);
      a3 = _mm256_fnmadd_ps(Load8(c + 24), xj, a3);
      a4 = _mm256_fnmadd_ps(Load8(c + 32), xj, a4);
      a5 = _mm256_fnmadd_ps(Load8(c + 40), xj, a5);
      a6 = _mm256_fnmadd_ps(Load8(c + 48), xj, a6);
      a7 = _mm256_fnmadd_ps(Load8(c + 56), xj, a7);
    }
    _mm256_storeu_ps(out, a0);
    _mm256_storeu_ps(out + 8, a1);
    _mm256_storeu_ps(out + 16, a2);
    _mm256_storeu_ps(out + 24, a3);
    _mm256_storeu_ps(out + 32, a4);
    _mm256_storeu_ps(out + 40, a5);
    _mm256_storeu_ps(out + 48, a6);
    _mm256_storeu_ps(out + 56, a7);
  }
  if (i0 < rows) SubtractColumns(rows - i0, cols, p + i0, rows, x, y + i0);
}

// U's factors in half precision are scaled by u_scale: U' x = u_scale y.
template <class E>
SR_AVX2_INLINE void ScaleForU(int n, float u_scale, float* x) {
  if constexpr (std::is_same_v<E, std::uint16_t>)
    for (int i = 0; i < n; ++i) x[i] *= u_scale;
}

// The solves' pieces, out of line (one call per block of columns): clang outlines an OpenMP
// region into a function without its parent's target attributes, and a half conversion inlined
// there became a library call (__gnu_h2f_ieee, which the fuzzer's link lacks). Called from the
// region, these keep theirs.
#define SR_AVX2_CALLED __attribute__((target("avx2,fma,f16c"), noinline))
// The triangle of a block of w columns, d its diagonal block (leading dimension ld) and x its
// rows: L's, x[k + 1, w) −= x_k L(k + 1 … w − 1, k); U's from the bottom.
template <class E>
SR_AVX2_CALLED void LowerTriangle(int w, const E* d, Eigen::Index ld, float* x) {
  for (int k = 0; k < w; ++k) AxpyShort(w - k - 1, d + k + 1 + k * ld, x[k], x + k + 1);
}
template <class E>
SR_AVX2_CALLED void UpperTriangle(int w, const E* d, Eigen::Index ld, float* x) {
  for (int k = w - 1; k >= 0; --k) {
    x[k] /= ToFloat(d[k + k * ld]);
    AxpyShort(k, d + k * ld, x[k], x);
  }
}
template <class E>
SR_AVX2_CALLED void SubtractColumnsCalled(int rows, int cols, const E* p, Eigen::Index ld,
                                          const float* x, float* y) {
  SubtractColumns(rows, cols, p, ld, x, y);
}
template <class E>
SR_AVX2_CALLED void SubtractChunkCalled(int rows, int cols, const E* p, const float* x, float* y) {
  SubtractChunk(rows, cols, p, x, y);
}
template <class E>
SR_AVX2_CALLED void ScaleForUCalled(int n, float u_scale, float* x) {
  ScaleForU<E>(n, u_scale, x);
}
#undef SR_AVX2_CALLED

// Single-precision factors column-major, half ones in tiles (LuPanels).
template <class E>
SR_AVX2 void LuSolveParallel(int n, const E* lu, const int* pivots, float u_scale, float* x) {
  for (int i = 0; i < n; ++i)
    if (pivots[i] - 1 != i) std::swap(x[i], x[pivots[i] - 1]);
  const LuPanels panels{.n = n, .tiled = std::is_same_v<E, std::uint16_t>};
#pragma omp parallel
  {
    for (int j0 = 0; j0 < n; j0 += kLuWideBlock) {  // L (unit diagonal), from the top
      const int j1 = std::min(j0 + kLuWideBlock, n), w = j1 - j0;
#pragma omp single
      LowerTriangle(w, lu + panels.LowerDiagonal(j0), panels.DiagonalStride(w), x + j0);
#pragma omp for schedule(static)
      for (int r = j1; r < n; r += kLuChunkRows) {
        const int rows = std::min(kLuChunkRows, n - r);
        if (panels.tiled)  // consecutive chunks
          SubtractChunkCalled(rows, w, lu + panels.LowerChunk(j0, j1, r), x + j0, x + r);
        else
          SubtractColumnsCalled(rows, w, lu + panels.LowerChunk(j0, j1, r),
                                panels.ChunkStride(rows), x + j0, x + r);
      }
    }
#pragma omp single
    ScaleForUCalled<E>(n, u_scale, x);
    for (int j1 = n; j1 > 0; j1 -= kLuWideBlock) {  // U, from the bottom
      const int j0 = std::max(j1 - kLuWideBlock, 0), w = j1 - j0;
#pragma omp single
      UpperTriangle(w, lu + panels.UpperDiagonal(j0, j1), panels.DiagonalStride(w), x + j0);
#pragma omp for schedule(static)
      for (int r = 0; r < j0; r += kLuChunkRows) {
        const int rows = std::min(kLuChunkRows, j0 - r);
        if (panels.tiled)  // consecutive chunks
          SubtractChunkCalled(rows, w, lu + panels.UpperChunk(j0, j1, r), x + j0, x + r);
        else
          SubtractColumnsCalled(rows, w, lu + panels.UpperChunk(j0, j1, r),
                                panels.ChunkStride(rows), x + j0, x + r);
      }
    }
  }
}

template <class E>
SR_AVX2 void LuSolve(int n, const E* lu, const int* pivots, float u_scale, float* x,
                     PrefetchSpan then = {}) {
  if (n >= kParallelLuSolve) return LuSolveParallel(n, lu, pivots, u_scale, x);
  SpreadPrefetch spread(then, 2 * ((n + kLuBlock - 1) / kLuBlock));
  for (int i = 0; i < n; ++i)
    if (pivots[i] - 1 != i) std::swap(x[i], x[pivots[i] - 1]);
  const Eigen::Index ld = n;
  for (int j0 = 0; j0 < n; j0 += kLuBlock) {  // L (unit diagonal), blocks from the top
    const int j1 = std::min(j0 + kLuBlock, n);
    spread.Next();
    LowerTriangle(j1 - j0, lu + j0 + j0 * ld, ld, x + j0);
    SubtractPanel(n - j1, j1 - j0, lu + j1 + j0 * ld, ld, x + j0, x + j1);
  }
  ScaleForU<E>(n, u_scale, x);
  for (int j1 = n; j1 > 0; j1 -= kLuBlock) {  // U, blocks from the bottom
    const int j0 = std::max(j1 - kLuBlock, 0);
    spread.Next();
    UpperTriangle(j1 - j0, lu + j0 + j0 * ld, ld, x + j0);
    SubtractPanel(j0, j1 - j0, lu + j0 * ld, ld, x + j0, x);
  }
}

}  // namespace

void LuSolveAvx2(int n, const float* lu, const int* pivots, float* x) {
  LuSolve(n, lu, pivots, 1.0f, x);
}

void LuSolveHalfAvx2(int n, const std::uint16_t* half, const int* pivots, float u_scale,
                     float* x, PrefetchSpan then) {
  LuSolve(n, half, pivots, u_scale, x, then);
}

SR_AVX2 bool RoundLuToHalfF16c(int n, const float* lu, std::uint16_t* half, float* u_scale) {
  const Eigen::Index ld = n;
  float largest = 0.0f;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i <= j; ++i) largest = std::max(largest, std::abs(lu[i + j * ld]));
  if (!std::isfinite(largest)) return false;
  const float scale = largest > 0.0f ? std::ldexp(1.0f, 14 - std::ilogb(largest)) : 1.0f;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {  // U (row ≤ j) scaled, L as it is
      const float v = lu[i + j * ld];
      half[i + j * ld] = _cvtss_sh(i <= j ? v * scale : v, kRound);
    }
  *u_scale = scale;
  return true;
}

bool HasLuSolveAvx2() {
  static const bool has = CpuHasAvx2FmaF16c();
  return has;
}
#undef SR_AVX2
#undef SR_AVX2_INLINE

#else
void LuSolveAvx2(int, const float*, const int*, float*) {}
void LuSolveHalfAvx2(int, const std::uint16_t*, const int*, float, float*) {}
bool RoundLuToHalfF16c(int, const float*, std::uint16_t*, float*) { return false; }
bool HasLuSolveAvx2() { return false; }
#endif

}  // namespace stokesrods
