// Reuse of an assembled dense mobility 𝕄 across the geometries of successive time steps, with an
// a-posteriori control of its error.
//
// 𝕄(x) is assembled at some steps only; in between it is extrapolated through the last three
// assembled geometries x_a, x_b, x_c (two at first) as a function of the position s of x on the
// line through the last two,
//     s(x) = ⟨x − x_c, x_c − x_b⟩ / |x_c − x_b|²      (s(x_c) = 0, s(x_b) = −1, s(x_a) = s_a),
// by the quadratic through the three (Newton's form; linear while only two are held):
//     𝕄(x) ≈ 𝕄_c + s D₁ + s (s + 1) D₂,   D₁ = 𝕄_c − 𝕄_b,
//     D₂ = (D₁ − (𝕄_b − 𝕄_a)/(−1 − s_a)) / (−s_a)
// (s = (t − t_c)/(t_c − t_b) for a steady motion, and s_a = −2 for equal intervals). Its error is
// third order in the distance travelled (second for the linear one). It is measured at every
// assembly, where the extrapolation is compared with the exact 𝕄 in the relative Frobenius norm
//     e = ‖𝕄_extrapolated − 𝕄‖_F / ‖𝕄‖_F,
// and the number of steps to the next assembly is set so that e stays below `tolerance`: e grows
// like m^p with the m steps extrapolated (p = 3, or 2 for the linear one), so
// m ← m (tolerance / e)^(1/p) × 0.9, at most 2m and kMaxInterval. After the first two assemblies
// m = 1: 𝕄 is assembled at every step, the error of a one-step extrapolation measured for free,
// until it is small enough for m = 2, and so on: no extrapolation goes more than twice as far as
// one whose error was measured. A large step (e(1) > 0.45^p tolerance) assembles at every step,
// exactly as without reuse. The quadratic term is left out (linear) where the
// interval before the last is under a quarter of the last (|1 + s_a| < 1/4: its divided
// difference would amplify the history's rounding). Forget drops the history. The largest e
// measured is kept in the statistics (an interval is shortened after the fact, not redone).
//
// SKIPPING. Measuring and keeping D₁, D₂ is a pass over four matrices at each assembly. Where
// even the quadratic extrapolation misses for two steps (m stays 1: large steps), the next
// assemblies take 𝕄_c only (the history restarted from each, as the first after Forget), 1, 2,
// 4, then kMaxSkip of them in a row while that repeats; then the history is rebuilt over the
// next three (D₁, D₂ and the measurement). 𝕄 is assembled at every step either way, so the
// results are the same; reuse can start at most kMaxSkip + 2 assemblies later than with a
// measurement at every one.
//
// Measured on paper Fig. 1 at h = 1 ms (t = 0.3 s, assembling at every step for the check): 20
// steps from a history 8 steps apart miss by 9.5e-5 linearly and 4.0e-6 quadratically; 40 steps
// by 3.3e-4 and 2.1e-5 (docs/performance.md).
//
// REMAP. Where the matrix's columns change from one Update to the next (a near pair of the
// matrix-free operator comes or goes), the columns kept keep their history and each new column
// gets the one it would have had: its values at the held geometries (at most kMaxHeld), taken
// oldest first through the same passes (𝕄_c, D₁ against the rounded 𝕄_c, D₂ through s_a of the
// same geometries). Only D₁, D₂'s rounding to half precision differs: the new columns' D₁ is
// rounded at the scale of the whole matrix once, not at each of its past assemblies. The
// interval and the error measured are the history's: the next assembly measures every column.
// Before, a change of the pattern dropped the history, and 20–100 helices 4R apart, whose near
// pairs change every few steps, assembled at 0.4–0.8 of the steps instead of 0.08.
//
// JUMPS. The extrapolation is used only for geometries that continue the motion it was
// measured on: along the line no farther than kMaxLinePosition |x_c − x_b| from x_c (a steady
// motion reaches s ≤ 2 + 1/k: the interval at most doubles), and off it by at most |x_c − x_b|
// (a turn of θ per interval leaves the line by ~θ s² |x_c − x_b|). Any other geometry (a rod
// moved by hand, a restored state, a jump of the near pattern's geometry) is assembled, and the
// error measured there sets the interval as for a large step.
//
// RESTART. A checkpoint keeps the history without its matrices (MobilityReuseHistory: where its
// assemblies were taken, the counters); Restore assembles 𝕄 there again, bit for bit the
// matrices the uninterrupted run holds, so a run need not forget the history at its restart
// points (forgetting costs the ramp of assemblies above).
//
// PRECISION. An assembled 𝕄 is given as it is (double). The history 𝕄_c, D₁, D₂ and the
// extrapolated 𝕄 are kept in single precision (D₁ is taken against the rounded 𝕄_c): their
// rounding (6e-8 relative, a few times that through s and s(s + 1)) is part of the e measured,
// and at a tolerance near it 𝕄 is simply assembled at every step (tested at 1e-8; reused at 1e-5). The extrapolated matrix
// streams half the bytes of a double one in the products, which sum in double (solver/blas.h
// GemvRowsMixed). From a tolerance of kSinglePrecisionTolerance (1e-4) on, the dense operator's
// products take the assembled 𝕄 rounded too (last_assembly_single(), the history's 𝕄_c): at a
// large step, where 𝕄 is assembled at every step, each product then streams half the bytes.
// With `half_differences` (that tolerance, and a CPU with AVX-512 BW or F16C: mobility_reuse_half.h)
// D₁ and D₂ are also rounded to IEEE half precision, each scaled by a power of two, and the
// single-precision D₁, D₂ the measurement reads are replaced by the values the half ones stand
// for: the extrapolation streams 𝕄_c and half of D₁, D₂'s bytes, and e still measures exactly
// what it uses (half's 2⁻¹¹ relative rounding of D₁, itself ~1e-2 of 𝕄 over an interval, is
// ~1e-5 of 𝕄 at most: inside the default 1e-4).
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <utility>
#include <vector>

