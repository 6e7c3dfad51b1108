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
// drops the history. The largest e measured is kept in the statistics (an interval is shortened
// after the fact, not redone).
//
// RESTART. A checkpoint keeps the history without its matrices (MobilityReuseHistory: where the
// last two assemblies were taken, the counters); Restore assembles 𝕄 there again, bit for bit the
// matrices the uninterrupted run holds, so a run need not forget the history at its restart
// points (forgetting costs the ramp of assemblies above, every 60 steps).
//
// PRECISION. An assembled 𝕄 is given as it is (double). The history 𝕄_b, 𝕄_b − 𝕄_a and the
// extrapolated 𝕄 are kept in single precision: their rounding (6e-8 relative) is part of the e
// measured, and below a tolerance of about 3e-7 (e(1) > 0.2 tolerance from the rounding alone) 𝕄
// is simply assembled at every step. The extrapolated matrix streams half the bytes of a double
// one in the products, which sum in double (solver/blas.h GemvRowsMixed).
#pragma once

#include <functional>
#include <optional>

#include "stokesrods/common/types.h"

namespace stokesrods {

struct MobilityReuseStats {
  long updates = 0;             ///< geometries 𝕄 was taken at
  long assemblies = 0;          ///< of which assembled
  double largest_error = 0.0;   ///< largest e measured (relative Frobenius)
};

/// The reuse's history short of its matrices: what a checkpoint keeps (io/checkpoint.h).
struct MobilityReuseHistory {
  int assemblies = 0;  ///< held since the last Forget: 0, 1 or 2 (base and slope)
  int since = 0;       ///< updates since the last assembly
  int interval = 1;    ///< updates from one assembly to the next
  VecX x_a;            ///< the geometry of the assembly before the last (assemblies = 2)
  VecX x_b;            ///< the geometry of the last assembly (assemblies ≥ 1)
};

class MobilityReuse {
 public:
  /// Assembles 𝕄 at the node positions x (3M) into its second argument.
  using Assemble = std::function<void(const VecX& x, MatX*)>;

  /// The most steps between two assemblies.
  static constexpr int kMaxInterval = 20;

  explicit MobilityReuse(double tolerance) : tolerance_(tolerance) {}

  /// 𝕄 at the node positions x (3M): assembled by `assemble` into `assembled` (returns true), or
  /// extrapolated into `extrapolated` (single precision; returns false). With tolerance 0 it
  /// always assembles. After Restore it first assembles the restored history again.
  bool Update(const VecX& x, const Assemble& assemble, MatX* assembled,
              Eigen::MatrixXf* extrapolated);
  /// Drops the history: the next Update assembles.
  void Forget();
  /// The history as a checkpoint keeps it.
  MobilityReuseHistory history() const;
  /// Takes a history kept by history(): the next Update assembles 𝕄 at its geometries first, then
  /// goes on as the reuse it was taken from would (a history of another size is dropped there).
  void Restore(const MobilityReuseHistory& history);
  const MobilityReuseStats& stats() const { return stats_; }

 private:
  double Projection(const VecX& x) const;
  /// Takes the assembled 𝕄(x) into the history; measures the extrapolation's miss when `measure`.
  void Take(const VecX& x, const MatX& assembled, bool measure);

  double tolerance_ = 0.0;
  int history_ = 0;    ///< assemblies since Forget (0, 1, 2 = base and slope known)
  int since_ = 0;      ///< updates since the last assembly
  int interval_ = 1;   ///< updates from one assembly to the next
  Eigen::MatrixXf base_;   ///< 𝕄_b
  Eigen::MatrixXf slope_;  ///< 𝕄_b − 𝕄_a (rounded once, from double)
  MatX last_assembled_;    ///< 𝕄_b in double
  VecX base_x_;        ///< x_b
  VecX previous_x_;    ///< x_a
  VecX step_x_;        ///< x_b − x_a
  std::optional<MobilityReuseHistory> restore_;  ///< to assemble again at the next Update
  MobilityReuseStats stats_;
};

}  // namespace stokesrods
