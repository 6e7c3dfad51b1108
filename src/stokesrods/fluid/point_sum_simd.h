// The Stokeslet sums over ranges of sources at K targets at once (point_sum_kernels.h), written
// once over the vectors of an instruction set: Avx512<T> (16 floats or 8 doubles) and Avx2<T> (8
// or 4). Included only by point_sum_avx512.cc and point_sum_avx2.cc, each compiled for its set
// alone (-mavx512f; -mavx2 -mfma), so everything here has internal linkage.
//
// The arithmetic is that of the portable loops (stokeslet_sum.cc) with fused multiply–adds and
// the lanes kept in registers, and
//   - 1/R³ as 1/R times 1/R², one multiplication fewer per pair than cubing 1/R;
//   - in single precision 1/R by the hardware's estimate (AVX-512 rsqrt14: 14 bits; AVX2 rsqrt:
//     12 bits) and one Newton step y (3 − a y²)/2 (≈ 3 and ≈ 4 ulp), instead of the IEEE
//     division and square root, which bounded the loops: on an Intel Xeon (20 helices, direct
//     sum, one thread) float 1.83 → 1.61 ms; on an AMD EPYC without AVX-512 see
//     point_sum_avx2.cc;
//   - in double on AVX-512 the estimate and two Newton steps y + y (1 − a y²)/2 (≈ 1 ulp; the
//     division and square root took ≈ 40 cycles per 8 lanes on the Xeon); on AVX2, which has no
//     estimate in double, the IEEE division and square root;
//   - K targets per pass over the sources: each block of sources is loaded once for all K (one
//     target alone reads 7 vectors per block, and its loop ran at less than half of the
//     multiply–add pipes' rate on the Xeon: 27 cycles per block of 16 instead of ~12). Each
//     target's arithmetic, and the order of its sums, are those of K = 1.
// Any ranges: a block that runs past a range's end is masked, its missing lanes read as a source
// at distance ≥ 1 of zero strength (they add exactly zero).
#pragma once

#include <immintrin.h>

#include "stokesrods/fluid/point_sum_kernels.h"

// GCC 12's avx512fintrin.h warns on its own _mm512_undefined_ps (GCC bug 105593).
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif

