// The direct sum of regularized Stokeslets and its vectorized inner loop (point_stokeslet.h). The
// fast sum is the kernel-independent FMM of fmm_sum.cc.
//
// MEASURED (one thread): on an AMD EPYC with AVX-512 (1280 sources × 650 targets, one target at a
// time) the direct sum on AVX-512 intrinsics (point_sum_simd.h) cost 0.46 ns per pair in double
// and 0.18 ns in single precision (the compiler's vectorization of the portable loops, kept for
// CPUs without AVX2: 1.6 and 0.22 ns); on an AMD EPYC without AVX-512 (point_sum_avx2.cc) 1.5 and
// 0.59 ns on AVX2 intrinsics against 6.0 and 0.88 ns portable; on an Intel Xeon (Emerald Rapids;
// 2560 × 1300, BM_StokesletSumApply/20/4/0) 0.52 ns in single precision one target at a time with
// the IEEE square root, 0.38 ns four at a time with rsqrt14; in double 1.76 and 0.9 ns.
#include "stokesrods/fluid/stokeslet_sum.h"

#include <algorithm>
#include <cmath>

#include "stokesrods/common/assert.h"
#include "stokesrods/common/parallel.h"
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

// The sums on the widest vectors the CPU has (point_sum_simd.h): AVX-512, else AVX2 with FMA;
// false where it has neither (the portable loops above then).
template <class Columns, class T>
bool AddSimdTargets(const Columns& c, const SourceRange* ranges, int count, int n,
                    const T* const* x, double* const* w, bool flush_ranges = false) {
#if defined(__x86_64__)
  if (HasPointSumAvx512()) {
    PointSumTargetsAvx512(c, ranges, count, n, x, w, flush_ranges);
    return true;
  }
  if (HasPointSumAvx2()) {
    PointSumTargetsAvx2(c, ranges, count, n, x, w, flush_ranges);
    return true;
  }
#endif
  return false;
}

}  // namespace

#if defined(__x86_64__)
bool HasPointSumAvx512() {
  static const bool has = __builtin_cpu_supports("avx512f");
  return has;
}
bool HasPointSumAvx2() {
  static const bool has = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  return has;
}
#else
bool HasPointSumAvx512() { return false; }
bool HasPointSumAvx2() { return false; }
#endif

void AddPointSumRangesTargets(const SourceColumns& c, const SourceRange* ranges, int count, int n,
                              const double* const* x, double* const* w) {
  if (AddSimdTargets(c, ranges, count, n, x, w)) return;
  for (int k = 0; k < n; ++k)
    for (int r = 0; r < count; ++r) PointSumPortable(c, ranges[r].begin, ranges[r].end, x[k], w[k]);
}

void AddPointSumRangesTargets(const SourceColumnsF& c, const SourceRange* ranges, int count, int n,
                              const float* const* x, double* const* w, bool flush_ranges) {
  // (the portable loops sum and reduce range by range: flushed always)
  if (AddSimdTargets(c, ranges, count, n, x, w, flush_ranges)) return;
  for (int k = 0; k < n; ++k)
    for (int r = 0; r < count; ++r)
      PointSumSinglePortable(c, ranges[r].begin, ranges[r].end, x[k], w[k]);
}

void AddPointSumBlocksTargets(const SourceColumnsF& c, const SourceRange* ranges, int count,
                              int n, const float* const* x, double* const* w) {
  if (AddSimdTargets(c, ranges, count, n, x, w)) return;
  for (int k = 0; k < n; ++k) PointSumBlocksPortable(c, ranges, count, x[k], w[k]);
}

void AddPointSum(const SourceColumns& c, Eigen::Index begin, Eigen::Index end, const double* x,
                 double* w) {
  const SourceRange range{static_cast<int>(begin), static_cast<int>(end)};
  if (AddSimdTargets(c, &range, 1, 1, &x, &w)) return;
  PointSumPortable(c, begin, end, x, w);
}

void AddPointSumSingle(const SourceColumnsF& c, Eigen::Index begin, Eigen::Index end,
                       const float* x, double* w) {
  const SourceRange range{static_cast<int>(begin), static_cast<int>(end)};
  if (AddSimdTargets(c, &range, 1, 1, &x, &w)) return;
  PointSumSinglePortable(c, begin, end, x, w);
}

void AddPointSumBlocks(const SourceColumnsF& c, const SourceRange* ranges, int count,
                       const float* x, double* w) {
  if (AddSimdTargets(c, ranges, count, 1, &x, &w)) return;
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
      ForEachStatic(static_cast<int>(groups), groups > 1, [&](int g) {
        const float* x[kPointSumTargets];
        double* out[kPointSumTargets];
        const int n = Group(g, nt, targets_f_, w, x, out);
        AddPointSumRangesTargets(c, &all, 1, n, x, out);
      });
      return;
    }
    src_.rightCols<3>() = strengths.transpose();
    const SourceColumns c = Columns(src_);
    ForEachStatic(static_cast<int>(groups), groups > 1, [&](int g) {
      const double* x[kPointSumTargets];
      double* out[kPointSumTargets];
      const int n = Group(g, nt, targets_, w, x, out);
      AddPointSumRangesTargets(c, &all, 1, n, x, out);
    });
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
