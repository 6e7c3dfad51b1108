#include "stokesrods/fluid/mobility_reuse.h"

#include <algorithm>
#include <cmath>

#include "stokesrods/common/assert.h"
#include "stokesrods/fluid/mobility_reuse_half.h"

namespace stokesrods {
namespace {

// The reuse's passes over the matrices, as plain loops vectorized for the CPU at hand (the build
// targets baseline x86-64, where Eigen's expressions use SSE2 only; GCC 12 at -O2 vectorizes only
// loops marked `omp simd`): one per step (forming the extrapolation) or per assembly (taking it
// into the history), over all 9M² entries; as Eigen expressions they were 10 % of Fig. 1's step.

// out = base + s · slope + c · curve (curve only when given; c = s (s + 1)), n entries.
__attribute__((target_clones("avx512f", "avx2", "default")))
void Extrapolate(Eigen::Index n, const float* base, float s, const float* slope, float c,
                 const float* curve, float* out) {
  if (curve) {
#pragma omp simd
    for (Eigen::Index i = 0; i < n; ++i) out[i] = base[i] + s * slope[i] + c * curve[i];
  } else {
#pragma omp simd
    for (Eigen::Index i = 0; i < n; ++i) out[i] = base[i] + s * slope[i];
  }
}

// What one pass over an assembled 𝕄 (`exact`, double) does to the history.
struct TakePass {
  bool measure = false;   ///< sum the miss of the extrapolation it replaces (s, c; curve if used)
  double s = 0.0, c = 0.0;
  bool use_curve = false;
  bool new_slope = false; ///< slope = exact − base (there is a base)
  bool new_curve = false; ///< curve = (slope_new − alpha · slope) · beta (there is a slope)
  double alpha = 0.0, beta = 0.0;
  const std::vector<double>* row_weights = nullptr;  ///< each row's weight in the sums, if any
};

// An assembled 𝕄 taken into the history in one pass: returns the squared miss
// Σ (base + s · slope + c · curve − exact)² and Σ exact² in `norm2` (when measuring), then sets
// curve, slope (against the rounded base) and base = exact (rounded).
__attribute__((target_clones("avx512f", "avx2", "default")))
double TakeAssembly(Eigen::Index n, const double* exact, const TakePass& p, float* base,
                    float* slope, float* curve, double* norm2) {
  double sum = 0.0, exact2 = 0.0;
  if (p.measure) {
    const double cc = p.use_curve ? p.c : 0.0;
    const float* q = p.use_curve ? curve : slope;  // cc = 0 reads slope twice instead of curve
    const auto miss = [&](Eigen::Index i) {
      return static_cast<double>(base[i]) + p.s * static_cast<double>(slope[i]) +
             cc * static_cast<double>(q[i]) - exact[i];
    };
    if (p.row_weights) {  // column by column, each row weighted
      const std::vector<double>& w = *p.row_weights;
      const auto rows = static_cast<Eigen::Index>(w.size());
      for (Eigen::Index first = 0; first < n; first += rows)
        for (Eigen::Index r = 0; r < rows; ++r) {
          const double d = miss(first + r), e = exact[first + r];
          sum += w[static_cast<size_t>(r)] * d * d;
          exact2 += w[static_cast<size_t>(r)] * e * e;
        }
    } else {
#pragma omp simd reduction(+ : sum, exact2)
      for (Eigen::Index i = 0; i < n; ++i) {
        const double d = miss(i);
        sum += d * d;
        exact2 += exact[i] * exact[i];
      }
    }
  }
  *norm2 = exact2;
  if (p.new_curve) {
#pragma omp simd
    for (Eigen::Index i = 0; i < n; ++i) {
      const double d1 = exact[i] - static_cast<double>(base[i]);
      curve[i] = static_cast<float>((d1 - p.alpha * static_cast<double>(slope[i])) * p.beta);
      slope[i] = static_cast<float>(d1);
      base[i] = static_cast<float>(exact[i]);
    }
  } else if (p.new_slope) {
#pragma omp simd
    for (Eigen::Index i = 0; i < n; ++i) {
      slope[i] = static_cast<float>(exact[i] - static_cast<double>(base[i]));
      base[i] = static_cast<float>(exact[i]);
    }
  } else {
#pragma omp simd
    for (Eigen::Index i = 0; i < n; ++i) base[i] = static_cast<float>(exact[i]);
  }
  return sum;
}

// The quadratic's D₂ through x, the last geometry and the one before (`before`): s_a of `before`
// on the new line (last → x); sets pass's curve (and returns true) where it is used (header).
bool SetCurvePass(const VecX& before, const VecX& last, const VecX& x, TakePass* pass) {
  const VecX step = x - last;
  const double length2 = step.squaredNorm();
  const double s_a = length2 > 0.0 ? (before - x).dot(step) / length2 : 0.0;
  if (std::abs(1.0 + s_a) < 0.25 || s_a >= -1.0) return false;
  pass->new_curve = true;
  pass->alpha = 1.0 / (-1.0 - s_a);
  pass->beta = 1.0 / -s_a;
  return true;
}

}  // namespace

MobilityReuse::MobilityReuse(double tolerance, bool half_differences)
    : tolerance_(tolerance), half_(half_differences && HasHalfDifferences()) {}

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
    Forget();
    const bool fits = std::all_of(kept.geometries.begin(), kept.geometries.end(),
                                  [&](const VecX& g) { return g.size() == x.size(); });
    if (fits && !kept.geometries.empty()) {
      for (const VecX& g : kept.geometries) {
        assemble(g, assembled);
        ++stats_.assemblies;
        Take(g, *assembled, false);
      }
      since_ = kept.since;
      interval_ = kept.interval;
      skip_ = kept.skip;
      skip_length_ = kept.skip_length;
    }
  }
  const bool same_size = !geometries_.empty() && geometries_.back().size() == x.size();
  double s = 0.0;
  if (geometries_.size() >= 2 && same_size && since_ + 1 < interval_ && OnTheLine(x, &s)) {
    ++since_;
    extrapolated->resize(base_.rows(), base_.cols());
    if (!half_current_) {
      Extrapolate(base_.size(), base_.data(), static_cast<float>(s), slope_.data(),
                  static_cast<float>(s * (s + 1.0)), quadratic_ ? curve_.data() : nullptr,
                  extrapolated->data());
      return false;
    }
    const auto a = static_cast<float>(s / slope_scale_);
    const auto b = static_cast<float>(s * (s + 1.0) / curve_scale_);
    ForTwoParts(base_.size(), [&](int, Eigen::Index first, Eigen::Index count) {
      ExtrapolateHalf(count, base_.data() + first, a, slope_half_.data() + first, b,
                      quadratic_ ? curve_half_.data() + first : nullptr,
                      extrapolated->data() + first);
    });
    return false;
  }
  if (!same_size) Forget();
  assemble(x, assembled);
  ++stats_.assemblies;
  if (skip_ > 0) {  // 𝕄_c only: the history starts again from this assembly (SKIPPING)
    --skip_;
    geometries_.clear();
  }
  Take(x, *assembled, geometries_.size() >= 2);
  return true;
}