namespace stokesrods {
namespace {

#if defined(__AVX512F__)
template <class T>
struct Avx512;
template <>
struct Avx512<float> {
  using V = __m512;
  using Mask = __mmask16;
  static constexpr int kLanes = 16;
  static Mask MaskFirst(int left) {
    return static_cast<Mask>(left >= kLanes ? ~0u : (1u << left) - 1u);
  }
  static V Set(float v) { return _mm512_set1_ps(v); }
  static V Load(Mask m, const float* p) { return _mm512_maskz_loadu_ps(m, p); }
  static V LoadOr(V fill, Mask m, const float* p) { return _mm512_mask_loadu_ps(fill, m, p); }
  static V Sub(V a, V b) { return _mm512_sub_ps(a, b); }
  static V Add(V a, V b) { return _mm512_add_ps(a, b); }
  static V Mul(V a, V b) { return _mm512_mul_ps(a, b); }
  static V Fma(V a, V b, V c) { return _mm512_fmadd_ps(a, b, c); }
  static V InverseSqrt(V a) {
    const V y = _mm512_rsqrt14_ps(a);
    const V t = _mm512_fnmadd_ps(_mm512_mul_ps(a, y), y, Set(3.0f));
    return _mm512_mul_ps(_mm512_mul_ps(Set(0.5f), y), t);
  }
  static double Sum(V a) { return _mm512_reduce_add_ps(a); }
};
template <>
struct Avx512<double> {
  using V = __m512d;
  using Mask = __mmask8;
  static constexpr int kLanes = 8;
  static Mask MaskFirst(int left) {
    return static_cast<Mask>(left >= kLanes ? ~0u : (1u << left) - 1u);
  }
  static V Set(double v) { return _mm512_set1_pd(v); }
  static V Load(Mask m, const double* p) { return _mm512_maskz_loadu_pd(m, p); }
  static V LoadOr(V fill, Mask m, const double* p) { return _mm512_mask_loadu_pd(fill, m, p); }
  static V Sub(V a, V b) { return _mm512_sub_pd(a, b); }
  static V Add(V a, V b) { return _mm512_add_pd(a, b); }
  static V Mul(V a, V b) { return _mm512_mul_pd(a, b); }
  static V Fma(V a, V b, V c) { return _mm512_fmadd_pd(a, b, c); }
  static V InverseSqrt(V a) {
    V y = _mm512_rsqrt14_pd(a);
    for (int step = 0; step < 2; ++step) {
      const V r = _mm512_fnmadd_pd(_mm512_mul_pd(a, y), y, Set(1.0));
      y = _mm512_fmadd_pd(_mm512_mul_pd(y, r), Set(0.5), y);
    }
    return y;
  }
  static double Sum(V a) { return _mm512_reduce_add_pd(a); }
};
#endif  // __AVX512F__

#if defined(__AVX2__) && defined(__FMA__)
// AVX2 has no mask registers: a mask is a vector of all-ones lanes, and a whole block (the
// common case, a branch the predictor learns) is read by plain loads.
struct Avx2Mask {
  __m256i lanes;
  bool whole;
};
template <class T>
struct Avx2;
template <>
struct Avx2<float> {
  using V = __m256;
  using Mask = Avx2Mask;
  static constexpr int kLanes = 8;
  static Mask MaskFirst(int left) {
    return {_mm256_cmpgt_epi32(_mm256_set1_epi32(left), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7)),
            left >= kLanes};
  }
  static V Set(float v) { return _mm256_set1_ps(v); }
  static V Load(const Mask& m, const float* p) {
    return m.whole ? _mm256_loadu_ps(p) : _mm256_maskload_ps(p, m.lanes);
  }
  static V LoadOr(V fill, const Mask& m, const float* p) {
    return m.whole ? _mm256_loadu_ps(p)
                   : _mm256_blendv_ps(fill, _mm256_maskload_ps(p, m.lanes),
                                      _mm256_castsi256_ps(m.lanes));
  }
  static V Sub(V a, V b) { return _mm256_sub_ps(a, b); }
  static V Add(V a, V b) { return _mm256_add_ps(a, b); }
  static V Mul(V a, V b) { return _mm256_mul_ps(a, b); }
  static V Fma(V a, V b, V c) { return _mm256_fmadd_ps(a, b, c); }
  static V InverseSqrt(V a) {
    const V y = _mm256_rsqrt_ps(a);
    const V t = _mm256_fnmadd_ps(_mm256_mul_ps(a, y), y, Set(3.0f));
    return _mm256_mul_ps(_mm256_mul_ps(Set(0.5f), y), t);
  }
  static double Sum(V a) {
    __m128 s = _mm_add_ps(_mm256_castps256_ps128(a), _mm256_extractf128_ps(a, 1));
    s = _mm_add_ps(s, _mm_movehl_ps(s, s));
    s = _mm_add_ss(s, _mm_movehdup_ps(s));
    return _mm_cvtss_f32(s);
  }
};
template <>
struct Avx2<double> {
  using V = __m256d;
  using Mask = Avx2Mask;
  static constexpr int kLanes = 4;
  static Mask MaskFirst(int left) {
    return {_mm256_cmpgt_epi64(_mm256_set1_epi64x(left), _mm256_setr_epi64x(0, 1, 2, 3)),
            left >= kLanes};
  }
  static V Set(double v) { return _mm256_set1_pd(v); }
  static V Load(const Mask& m, const double* p) {
    return m.whole ? _mm256_loadu_pd(p) : _mm256_maskload_pd(p, m.lanes);
  }
  static V LoadOr(V fill, const Mask& m, const double* p) {
    return m.whole ? _mm256_loadu_pd(p)
                   : _mm256_blendv_pd(fill, _mm256_maskload_pd(p, m.lanes),
                                      _mm256_castsi256_pd(m.lanes));
  }
  static V Sub(V a, V b) { return _mm256_sub_pd(a, b); }
  static V Add(V a, V b) { return _mm256_add_pd(a, b); }
  static V Mul(V a, V b) { return _mm256_mul_pd(a, b); }
  static V Fma(V a, V b, V c) { return _mm256_fmadd_pd(a, b, c); }
  static V InverseSqrt(V a) { return _mm256_div_pd(Set(1.0), _mm256_sqrt_pd(a)); }
  static double Sum(V a) {
    __m128d s = _mm_add_pd(_mm256_castpd256_pd128(a), _mm256_extractf128_pd(a, 1));
    return _mm_cvtsd_f64(_mm_add_sd(s, _mm_unpackhi_pd(s, s)));
  }
};
#endif  // __AVX2__ && __FMA__

// w[k] += the sum over the ranges at x[k], k < K, on the vectors of A. With kFlush each range is
// summed in lanes of its own, added to the ranges' lanes after it (so that no lane accumulates
// the whole sum's terms one by one: fewer roundings against the large partial sums); a template
// parameter, so that the other sums keep their registers.
template <class A, int K, bool kFlush, class T, class Columns>
void PointSumRanges(const Columns& c, const SourceRange* ranges, int count, const T* const* x,
                    double* const* w) {
  using V = typename A::V;
  const V one = A::Set(T(1));
  V px[K], py[K], pz[K], wx[K], wy[K], wz[K];
  [[maybe_unused]] V vx[K], vy[K], vz[K];  // the ranges' sums (kFlush)
#pragma GCC unroll 8
  for (int k = 0; k < K; ++k) {
    px[k] = A::Set(x[k][0]), py[k] = A::Set(x[k][1]), pz[k] = A::Set(x[k][2]);
    wx[k] = A::Set(T(0)), wy[k] = wx[k], wz[k] = wx[k];
    vx[k] = wx[k], vy[k] = wx[k], vz[k] = wx[k];
  }
  for (int r = 0; r < count; ++r) {
    for (int s = ranges[r].begin; s < ranges[r].end; s += A::kLanes) {
      const auto m = A::MaskFirst(ranges[r].end - s);
      const V sx = A::Load(m, c.x + s), sy = A::Load(m, c.y + s), sz = A::Load(m, c.z + s);
      const V e2 = A::LoadOr(one, m, c.e2 + s);
      const V gx = A::Load(m, c.gx + s), gy = A::Load(m, c.gy + s), gz = A::Load(m, c.gz + s);
#pragma GCC unroll 8
      for (int k = 0; k < K; ++k) {
        const V rx = A::Sub(px[k], sx), ry = A::Sub(py[k], sy), rz = A::Sub(pz[k], sz);
        const V inv_r = A::InverseSqrt(A::Fma(rx, rx, A::Fma(ry, ry, A::Fma(rz, rz, e2))));
        const V inv_r2 = A::Mul(inv_r, inv_r);
        const V inv_r3 = A::Mul(inv_r, inv_r2);
        const V a = A::Fma(e2, inv_r3, inv_r);
        const V b = A::Mul(A::Fma(rx, gx, A::Fma(ry, gy, A::Mul(rz, gz))), inv_r3);
        wx[k] = A::Fma(a, gx, A::Fma(b, rx, wx[k]));
        wy[k] = A::Fma(a, gy, A::Fma(b, ry, wy[k]));
        wz[k] = A::Fma(a, gz, A::Fma(b, rz, wz[k]));
      }
    }
    if constexpr (kFlush) {
#pragma GCC unroll 8
      for (int k = 0; k < K; ++k) {
        vx[k] = A::Add(vx[k], wx[k]), vy[k] = A::Add(vy[k], wy[k]), vz[k] = A::Add(vz[k], wz[k]);
        wx[k] = A::Set(T(0)), wy[k] = wx[k], wz[k] = wx[k];
      }
    }
  }
#pragma GCC unroll 8
  for (int k = 0; k < K; ++k) {
    if constexpr (kFlush) wx[k] = vx[k], wy[k] = vy[k], wz[k] = vz[k];
    w[k][0] += A::Sum(wx[k]);
    w[k][1] += A::Sum(wy[k]);
    w[k][2] += A::Sum(wz[k]);
  }
}

// n ≤ kPointSumTargets targets, kMax (≤ kPointSumTargets) at a time.
template <class A, int kMax, bool kFlush, class T, class Columns>
void PointSumTargetsOf(const Columns& c, const SourceRange* ranges, int count, int n,
                       const T* const* x, double* const* w) {
  for (int first = 0; first < n; first += kMax) {
    const int left = n - first < kMax ? n - first : kMax;
    const T* const* xk = x + first;
    double* const* wk = w + first;
    if (left == 1) PointSumRanges<A, 1, kFlush>(c, ranges, count, xk, wk);
    if constexpr (kMax >= 2)
      if (left == 2) PointSumRanges<A, 2, kFlush>(c, ranges, count, xk, wk);
    if constexpr (kMax >= 3)
      if (left == 3) PointSumRanges<A, 3, kFlush>(c, ranges, count, xk, wk);
    if constexpr (kMax >= 4)
      if (left == 4) PointSumRanges<A, 4, kFlush>(c, ranges, count, xk, wk);
  }
}

template <class A, int kMax, class T, class Columns>
void PointSumTargets(const Columns& c, const SourceRange* ranges, int count, int n,
                     const T* const* x, double* const* w, bool flush_ranges) {
  if (flush_ranges)
    PointSumTargetsOf<A, kMax, true>(c, ranges, count, n, x, w);
  else
    PointSumTargetsOf<A, kMax, false>(c, ranges, count, n, x, w);
}

}  // namespace
}  // namespace stokesrods

#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif
