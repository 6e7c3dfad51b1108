// The direct sum of regularized Stokeslets and its vectorized inner loop (point_stokeslet.h). The
// fast sum is the kernel-independent FMM of fmm_sum.cc.
//
// MEASURED (one thread): on an AMD EPYC (1280 sources × 650 targets, one target at a time) the
// direct sum on AVX-512 intrinsics cost 0.46 ns per pair in double and 0.18 ns in single
// precision (the compiler's vectorization of the portable loops, kept for CPUs without AVX-512:
// 1.6 and 0.22 ns); on an Intel Xeon (Emerald Rapids; 2560 × 1300, BM_StokesletSumApply/20/4/0)
// 0.52 ns in single precision one target at a time with the IEEE square root, 0.38 ns four at a
// time with rsqrt14; in double 1.76 and 0.9 ns.
#include "stokesrods/fluid/stokeslet_sum.h"

#include <algorithm>
#include <cmath>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include "stokesrods/common/assert.h"
#include "stokesrods/fluid/point_stokeslet.h"

namespace stokesrods {

SourceColumns Columns(const MatX& src) {
  return {src.col(0).data(), src.col(1).data(), src.col(2).data(), src.col(3).data(),
          src.col(4).data(), src.col(5).data(), src.col(6).data()};
}

__attribute__((target_clones("avx2", "default")))
void PointSumPortable(const SourceColumns& c, Eigen::Index begin, Eigen::Index end,
                      const double* x, double* w) {
  double wx = 0.0, wy = 0.0, wz = 0.0;
#pragma omp simd reduction(+ : wx, wy, wz)
  for (Eigen::Index s = begin; s < end; ++s) {
    const double rx = x[0] - c.x[s], ry = x[1] - c.y[s], rz = x[2] - c.z[s];
    const double inv_r = 1.0 / std::sqrt(rx * rx + ry * ry + rz * rz + c.e2[s]);
    const double inv_r3 = inv_r * inv_r * inv_r;
    const double a = inv_r + c.e2[s] * inv_r3;
    const double b = (rx * c.gx[s] + ry * c.gy[s] + rz * c.gz[s]) * inv_r3;
    wx += a * c.gx[s] + b * rx;
    wy += a * c.gy[s] + b * ry;
    wz += a * c.gz[s] + b * rz;
  }
  w[0] += wx;
  w[1] += wy;
  w[2] += wz;
}

SourceColumnsF ColumnsF(const Eigen::MatrixXf& src) {
  return {src.col(0).data(), src.col(1).data(), src.col(2).data(), src.col(3).data(),
          src.col(4).data(), src.col(5).data(), src.col(6).data()};
}

// The portable float loops, vectorized by the compiler (AVX2 clone chosen at run time).
__attribute__((target_clones("avx2", "default")))
void PointSumSinglePortable(const SourceColumnsF& c, Eigen::Index begin, Eigen::Index end,
                            const float* x, double* w) {
  const float *sx = c.x, *sy = c.y, *sz = c.z, *se2 = c.e2, *gx = c.gx, *gy = c.gy, *gz = c.gz;
  const float px = x[0], py = x[1], pz = x[2];
  float wx = 0.0f, wy = 0.0f, wz = 0.0f;
#pragma omp simd reduction(+ : wx, wy, wz)
  for (Eigen::Index s = begin; s < end; ++s) {
    const float rx = px - sx[s], ry = py - sy[s], rz = pz - sz[s];
    const float inv_r = 1.0f / std::sqrt(rx * rx + ry * ry + rz * rz + se2[s]);
    const float inv_r3 = inv_r * inv_r * inv_r;
    const float a = inv_r + se2[s] * inv_r3;
    const float b = (rx * gx[s] + ry * gy[s] + rz * gz[s]) * inv_r3;
    wx += a * gx[s] + b * rx;
    wy += a * gy[s] + b * ry;
    wz += a * gz[s] + b * rz;
  }
  w[0] += wx;
  w[1] += wy;
  w[2] += wz;
}

__attribute__((target_clones("avx2", "default")))
void PointSumBlocksPortable(const SourceColumnsF& c, const SourceRange* ranges, int count,
                            const float* x, double* w) {
  constexpr int kLanes = kPointSumBlock;
  const float *sx = c.x, *sy = c.y, *sz = c.z, *se2 = c.e2, *gx = c.gx, *gy = c.gy, *gz = c.gz;
  const float px = x[0], py = x[1], pz = x[2];
  float wx[kLanes] = {}, wy[kLanes] = {}, wz[kLanes] = {};
  for (int r = 0; r < count; ++r) {
    SR_DASSERT(ranges[r].begin % kLanes == 0 && ranges[r].end % kLanes == 0, "whole blocks");
    for (int first = ranges[r].begin; first < ranges[r].end; first += kLanes) {
#pragma omp simd
      for (int l = 0; l < kLanes; ++l) {
        const int s = first + l;
        const float rx = px - sx[s], ry = py - sy[s], rz = pz - sz[s];
        const float inv_r = 1.0f / std::sqrt(rx * rx + ry * ry + rz * rz + se2[s]);
        const float inv_r3 = inv_r * inv_r * inv_r;
        const float a = inv_r + se2[s] * inv_r3;
        const float b = (rx * gx[s] + ry * gy[s] + rz * gz[s]) * inv_r3;
        wx[l] += a * gx[s] + b * rx;
        wy[l] += a * gy[s] + b * ry;
        wz[l] += a * gz[s] + b * rz;
      }
    }
  }
  float sum_x = 0.0f, sum_y = 0.0f, sum_z = 0.0f;
  for (int l = 0; l < kLanes; ++l) sum_x += wx[l], sum_y += wy[l], sum_z += wz[l];
  w[0] += sum_x;
  w[1] += sum_y;
  w[2] += sum_z;
}

namespace {

#if defined(__x86_64__)
// The sums written with AVX-512 intrinsics: the arithmetic of the portable loops with fused
// multiply–adds and the lanes kept in registers, and
//   - 1/R³ as 1/R times 1/R², one multiplication fewer per pair than cubing 1/R;
//   - 1/R by the 14-bit estimate rsqrt14 and Newton steps instead of the IEEE division and
//     square root: one step in single precision (≈ 3 ulp), two in double (≈ 1 ulp). The IEEE
//     operations bounded the loops on an Intel Xeon (20 helices, direct sum, one thread: float
//     1.83 → 1.61 ms; double, at 1e-6, 5.9 → 3.1 ms with four targets at once), and cost
//     nothing measurable in float on an AMD EPYC (session 12);
//   - up to kPointSumTargets targets per pass over the sources (PointSumRanges512<K>).
// GCC 12 vectorizes the portable loops into code 18 % slower in single precision and 3.5× slower
// in double (measured, AMD EPYC, one thread, 1280 sources × 650 targets: 0.182 against 0.222 and
// 0.456 against 1.61 ns per pair, before the targets were taken together). Any ranges: a block
// that runs past a range's end is masked, its missing lanes read as a source at distance ≥ 1 of
// zero strength (they add exactly zero).
#define SR_AVX512 __attribute__((target("avx512f"), always_inline)) static inline

// 16 floats or 8 doubles per vector.
template <class T>
struct Avx512;
template <>
struct Avx512<float> {
  using V = __m512;
  using Mask = __mmask16;
  static constexpr int kLanes = 16;
  SR_AVX512 V Set(float v) { return _mm512_set1_ps(v); }
  SR_AVX512 V Load(Mask m, const float* p) { return _mm512_maskz_loadu_ps(m, p); }
  SR_AVX512 V LoadOr(V fill, Mask m, const float* p) { return _mm512_mask_loadu_ps(fill, m, p); }
  SR_AVX512 V Sub(V a, V b) { return _mm512_sub_ps(a, b); }
  SR_AVX512 V Mul(V a, V b) { return _mm512_mul_ps(a, b); }
  SR_AVX512 V Fma(V a, V b, V c) { return _mm512_fmadd_ps(a, b, c); }
  SR_AVX512 V Inverse(V a) { return _mm512_div_ps(Set(1.0f), a); }
  SR_AVX512 V Sqrt(V a) { return _mm512_sqrt_ps(a); }
  // 1/√a by the 14-bit estimate and one Newton step, y (3 − a y²) / 2: relative error ≈ 3 ulp.
  SR_AVX512 V InverseSqrt(V a) {
    const V y = _mm512_rsqrt14_ps(a);
    const V t = _mm512_fnmadd_ps(_mm512_mul_ps(a, y), y, Set(3.0f));
    return _mm512_mul_ps(_mm512_mul_ps(Set(0.5f), y), t);
  }
  SR_AVX512 double Sum(V a) { return _mm512_reduce_add_ps(a); }
};
template <>
struct Avx512<double> {
  using V = __m512d;
  using Mask = __mmask8;
  static constexpr int kLanes = 8;
  SR_AVX512 V Set(double v) { return _mm512_set1_pd(v); }
  SR_AVX512 V Load(Mask m, const double* p) { return _mm512_maskz_loadu_pd(m, p); }
  SR_AVX512 V LoadOr(V fill, Mask m, const double* p) { return _mm512_mask_loadu_pd(fill, m, p); }
  SR_AVX512 V Sub(V a, V b) { return _mm512_sub_pd(a, b); }
  SR_AVX512 V Mul(V a, V b) { return _mm512_mul_pd(a, b); }
  SR_AVX512 V Fma(V a, V b, V c) { return _mm512_fmadd_pd(a, b, c); }
  SR_AVX512 V Inverse(V a) { return _mm512_div_pd(Set(1.0), a); }
  SR_AVX512 V Sqrt(V a) { return _mm512_sqrt_pd(a); }
  // 1/√a by the 14-bit estimate and two Newton steps y + y (1 − a y²)/2, the bracket by a fused
  // multiply–add (≈ 1 ulp; the division and square root took ≈ 40 cycles per 8 lanes on an Intel
  // Xeon, where the double sum ran at 1.7 ns per pair).
  SR_AVX512 V InverseSqrt(V a) {
    V y = _mm512_rsqrt14_pd(a);
    for (int step = 0; step < 2; ++step) {
      const V r = _mm512_fnmadd_pd(_mm512_mul_pd(a, y), y, Set(1.0));
      y = _mm512_fmadd_pd(_mm512_mul_pd(y, r), Set(0.5), y);
    }
    return y;
  }
  SR_AVX512 double Sum(V a) { return _mm512_reduce_add_pd(a); }
};

// (GCC 12's avx512fintrin.h warns on its own _mm512_undefined_ps, GCC bug 105593.)
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
// K targets at once over the same sources: each block of 16 sources is loaded once for all K
// (one target alone reads 7 vectors per 16 pairs from L2, and its loop ran at less than half of
// the multiply–add pipes' rate on an Intel Xeon: measured 27 cycles per block instead of ~12).
// Each target's arithmetic, and the order of its sums, are those of K = 1.
template <int K, class T, class Columns>
__attribute__((target("avx512f")))
void PointSumRanges512(const Columns& c, const SourceRange* ranges, int count,
                       const T* const* x, double* const* w) {
  using A = Avx512<T>;
  using V = typename A::V;
  const V one = A::Set(T(1));
  V px[K], py[K], pz[K], wx[K], wy[K], wz[K];
#pragma GCC unroll 8
  for (int k = 0; k < K; ++k) {
    px[k] = A::Set(x[k][0]), py[k] = A::Set(x[k][1]), pz[k] = A::Set(x[k][2]);
    wx[k] = A::Set(T(0)), wy[k] = wx[k], wz[k] = wx[k];
  }
  for (int r = 0; r < count; ++r) {
    for (int s = ranges[r].begin; s < ranges[r].end; s += A::kLanes) {
      const int left = ranges[r].end - s;
      const auto m = static_cast<typename A::Mask>(left >= A::kLanes ? ~0u : (1u << left) - 1u);
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
  }
#pragma GCC unroll 8
  for (int k = 0; k < K; ++k) {
    w[k][0] += A::Sum(wx[k]);
    w[k][1] += A::Sum(wy[k]);
    w[k][2] += A::Sum(wz[k]);
  }
}

template <class T, class Columns>
__attribute__((target("avx512f")))
void PointSumRanges512(const Columns& c, const SourceRange* ranges, int count, const T* x,
                       double* w) {
  PointSumRanges512<1>(c, ranges, count, &x, &w);
}
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif
#undef SR_AVX512

bool HasAvx512() {
  static const bool has = __builtin_cpu_supports("avx512f");
  return has;
}
#else
constexpr bool HasAvx512() { return false; }
template <class T, class Columns>
void PointSumRanges512(const Columns&, const SourceRange*, int, const T*, double*) {}
template <int K, class T, class Columns>
void PointSumRanges512(const Columns&, const SourceRange*, int, const T* const*, double* const*) {}
#endif

// n ≤ kPointSumTargets targets over the same ranges, by the kernel for n at once.
template <class T, class Columns>
void PointSumTargets512(const Columns& c, const SourceRange* ranges, int count, int n,
                        const T* const* x, double* const* w) {
  switch (n) {
    case 1: return PointSumRanges512<1>(c, ranges, count, x, w);
    case 2: return PointSumRanges512<2>(c, ranges, count, x, w);
    case 3: return PointSumRanges512<3>(c, ranges, count, x, w);
    case 4: return PointSumRanges512<4>(c, ranges, count, x, w);
    default: SR_ASSERT(false, "at most kPointSumTargets targets at once");
  }
}

}  // namespace

void AddPointSumRangesTargets(const SourceColumns& c, const SourceRange* ranges, int count, int n,
                              const double* const* x, double* const* w) {
  if (!HasAvx512()) {
    for (int k = 0; k < n; ++k)
      for (int r = 0; r < count; ++r) PointSumPortable(c, ranges[r].begin, ranges[r].end, x[k], w[k]);
    return;
  }
  PointSumTargets512(c, ranges, count, n, x, w);
}

void AddPointSumRangesTargets(const SourceColumnsF& c, const SourceRange* ranges, int count, int n,
                              const float* const* x, double* const* w) {
  if (!HasAvx512()) {
    for (int k = 0; k < n; ++k)
      for (int r = 0; r < count; ++r)
        PointSumSinglePortable(c, ranges[r].begin, ranges[r].end, x[k], w[k]);
    return;
  }
  PointSumTargets512(c, ranges, count, n, x, w);
}

void AddPointSumBlocksTargets(const SourceColumnsF& c, const SourceRange* ranges, int count,
                              int n, const float* const* x, double* const* w) {
  if (!HasAvx512()) {
    for (int k = 0; k < n; ++k) PointSumBlocksPortable(c, ranges, count, x[k], w[k]);
    return;
  }
  PointSumTargets512(c, ranges, count, n, x, w);
}

void AddPointSum(const SourceColumns& c, Eigen::Index begin, Eigen::Index end, const double* x,
                 double* w) {
  if (!HasAvx512()) return PointSumPortable(c, begin, end, x, w);
  const SourceRange range{static_cast<int>(begin), static_cast<int>(end)};
  PointSumRanges512(c, &range, 1, x, w);
}

void AddPointSumSingle(const SourceColumnsF& c, Eigen::Index begin, Eigen::Index end,
                       const float* x, double* w) {
  if (!HasAvx512()) return PointSumSinglePortable(c, begin, end, x, w);
  const SourceRange range{static_cast<int>(begin), static_cast<int>(end)};
  PointSumRanges512(c, &range, 1, x, w);
}

void AddPointSumBlocks(const SourceColumnsF& c, const SourceRange* ranges, int count,
                       const float* x, double* w) {
  if (HasAvx512()) return PointSumRanges512(c, ranges, count, x, w);
  PointSumBlocksPortable(c, ranges, count, x, w);
}

MatX SourceMatrix(const Matrix3X& sources, const VecX& regularization) {
  MatX src(sources.cols(), 7);
  src.leftCols<3>() = sources.transpose();
  src.col(3) = regularization.array().square().matrix();
  src.rightCols<3>().setZero();
  return src;
}

namespace {

// The targets of group g (kPointSumTargets consecutive columns, fewer in the last) and their
// outputs; returns how many.
template <class Targets, class T>
int Group(Eigen::Index g, Eigen::Index nt, const Targets& targets, Matrix3X* w, const T** x,
          double** out) {
  const Eigen::Index first = g * kPointSumTargets;
  const int n = static_cast<int>(std::min<Eigen::Index>(kPointSumTargets, nt - first));
  for (int k = 0; k < n; ++k) x[k] = targets.col(first + k).data(), out[k] = w->col(first + k).data();
  return n;
}

class DirectStokesletSum final : public StokesletSum {
 public:
  explicit DirectStokesletSum(bool single) : single_(single) {}