void MobilityReuse::Take(const VecX& x, const MatX& assembled, bool measure) {
  const std::size_t held = geometries_.size();
  if (held == 0) {
    base_.resize(assembled.rows(), assembled.cols());
    slope_.resize(assembled.rows(), assembled.cols());
  }
  TakePass pass;
  pass.measure = measure;
  if (!row_weights_.empty()) {
    SR_ASSERT(assembled.rows() == static_cast<Eigen::Index>(row_weights_.size()),
              "MobilityReuse: the row weights do not fit the matrix");
    pass.row_weights = &row_weights_;
  }
  // What the extrapolation gives here, since_ + 1 updates from the last assembly (one more than
  // the farthest used, so it bounds them), rounding included.
  if (measure) {
    pass.s = Position(x);
    pass.c = pass.s * (pass.s + 1.0);
    pass.use_curve = quadratic_;
  }
  pass.new_slope = held >= 1;
  const bool quadratic =
      held >= 2 && SetCurvePass(geometries_[held - 2], geometries_[held - 1], x, &pass);
  if (quadratic) curve_.resize(assembled.rows(), assembled.cols());
  double norm2 = 0.0;
  const double miss = std::sqrt(TakeAssembly(assembled.size(), assembled.data(), pass,
                                             base_.data(), slope_.data(), curve_.data(), &norm2));
  // D₁, D₂ to half precision; slope_, curve_ then hold the values the half ones stand for, so
  // that the next measurement reads what the extrapolation used (PRECISION).
  half_current_ = half_ && pass.new_slope && RoundDifferencesToHalf(quadratic);
  if (measure) {
    ++stats_.measurements;
    const double error = miss / std::max(std::sqrt(norm2), 1e-300);
    if (since_ > 0) stats_.largest_error = std::max(stats_.largest_error, error);
    const int used = since_ + 1;
    const double order = quadratic_ ? 3.0 : 2.0;  // of the extrapolation just measured
    const double grow = error > 0.0 ? 0.9 * std::pow(tolerance_ / error, 1.0 / order) : 2.0;
    interval_ = std::clamp(static_cast<int>(std::floor(used * std::min(grow, 2.0))), 1,
                           kMaxInterval);
    // The quadratic one missed for two steps: skip the next measurements (header, SKIPPING).
    if (quadratic_ && interval_ == 1) {
      skip_length_ = std::min(std::max(2 * skip_length_, 1), kMaxSkip);
      skip_ = skip_length_;
    } else if (interval_ > 1) {
      skip_length_ = 0;
    }
  }
  quadratic_ = quadratic;
  if (held == static_cast<std::size_t>(kMaxHeld)) geometries_.erase(geometries_.begin());
  geometries_.push_back(x);
  since_ = 0;
}

