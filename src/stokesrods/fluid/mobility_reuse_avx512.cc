// The reuse's differences D₁, D₂ in half precision: each step's extrapolation streams 𝕄_c
// (single) and D₁, D₂ (paper Fig. 1: three 390 × 390 matrices, 1.8 MB in single precision, with
// the extrapolated 𝕄 and the preconditioner's LU above this CPU's 2 MB L2); D₁ and D₂ in half
// precision stream half their bytes, widened 16 at a time (vcvtph2ps) as they are read.
// bench_step BM_ReuseExtrapolate (one thread, Fig. 1's size): 61 µs in single precision, 33 µs.
#include "stokesrods/fluid/mobility_reuse_avx512.h"

#include <immintrin.h>

#include <algorithm>
#include <cmath>

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

}  // namespace

SR_HALF float RoundToHalfAvx512(Eigen::Index n, float* d, std::uint16_t* half) {
  __m512 largest = _mm512_setzero_ps();
  __m512 poison = _mm512_setzero_ps();  // not a number once an entry is infinite or not a number
  for (Eigen::Index i = 0; i < n; i += 16) {
    const __m512 v = _mm512_maskz_loadu_ps(Lanes(n - i), d + i);
    largest = _mm512_max_ps(largest, _mm512_abs_ps(v));
    poison = _mm512_add_ps(poison, _mm512_mul_ps(v, _mm512_setzero_ps()));
  }
  if (std::isnan(_mm512_reduce_add_ps(poison))) return 0.0f;
  const float top = _mm512_reduce_max_ps(largest);
  const float scale = top > 0.0f ? std::ldexp(1.0f, std::min(14 - std::ilogb(top), 126)) : 1.0f;
  const __m512 up = _mm512_set1_ps(scale), down = _mm512_set1_ps(1.0f / scale);
  for (Eigen::Index i = 0; i < n; i += 16) {
    const __mmask16 m = Lanes(n - i);
    const __m256i h = _mm512_cvtps_ph(_mm512_mul_ps(_mm512_maskz_loadu_ps(m, d + i), up),
                                      _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC);
    _mm256_mask_storeu_epi16(half + i, m, h);
    _mm512_mask_storeu_ps(d + i, m, _mm512_mul_ps(_mm512_cvtph_ps(h), down));
  }
  return scale;
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

#else
float RoundToHalfAvx512(Eigen::Index, float*, std::uint16_t*) { return 0.0f; }
void ExtrapolateHalfAvx512(Eigen::Index, const float*, float, const std::uint16_t*, float,
                           const std::uint16_t*, float*) {}
#endif

}  // namespace stokesrods
