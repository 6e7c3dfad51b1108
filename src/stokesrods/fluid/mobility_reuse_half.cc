// The reuse's differences D₁, D₂ in half precision: each step's extrapolation streams 𝕄_c
// (single) and D₁, D₂ (paper Fig. 1: three 390 × 390 matrices, 1.8 MB in single precision, with
// the extrapolated 𝕄 and the preconditioner's LU above this CPU's 2 MB L2); D₁ and D₂ in half
// precision stream half their bytes, widened 16 at a time (vcvtph2ps) as they are read.
// bench_step BM_ReuseExtrapolate (one thread, Fig. 1's size): 61 µs in single precision, 33 µs.
// On AVX2 (no masks for 16-bit lanes) whole blocks of 8 by vectors and the last entries one by
// one, by the same IEEE conversions and fused multiply–adds: the same bits as AVX-512.
#include "stokesrods/fluid/mobility_reuse_half.h"

#include <immintrin.h>

#include <algorithm>
#include <cmath>

#include "stokesrods/common/assert.h"
#include "stokesrods/common/cpu_features.h"
#include "stokesrods/solver/lu_solve_avx512.h"  // HasLuSolveHalfAvx512: the same CPU features

namespace stokesrods {

#if defined(__GNUC__) && defined(__x86_64__)
#define SR_HALF __attribute__((target("avx512f,avx512bw,avx512vl,f16c")))
// (GCC 12's avx512fintrin.h warns on its own _mm512_undefined_ps in vcvtph2ps, GCC bug 105593.)
#if !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
namespace {

// The first min(count, 16) lanes, none if count ≤ 0.
inline __mmask16 Lanes(Eigen::Index count) {
  return static_cast<__mmask16>((1u << std::clamp<Eigen::Index>(count, 0, 16)) - 1u);
}

SR_HALF inline __m512 LoadHalf(__mmask16 m, const std::uint16_t* p) {
  return _mm512_cvtph_ps(_mm256_maskz_loadu_epi16(m, p));
}

// σ for the largest |entry| `top`.
float HalfScale(float top) {
  return top > 0.0f ? std::ldexp(1.0f, std::min(14 - std::ilogb(top), 126)) : 1.0f;
}

// The largest |entry| of d in *top; false when an entry is infinite or not a number.
SR_HALF bool LargestAvx512(Eigen::Index n, const float* d, float* top) {
  __m512 largest = _mm512_setzero_ps();
  __m512 poison = _mm512_setzero_ps();  // not a number once an entry is infinite or not a number
  for (Eigen::Index i = 0; i < n; i += 16) {
    const __m512 v = _mm512_maskz_loadu_ps(Lanes(n - i), d + i);
    largest = _mm512_max_ps(largest, _mm512_abs_ps(v));
    poison = _mm512_add_ps(poison, _mm512_mul_ps(v, _mm512_setzero_ps()));
  }
  *top = _mm512_reduce_max_ps(largest);
  return !std::isnan(_mm512_reduce_add_ps(poison));
}

// half = σ d in half precision, d ← half / σ.
SR_HALF void ToHalfAvx512(Eigen::Index n, float* d, std::uint16_t* half, float scale) {
  const __m512 up = _mm512_set1_ps(scale), down = _mm512_set1_ps(1.0f / scale);
  for (Eigen::Index i = 0; i < n; i += 16) {
    const __mmask16 m = Lanes(n - i);
    const __m256i h = _mm512_cvtps_ph(_mm512_mul_ps(_mm512_maskz_loadu_ps(m, d + i), up),
                                      _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC);
    _mm256_mask_storeu_epi16(half + i, m, h);
    _mm512_mask_storeu_ps(d + i, m, _mm512_mul_ps(_mm512_cvtph_ps(h), down));
  }
}

SR_HALF void ExtrapolateHalfAvx512(Eigen::Index n, const float* base, float a,
                                   const std::uint16_t* slope, float b, const std::uint16_t* curve,
                                   float* out) {
  const __m512 av = _mm512_set1_ps(a), bv = _mm512_set1_ps(b);
  for (Eigen::Index i = 0; i < n; i += 16) {
    const __mmask16 m = Lanes(n - i);
    __m512 v = _mm512_fmadd_ps(LoadHalf(m, slope + i), av, _mm512_maskz_loadu_ps(m, base + i));
    if (curve) v = _mm512_fmadd_ps(LoadHalf(m, curve + i), bv, v);
    _mm512_mask_storeu_ps(out + i, m, v);
  }
}

#if !defined(__clang__)
#pragma GCC diagnostic pop
#endif
#undef SR_HALF

#define SR_F16C __attribute__((target("avx2,fma,f16c")))
constexpr int kRound = _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC;

SR_F16C bool LargestF16c(Eigen::Index n, const float* d, float* top) {
  const __m256 sign = _mm256_set1_ps(-0.0f);
  __m256 largest = _mm256_setzero_ps();
  __m256 poison = _mm256_setzero_ps();  // as LargestAvx512's
  Eigen::Index i = 0;
  for (; i + 8 <= n; i += 8) {
    const __m256 v = _mm256_loadu_ps(d + i);
    largest = _mm256_max_ps(largest, _mm256_andnot_ps(sign, v));
    poison = _mm256_add_ps(poison, _mm256_mul_ps(v, _mm256_setzero_ps()));
  }
  alignas(32) float lanes[8], poisoned[8];
  _mm256_store_ps(lanes, largest);
  _mm256_store_ps(poisoned, poison);
  float largest_entry = 0.0f, bad = 0.0f;
  for (int l = 0; l < 8; ++l) largest_entry = std::max(largest_entry, lanes[l]), bad += poisoned[l];
  for (Eigen::Index j = i; j < n; ++j)
    largest_entry = std::max(largest_entry, std::abs(d[j])), bad += d[j] * 0.0f;
  *top = largest_entry;
  return !std::isnan(bad);
}

SR_F16C void ToHalfF16c(Eigen::Index n, float* d, std::uint16_t* half, float scale) {
  const __m256 up = _mm256_set1_ps(scale), down = _mm256_set1_ps(1.0f / scale);
  Eigen::Index i = 0;
  for (; i + 8 <= n; i += 8) {
    const __m128i h = _mm256_cvtps_ph(_mm256_mul_ps(_mm256_loadu_ps(d + i), up), kRound);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(half + i), h);
    _mm256_storeu_ps(d + i, _mm256_mul_ps(_mm256_cvtph_ps(h), down));
  }
  for (; i < n; ++i) {
    half[i] = _cvtss_sh(d[i] * scale, kRound);
    d[i] = _cvtsh_ss(half[i]) * (1.0f / scale);
  }
}

SR_F16C void ExtrapolateHalfF16c(Eigen::Index n, const float* base, float a,
                                 const std::uint16_t* slope, float b, const std::uint16_t* curve,
                                 float* out) {
  const __m256 av = _mm256_set1_ps(a), bv = _mm256_set1_ps(b);
  Eigen::Index i = 0;
  for (; i + 8 <= n; i += 8) {
    const __m128i s = _mm_loadu_si128(reinterpret_cast<const __m128i*>(slope + i));
    __m256 v = _mm256_fmadd_ps(_mm256_cvtph_ps(s), av, _mm256_loadu_ps(base + i));
    if (curve) {
      const __m128i c = _mm_loadu_si128(reinterpret_cast<const __m128i*>(curve + i));
      v = _mm256_fmadd_ps(_mm256_cvtph_ps(c), bv, v);
    }
    _mm256_storeu_ps(out + i, v);
  }
  for (; i < n; ++i) {
    float v = std::fma(_cvtsh_ss(slope[i]), a, base[i]);
    if (curve) v = std::fma(_cvtsh_ss(curve[i]), b, v);
    out[i] = v;
  }
}
#undef SR_F16C

bool HasF16c() {
  static const bool has = CpuHasAvx2FmaF16c();
  return has;
}

}  // namespace