void MobilityReuse::Remap(const std::vector<int>& old_column, const AssembleColumns& assemble) {
  if (restore_) return Forget();  // not assembled again yet: the restored history would not fit
  if (tolerance_ <= 0.0 || geometries_.empty()) return;
  const Eigen::Index rows = base_.rows();
  const auto cols = static_cast<Eigen::Index>(old_column.size());
  Eigen::Index num_fresh = 0;  // the new columns
  for (const int from : old_column) {
    SR_ASSERT(from < base_.cols(), "Remap: no such column");
    num_fresh += from < 0;
  }
  // The new columns through the held geometries, as Take took each (REMAP).
  Eigen::MatrixXf base(rows, num_fresh), slope(rows, num_fresh);
  Eigen::MatrixXf curve = Eigen::MatrixXf::Zero(rows, num_fresh);
  if (num_fresh > 0) {
    MatX values;
    for (std::size_t k = 0; k < geometries_.size(); ++k) {
      assemble(geometries_[k], &values);
      SR_ASSERT(values.rows() == rows && values.cols() == num_fresh,
                "Remap: the new columns assembled have the wrong size");
      TakePass pass;
      pass.new_slope = k >= 1;
      if (k >= 2) SetCurvePass(geometries_[k - 2], geometries_[k - 1], geometries_[k], &pass);
      double norm2 = 0.0;
      TakeAssembly(values.size(), values.data(), pass, base.data(), slope.data(), curve.data(),
                   &norm2);
    }
  }
  const bool with_slope = geometries_.size() >= 2;
  // By runs of columns kept in order (most of them) or new.
  auto remap = [&](const Eigen::MatrixXf& old, const Eigen::MatrixXf& fresh_values) {
    Eigen::MatrixXf out(rows, cols);
    Eigen::Index next = 0;
    for (Eigen::Index j = 0; j < cols;) {
      const int from = old_column[static_cast<size_t>(j)];
      Eigen::Index run = 1;
      if (from >= 0) {
        while (j + run < cols && old_column[static_cast<size_t>(j + run)] == from + run) ++run;
        out.middleCols(j, run) = old.middleCols(from, run);
      } else {
        while (j + run < cols && old_column[static_cast<size_t>(j + run)] < 0) ++run;
        out.middleCols(j, run) = fresh_values.middleCols(next, run);
        next += run;
      }
      j += run;
    }
    return out;
  };
  // The matrices over the threads (passes over memory; on a hundred helices 5 MB each).
#pragma omp parallel sections if (rows * cols >= kTwoPartsFrom)
  {
#pragma omp section
    base_ = remap(base_, base);
#pragma omp section
    {
      if (with_slope)
        slope_ = remap(slope_, slope);
      else
        slope_.resize(rows, cols);  // written by the next Take
    }
#pragma omp section
    {
      if (quadratic_) curve_ = remap(curve_, curve);
    }
  }
  // D₁, D₂ to half precision again, at the scale of the remapped matrices (PRECISION).
  if (half_current_) half_current_ = RoundDifferencesToHalf(quadratic_);
  ++stats_.remaps;
}

