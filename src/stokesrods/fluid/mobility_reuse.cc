#include "stokesrods/fluid/mobility_reuse.h"

#include <algorithm>
#include <cmath>

namespace stokesrods {

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
    extrapolated->noalias() = base_ + s * slope_;
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
        (base_.cast<double>() + s * slope_.cast<double>() - *assembled).norm() /
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