#include "stokesrods/common/types.h"

namespace stokesrods {

struct MobilityReuseStats {
  long updates = 0;             ///< geometries 𝕄 was taken at
  long assemblies = 0;          ///< of which assembled
  double largest_error = 0.0;   ///< largest e measured (relative Frobenius)
  long measurements = 0;        ///< assemblies at which e was measured
  long remaps = 0;              ///< column changes taken into the history (Remap)
};

/// The reuse's history short of its matrices: what a checkpoint keeps (io/checkpoint.h).
struct MobilityReuseHistory {
  int since = 0;       ///< updates since the last assembly
  int interval = 1;    ///< updates from one assembly to the next
  int skip = 0;        ///< assemblies left that take 𝕄_c only (MobilityReuse::kMaxSkip)
  int skip_length = 0; ///< the length of the last such run
  /// The geometries (3M each) of the assemblies held since the last Forget, oldest first: at
  /// most kMaxHeld.
  std::vector<VecX> geometries;
};

class MobilityReuse {
 public:
  /// Assembles 𝕄 at the node positions x (3M) into its second argument.
  using Assemble = std::function<void(const VecX& x, MatX*)>;
  /// The most steps between two assemblies.
  static constexpr int kMaxInterval = 40;
  /// The most assemblies the extrapolation goes through.
  static constexpr int kMaxHeld = 3;
  /// The most assemblies in a row that take 𝕄_c only, after the quadratic extrapolation missed
  /// for even two steps.
  static constexpr int kMaxSkip = 8;
  /// The farthest along the line, in units of |x_c − x_b|, the history extrapolates (JUMPS).
  static constexpr double kMaxLinePosition = 4.0;

  /// `half_differences`: D₁, D₂ in half precision where the CPU has the kernels (PRECISION).
  explicit MobilityReuse(double tolerance, bool half_differences = false);