bool HasHalfDifferences() { return HasLuSolveHalfAvx512() || HasF16c(); }

float RoundToHalf(Eigen::Index n, float* d, std::uint16_t* half, bool f16c) {
  const bool wide = !f16c && HasLuSolveHalfAvx512();
  SR_ASSERT(wide || HasF16c(), "half precision needs AVX-512 BW or F16C");
  // Each part's largest |entry|, then each part rounded at the scale of the whole: the same bits
  // on any number of threads (on a hundred helices the near corrections' D₁, D₂, 6 × 138 000
  // entries, at each assembly and remap).
  float top[2] = {0.0f, 0.0f};
  bool finite[2] = {true, true};
  ForTwoParts(n, [&](int part, Eigen::Index first, Eigen::Index count) {
    finite[part] = wide ? LargestAvx512(count, d + first, &top[part])
                        : LargestF16c(count, d + first, &top[part]);
  });
  if (!finite[0] || !finite[1]) return 0.0f;
  const float scale = HalfScale(std::max(top[0], top[1]));
  ForTwoParts(n, [&](int, Eigen::Index first, Eigen::Index count) {
    if (wide)
      ToHalfAvx512(count, d + first, half + first, scale);
    else
      ToHalfF16c(count, d + first, half + first, scale);
  });
  return scale;
}

void ExtrapolateHalf(Eigen::Index n, const float* base, float a, const std::uint16_t* slope,
                     float b, const std::uint16_t* curve, float* out, bool f16c) {
  if (!f16c && HasLuSolveHalfAvx512())
    return ExtrapolateHalfAvx512(n, base, a, slope, b, curve, out);
  SR_ASSERT(HasF16c(), "half precision needs AVX-512 BW or F16C");
  ExtrapolateHalfF16c(n, base, a, slope, b, curve, out);
}

#else
bool HasHalfDifferences() { return false; }
float RoundToHalf(Eigen::Index, float*, std::uint16_t*, bool) { return 0.0f; }
void ExtrapolateHalf(Eigen::Index, const float*, float, const std::uint16_t*, float,
                     const std::uint16_t*, float*, bool) {}
#endif

}  // namespace stokesrods
