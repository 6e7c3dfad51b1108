// Reuse of an assembled dense mobility 𝕄 across the geometries of successive time steps, with an
// a-posteriori control of its error.
//
// 𝕄(x) is assembled at some steps only; in between it is extrapolated along the line through the
// last two assembled geometries x_a, x_b:
//     𝕄(x) ≈ 𝕄_b + s (𝕄_b − 𝕄_a),   s = ⟨x − x_b, x_b − x_a⟩ / |x_b − x_a|²,
// the point on that line nearest x (s = (t − t_b)/(t_b − t_a) for a steady motion). Its error is
// second order in the distance travelled. It is measured at every assembly, where the
// extrapolation is compared with the exact 𝕄 in the relative Frobenius norm
//     e = ‖𝕄_extrapolated − 𝕄‖_F / ‖𝕄‖_F,
// and the number of steps to the next assembly is set so that e stays below `tolerance`: e grows
// like m² with the m steps extrapolated, so m ← m (tolerance / e)^½ × 0.9, at most 2m and
// kMaxInterval. After the first two assemblies m = 1: 𝕄 is assembled at every step, the error of
// a one-step extrapolation measured for free, until it is small enough (e ≤ 0.2 tolerance) for
// m = 2, and so on: no extrapolation goes more than twice as far as one whose error was measured.
// A large step (e(1) > 0.2 tolerance) assembles at every step, exactly as without reuse. Forget
// drops the history (a restart point: the next steps then depend on the state alone). The largest e
// measured is kept in the statistics (an interval is shortened after the fact, not redone).
//
// PRECISION. An assembled 𝕄 is given as it is (double). The history 𝕄_b, 𝕄_b − 𝕄_a and the
// extrapolated 𝕄 are kept in single precision: their rounding (6e-8 relative) is part of the e
// measured, and below a tolerance of about 3e-7 (e(1) > 0.2 tolerance from the rounding alone) 𝕄
// is simply assembled at every step. The extrapolated matrix streams half the bytes of a double
// one in the products, which sum in double (solver/blas.h GemvRowsMixed).
#pragma once

#include <functional>

#include "stokesrods/common/types.h"

namespace stokesrods {

struct MobilityReuseStats {
  long updates = 0;             ///< geometries 𝕄 was taken at
  long assemblies = 0;          ///< of which assembled
  double largest_error = 0.0;   ///< largest e measured (relative Frobenius)
};

class MobilityReuse {
 public:
  /// The most steps between two assemblies.
  static constexpr int kMaxInterval = 20;

  explicit MobilityReuse(double tolerance) : tolerance_(tolerance) {}

  /// 𝕄 at the node positions x (3M): assembled by `assemble` (which writes 𝕄(x) into its
  /// argument) into `assembled` (returns true), or extrapolated into `extrapolated` (single
  /// precision; returns false). With tolerance 0 it always assembles.
  bool Update(const VecX& x, const std::function<void(MatX*)>& assemble, MatX* assembled,
              Eigen::MatrixXf* extrapolated);
  /// Drops the history: the next Update assembles.
  void Forget();
  const MobilityReuseStats& stats() const { return stats_; }

 private:
  double Projection(const VecX& x) const;

  double tolerance_ = 0.0;
  int history_ = 0;    ///< assemblies since Forget (0, 1, 2 = base and slope known)
  int since_ = 0;      ///< updates since the last assembly
  int interval_ = 1;   ///< updates from one assembly to the next
  Eigen::MatrixXf base_;   ///< 𝕄_b
  Eigen::MatrixXf slope_;  ///< 𝕄_b − 𝕄_a (rounded once, from double)
  MatX last_assembled_;    ///< 𝕄_b in double
  VecX base_x_;        ///< x_b
  VecX step_x_;        ///< x_b − x_a
  MobilityReuseStats stats_;
};

}  // namespace stokesrods
