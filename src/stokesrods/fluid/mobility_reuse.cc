#include "stokesrods/fluid/mobility_reuse.h"

#include <algorithm>
#include <cmath>

namespace stokesrods {
namespace {

// The extrapolation's two passes over the matrices, as plain loops vectorized for the CPU at hand
// (the build targets baseline x86-64, where Eigen's expressions use SSE2 only; GCC 12 at -O2
// vectorizes only loops marked `omp simd`). Each runs once per step or per assembly over all
// 9M² entries and was 10 % of Fig. 1's step as Eigen expressions.

// out = base + s · slope (n entries).
__attribute__((target_clones("avx512f", "avx2", "default")))
void Extrapolate(Eigen::Index n, const float* base, float s, const float* slope, float* out) {
#pragma omp simd
  for (Eigen::Index i = 0; i < n; ++i) out[i] = base[i] + s * slope[i];
}

// Σ (base + s · slope − exact)², in double.
__attribute__((target_clones("avx512f", "avx2", "default")))
double SquaredMiss(Eigen::Index n, const float* base, double s, const float* slope,
                   const double* exact) {
  double sum = 0.0;
#pragma omp simd reduction(+ : sum)
  for (Eigen::Index i = 0; i < n; ++i) {
    const double d = static_cast<double>(base[i]) + s * static_cast<double>(slope[i]) - exact[i];
    sum += d * d;
  }
  return sum;
}

}  // namespace

bool MobilityReuse::Update(const VecX& x, const std::function<void(MatX*)>& assemble,
                           MatX* assembled, Eigen::MatrixXf* extrapolated) {
  ++stats_.updates;
  if (tolerance_ <= 0.0) {
    assemble(assembled);
    ++stats_.assemblies;
    return true;
  }
  const bool same_size = base_x_.size() == x.size();
  if (history_ == 2 && same_size && since_ + 1 < interval_) {
    ++since_;
    const auto s = static_cast<float>(Projection(x));
    extrapolated->resize(base_.rows(), base_.cols());
    Extrapolate(base_.size(), base_.data(), s, slope_.data(), extrapolated->data());
    return false;
  }
  if (!same_size) history_ = 0;
  assemble(assembled);
  ++stats_.assemblies;
  if (history_ == 2) {
    // What the extrapolation gives here, since_ + 1 updates from base_ (one more than the
    // farthest used since base_, so it bounds them), rounding included.
    const double s = Projection(x);
    const double error =
        std::sqrt(SquaredMiss(base_.size(), base_.data(), s, slope_.data(), assembled->data())) /
        std::max(assembled->norm(), 1e-300);
    if (since_ > 0) stats_.largest_error = std::max(stats_.largest_error, error);
    const int used = since_ + 1;
    const double grow = error > 0.0 ? 0.9 * std::sqrt(tolerance_ / error) : 2.0;
    interval_ = std::clamp(static_cast<int>(std::floor(used * std::min(grow, 2.0))), 1,
                           kMaxInterval);
  }
  if (history_ >= 1) {
    slope_ = (*assembled - last_assembled_).cast<float>();
    step_x_ = x - base_x_;
  }
  last_assembled_ = *assembled;
  base_ = assembled->cast<float>();
  base_x_ = x;
  history_ = std::min(history_ + 1, 2);
  since_ = 0;
  return true;
}

void MobilityReuse::Forget() {
  history_ = 0;
  since_ = 0;
  interval_ = 1;
}

double MobilityReuse::Projection(const VecX& x) const {
  const double length2 = step_x_.squaredNorm();
  return length2 > 0.0 ? (x - base_x_).dot(step_x_) / length2 : 0.0;
}

}  // namespace stokesrods