  void Build(const Matrix3X& sources, const VecX& regularization,
             const Matrix3X& targets) override {
    SR_ASSERT(regularization.size() == sources.cols(), "one ε per source");
    src_ = SourceMatrix(sources, regularization);
    targets_ = targets;
    if (!single_) return;
    origin_ = sources.cols() > 0 ? Vec3(sources.rowwise().mean()) : Vec3::Zero();
    src_f_ = src_.cast<float>();
    src_f_.leftCols<3>() = (sources.colwise() - origin_).transpose().cast<float>();
    targets_f_ = (targets.colwise() - origin_).cast<float>();
  }

  void Apply(const Matrix3X& strengths, Matrix3X* w) const override {
    SR_ASSERT(strengths.cols() == src_.rows(), "one strength per source");
    const Eigen::Index nt = targets_.cols();
    w->setZero(3, nt);
    // Groups of kPointSumTargets consecutive targets, each group summed at once.
    const Eigen::Index groups = (nt + kPointSumTargets - 1) / kPointSumTargets;
    const SourceRange all{0, static_cast<int>(src_.rows())};
    if (single_) {
      src_f_.rightCols<3>() = strengths.transpose().cast<float>();
      const SourceColumnsF c = ColumnsF(src_f_);
#pragma omp parallel for schedule(static)
      for (Eigen::Index g = 0; g < groups; ++g) {
        const float* x[kPointSumTargets];
        double* out[kPointSumTargets];
        const int n = Group(g, nt, targets_f_, w, x, out);
        AddPointSumRangesTargets(c, &all, 1, n, x, out);
      }
      return;
    }
    src_.rightCols<3>() = strengths.transpose();
    const SourceColumns c = Columns(src_);
#pragma omp parallel for schedule(static)
    for (Eigen::Index g = 0; g < groups; ++g) {
      const double* x[kPointSumTargets];
      double* out[kPointSumTargets];
      const int n = Group(g, nt, targets_, w, x, out);
      AddPointSumRangesTargets(c, &all, 1, n, x, out);
    }
  }

  StokesletSumStats Stats() const override {
    StokesletSumStats stats;
    stats.near_pairs = static_cast<std::int64_t>(src_.rows()) * targets_.cols();
    stats.stored_values = src_.size() + targets_.size();
    stats.cost = static_cast<double>(stats.near_pairs);
    return stats;
  }

 private:
  bool single_ = false;
  mutable MatX src_;  // S × 7, the strengths are those of the current Apply
  Matrix3X targets_;
  Vec3 origin_ = Vec3::Zero();       // single precision: positions relative to it
  mutable Eigen::MatrixXf src_f_;
  Eigen::Matrix3Xf targets_f_;
};

}  // namespace

std::unique_ptr<StokesletSum> MakeDirectStokesletSum(bool single_precision) {
  return std::make_unique<DirectStokesletSum>(single_precision);
}

}  // namespace stokesrods
