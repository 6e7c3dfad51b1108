#include "stokesrods/fluid/mobility_reuse.h"

#include <algorithm>
#include <cmath>

namespace stokesrods {
namespace {

// The reuse's passes over the matrices, as plain loops vectorized for the CPU at hand (the build
// targets baseline x86-64, where Eigen's expressions use SSE2 only; GCC 12 at -O2 vectorizes only
// loops marked `omp simd`): one per step (forming the extrapolation) or per assembly (taking it
// into the history), over all 9M² entries; as Eigen expressions they were 10 % of Fig. 1's step.

// out = base + s · slope (n entries).
__attribute__((target_clones("avx512f", "avx2", "default")))
void Extrapolate(Eigen::Index n, const float* base, float s, const float* slope, float* out) {
#pragma omp simd
  for (Eigen::Index i = 0; i < n; ++i) out[i] = base[i] + s * slope[i];
}

// An assembled 𝕄 (`exact`, double) taken into the history in one pass: returns the squared miss
// Σ (base + s · slope − exact)² of the extrapolation it replaces and Σ exact² in `norm2` (when
// `measure`), then sets slope = exact − last (when `have_last`; rounded once), base = exact
// (rounded), last = exact.
__attribute__((target_clones("avx512f", "avx2", "default")))
double TakeAssembly(Eigen::Index n, const double* exact, double s, bool measure, bool have_last,
                    float* base, float* slope, double* last, double* norm2) {
  double sum = 0.0, exact2 = 0.0;
  if (measure) {
#pragma omp simd reduction(+ : sum, exact2)
    for (Eigen::Index i = 0; i < n; ++i) {
      const double d = static_cast<double>(base[i]) + s * static_cast<double>(slope[i]) - exact[i];
      sum += d * d;
      exact2 += exact[i] * exact[i];
    }
  }
  *norm2 = exact2;
#pragma omp simd
  for (Eigen::Index i = 0; i < n; ++i) {
    if (have_last) slope[i] = static_cast<float>(exact[i] - last[i]);
    base[i] = static_cast<float>(exact[i]);
    last[i] = exact[i];
  }
  return sum;
}

}  // namespace

bool MobilityReuse::Update(const VecX& x, const Assemble& assemble, MatX* assembled,
                           Eigen::MatrixXf* extrapolated) {
  ++stats_.updates;
  if (tolerance_ <= 0.0) {
    assemble(x, assembled);
    ++stats_.assemblies;
    return true;
  }
  if (restore_) {  // the history as it was: its assemblies again, then its counters
    const MobilityReuseHistory kept = std::move(*restore_);
    restore_.reset();
    history_ = 0;
    if (kept.assemblies >= 1 && kept.x_b.size() == x.size()) {
      if (kept.assemblies == 2) {
        assemble(kept.x_a, assembled);
        ++stats_.assemblies;
        Take(kept.x_a, *assembled, false);
      }
      assemble(kept.x_b, assembled);
      ++stats_.assemblies;
      Take(kept.x_b, *assembled, false);
      since_ = kept.since;
      interval_ = kept.interval;
    }
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
  assemble(x, assembled);
  ++stats_.assemblies;
  Take(x, *assembled, history_ == 2);
  return true;
}

void MobilityReuse::Take(const VecX& x, const MatX& assembled, bool measure) {
  if (history_ == 0) {
    base_.resize(assembled.rows(), assembled.cols());
    slope_.resize(assembled.rows(), assembled.cols());
    last_assembled_.resize(assembled.rows(), assembled.cols());
  }
  // What the extrapolation gives here, since_ + 1 updates from base_ (one more than the farthest
  // used since base_, so it bounds them), rounding included.
  const double s = measure ? Projection(x) : 0.0;
  double norm2 = 0.0;
  const double miss = std::sqrt(TakeAssembly(assembled.size(), assembled.data(), s, measure,
                                             history_ >= 1, base_.data(), slope_.data(),
                                             last_assembled_.data(), &norm2));
  if (measure) {
    const double error = miss / std::max(std::sqrt(norm2), 1e-300);
    if (since_ > 0) stats_.largest_error = std::max(stats_.largest_error, error);
    const int used = since_ + 1;
    const double grow = error > 0.0 ? 0.9 * std::sqrt(tolerance_ / error) : 2.0;
    interval_ = std::clamp(static_cast<int>(std::floor(used * std::min(grow, 2.0))), 1,
                           kMaxInterval);
  }
  if (history_ >= 1) {
    previous_x_ = base_x_;
    step_x_ = x - base_x_;
  }
  base_x_ = x;
  history_ = std::min(history_ + 1, 2);
  since_ = 0;
}

void MobilityReuse::Forget() {
  history_ = 0;
  since_ = 0;
  interval_ = 1;
  restore_.reset();
}

MobilityReuseHistory MobilityReuse::history() const {
  if (restore_) return *restore_;  // not assembled again yet
  MobilityReuseHistory kept;
  kept.assemblies = tolerance_ > 0.0 ? history_ : 0;
  kept.since = since_;
  kept.interval = interval_;
  if (kept.assemblies >= 1) kept.x_b = base_x_;
  if (kept.assemblies == 2) kept.x_a = previous_x_;
  return kept;
}

void MobilityReuse::Restore(const MobilityReuseHistory& history) {
  Forget();
  if (tolerance_ > 0.0 && history.assemblies > 0) restore_ = history;
}

double MobilityReuse::Projection(const VecX& x) const {
  const double length2 = step_x_.squaredNorm();
  return length2 > 0.0 ? (x - base_x_).dot(step_x_) / length2 : 0.0;
}

}  // namespace stokesrods