bool MobilityReuse::RoundDifferencesToHalf(bool with_curve) {
  slope_half_.resize(static_cast<std::size_t>(slope_.size()));
  slope_scale_ = RoundToHalf(slope_.size(), slope_.data(), slope_half_.data());
  if (slope_scale_ <= 0.0f || !with_curve) return slope_scale_ > 0.0f;
  curve_half_.resize(static_cast<std::size_t>(curve_.size()));
  curve_scale_ = RoundToHalf(curve_.size(), curve_.data(), curve_half_.data());
  return curve_scale_ > 0.0f;
}

void MobilityReuse::Forget() {
  geometries_.clear();
  half_current_ = false;
  quadratic_ = false;
  since_ = 0;
  interval_ = 1;
  skip_ = skip_length_ = 0;
  restore_.reset();
}

MobilityReuseHistory MobilityReuse::history() const {
  if (restore_) return *restore_;  // not assembled again yet
  MobilityReuseHistory kept;
  if (tolerance_ <= 0.0) return kept;
  kept.since = since_;
  kept.interval = interval_;
  kept.skip = skip_;
  kept.skip_length = skip_length_;
  kept.geometries = geometries_;
  return kept;
}

void MobilityReuse::Restore(const MobilityReuseHistory& history) {
  Forget();
  if (tolerance_ > 0.0 && !history.geometries.empty()) restore_ = history;
}

bool MobilityReuse::OnTheLine(const VecX& x, double* s) const {
  const std::size_t held = geometries_.size();
  const VecX& last = geometries_[held - 1];
  const VecX step = last - geometries_[held - 2];
  const double step2 = step.squaredNorm();
  *s = step2 > 0.0 ? (x - last).dot(step) / step2 : 0.0;  // Position(x)
  // |x − (x_c + s (x_c − x_b))|² = |x − x_c|² − s² |x_c − x_b|²
  const double off2 = std::max(0.0, (x - last).squaredNorm() - *s * *s * step2);
  return std::abs(*s) <= kMaxLinePosition && off2 <= step2;
}

double MobilityReuse::Position(const VecX& x) const {
  const std::size_t held = geometries_.size();
  if (held < 2) return 0.0;
  const VecX& last = geometries_[held - 1];
  const VecX step = last - geometries_[held - 2];
  const double length2 = step.squaredNorm();
  return length2 > 0.0 ? (x - last).dot(step) / length2 : 0.0;
}

}  // namespace stokesrods
