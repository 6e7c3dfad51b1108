// The direct sum of regularized Stokeslets and its vectorized inner loop (point_stokeslet.h). The
// fast sum is the kernel-independent FMM of fmm_sum.cc.
//
// MEASURED (AMD EPYC, ms, one thread): the direct sum, vectorized (AVX-512/AVX2 clones chosen at
// run time, -fno-math-errno), costs 1.7 ns per pair: Apply 1.4 (10 helices of the lattice in
// tests/common/helix_lattice.h), 5.6 (20), 34 (50), 141 (100); Build ≈ 0.
#include "stokesrods/fluid/stokeslet_sum.h"

#include <cmath>

#include "stokesrods/common/assert.h"
#include "stokesrods/fluid/point_stokeslet.h"

namespace stokesrods {

SourceColumns Columns(const MatX& src) {
  return {src.col(0).data(), src.col(1).data(), src.col(2).data(), src.col(3).data(),
          src.col(4).data(), src.col(5).data(), src.col(6).data()};
}

__attribute__((target_clones("avx512f", "avx2", "default")))
void AddPointSum(const SourceColumns& c, Eigen::Index begin, Eigen::Index end, const double* x,
                 double* w) {
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

MatX SourceMatrix(const Matrix3X& sources, const VecX& regularization) {
  MatX src(sources.cols(), 7);
  src.leftCols<3>() = sources.transpose();
  src.col(3) = regularization.array().square().matrix();
  src.rightCols<3>().setZero();
  return src;
}

namespace {

class DirectStokesletSum final : public StokesletSum {
 public:
  void Build(const Matrix3X& sources, const VecX& regularization,
             const Matrix3X& targets) override {
    SR_ASSERT(regularization.size() == sources.cols(), "one ε per source");
    src_ = SourceMatrix(sources, regularization);
    targets_ = targets;
  }

  void Apply(const Matrix3X& strengths, Matrix3X* w) const override {
    SR_ASSERT(strengths.cols() == src_.rows(), "one strength per source");
    const Eigen::Index nt = targets_.cols();
    src_.rightCols<3>() = strengths.transpose();
    w->setZero(3, nt);
    const SourceColumns c = Columns(src_);
#pragma omp parallel for schedule(static)
    for (Eigen::Index t = 0; t < nt; ++t)
      AddPointSum(c, 0, src_.rows(), targets_.col(t).data(), w->col(t).data());
  }

  StokesletSumStats Stats() const override {
    StokesletSumStats stats;
    stats.near_pairs = static_cast<std::int64_t>(src_.rows()) * targets_.cols();
    stats.stored_values = src_.size() + targets_.size();
    return stats;
  }

 private:
  mutable MatX src_;  // S × 7, the strengths are those of the current Apply
  Matrix3X targets_;
};

}  // namespace

std::unique_ptr<StokesletSum> MakeDirectStokesletSum() {
  return std::make_unique<DirectStokesletSum>();
}

}  // namespace stokesrods