  /// 𝕄 at the node positions x (3M): assembled by `assemble` into `assembled` (returns true), or
  /// extrapolated into `extrapolated` (single precision; returns false). With tolerance 0 it
  /// always assembles. After Restore it first assembles the restored history again.
  bool Update(const VecX& x, const Assemble& assemble, MatX* assembled,
              Eigen::MatrixXf* extrapolated);
  /// The values of the columns new to a Remap (in their order) at the node positions x.
  using AssembleColumns = std::function<void(const VecX& x, MatX* columns)>;
  /// The matrix's columns change (the near pairs of the matrix-free operator): column j becomes
  /// column old_column[j] of the history, or, where old_column[j] < 0, a new one. The new columns
  /// are assembled at each geometry held, oldest first, and taken through the passes their
  /// assemblies would have made (REMAP), so the history goes on instead of starting again.
  /// Nothing to do without a history (the next Update assembles).
  void Remap(const std::vector<int>& old_column, const AssembleColumns& assemble);
  /// Drops the history: the next Update assembles.
  void Forget();
  /// The tolerance from now on (the next assembly measures against it and sets the interval).
  void set_tolerance(double tolerance) { tolerance_ = tolerance; }
  /// The matrix's columns hold `weights.size()` rows, row r standing for weights[r] entries in
  /// the Frobenius norms of e (the near corrections' symmetric blocks keep an off-diagonal entry
  /// once for its two places: weight 2). None (the default): every entry once.
  void set_row_weights(std::vector<double> weights) { row_weights_ = std::move(weights); }
  /// The history as a checkpoint keeps it.
  MobilityReuseHistory history() const;
  /// Takes a history kept by history(): the next Update assembles 𝕄 at its geometries first, then
  /// goes on as the reuse it was taken from would (a history of another size is dropped there).
  void Restore(const MobilityReuseHistory& history);
  const MobilityReuseStats& stats() const { return stats_; }
  /// 𝕄 of the last assembly rounded to single precision (the history's 𝕄_c); empty with
  /// tolerance 0 and before the first assembly.
  const Eigen::MatrixXf& last_assembly_single() const { return base_; }

 private:
  /// s(x) on the line through the last two geometries.
  double Position(const VecX& x) const;
  /// x is one the history may extrapolate to (JUMPS): |s(x)| ≤ kMaxLinePosition and x within
  /// |x_c − x_b| of the line; s = s(x) either way. Needs two geometries held.
  bool OnTheLine(const VecX& x, double* s) const;
  /// D₁ (and D₂ `with_curve`) to half precision (PRECISION); false where one is not finite.
  bool RoundDifferencesToHalf(bool with_curve);
  /// Takes the assembled 𝕄(x) into the history; measures the extrapolation's miss when `measure`.
  void Take(const VecX& x, const MatX& assembled, bool measure);

  double tolerance_ = 0.0;
  int since_ = 0;      ///< updates since the last assembly
  int interval_ = 1;   ///< updates from one assembly to the next
  int skip_ = 0;         ///< assemblies left that take 𝕄_c only
  int skip_length_ = 0;  ///< the last run of them: doubles while the extrapolation keeps missing
  std::vector<VecX> geometries_;  ///< of the assemblies held, oldest first (≤ kMaxHeld)
  bool quadratic_ = false;        ///< curve_ holds D₂
  Eigen::MatrixXf base_;   ///< 𝕄_c
  Eigen::MatrixXf slope_;  ///< D₁
  Eigen::MatrixXf curve_;  ///< D₂
  bool half_ = false;      ///< D₁, D₂ rounded to half precision at each assembly (PRECISION)
  bool half_current_ = false;  ///< slope_half_ (and curve_half_ if quadratic_) hold D₁, D₂
  std::vector<std::uint16_t> slope_half_, curve_half_;  ///< σ₁ D₁, σ₂ D₂ in half precision
  float slope_scale_ = 1.0f, curve_scale_ = 1.0f;       ///< σ₁, σ₂: powers of two
  std::vector<double> row_weights_;  ///< each row's weight in e's norms (set_row_weights)
  std::optional<MobilityReuseHistory> restore_;  ///< to assemble again at the next Update
  MobilityReuseStats stats_;
};

}  // namespace stokesrods
