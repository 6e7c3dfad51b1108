// The far field of the matrix-free RSS mobility (mobility_operator.cc) summed directly, with for
// each group of targets and each source rod the fewest Gauss points per segment that meet the
// tolerance there.
//
// The operator's split takes n points on every segment and the closed forms on segments nearer
// than NearRadius(n) of their lengths. The k-point rule (2 ≤ k < n) meets the same tolerance from
// NearRadius(k) segment lengths on (GaussRuleError), so a rod whose every segment lies that far
// from a group of targets is summed there with k points; the same holds chunk by chunk of a rod's
// consecutive segments. With δ = √(d² + ε²)/|v| (d from a target to the segment), it is enough that
//     d_box² ≥ NearRadius(k)² max_s |v_s|²,
// d_box the distance between the group's bounding box and the chunk's (which holds its segments;
// leaving ε² out makes the test conservative), the maximum over the chunk's segments.
// Near segments (δ < NearRadius(n)) only occur in chunks that fail this test for every k < n, so
// they keep the n-point rule. Ten helices on a ring 3R apart take n = 3 (ChooseSplitByCost), and
// most of the other rods' chunks are far enough for 2.
//
// The near pairs are left out of the sum (Build's `excluded`): their near corrections carry the
// closed forms alone, instead of the closed forms minus the rule that the sum would add. The two
// agree to rounding, but the rule's terms at the nearest pairs are the largest of the sum, and in
// single precision their rounding (≈ 1e-7 of each, different at every step as the rods move) was
// the step-to-step noise of the operator that the drag's extrapolation amplifies into GMRES's
// right-hand side (docs/performance.md, sessions 26, 29 and 30). The targets are summed K at a
// time over shared ranges of sources (point_stokeslet.h); the union of the K targets' left-out
// points is cut from those ranges and summed for each target alone, without its own. In single
// precision each range is summed in lanes of its own and added to the ranges' lanes after it
// (AddPointSumRangesTargets' flush_ranges): the accumulation's rounding, the next largest part of
// that noise, falls with it (ring10: GMRES products per step 2.7 → 2.45).
// Used where the far sum is direct (the FMM sums one set of points, and its tree replaces the
// distant pairs anyway).
#pragma once

#include <cstdint>
#include <vector>

#include "stokesrods/common/types.h"
#include "stokesrods/fluid/point_stokeslet.h"

namespace stokesrods {

class FarRuleSum {
 public:
  /// Consecutive targets taken as one group, and consecutive segments of a rod as one chunk: the
  /// distance between their bounding boxes decides the chunk's rule at the group's targets.
  static constexpr int kGroupTargets = 16;
  static constexpr int kChunkSegments = 16;

  /// Segment s runs from nodes.col(first_node[s]) to the next column, with blob size eps[s]; rod
  /// r's segments are [rod_first_segment[r], rod_first_segment[r + 1]). points: the split's n
  /// (≥ 2); accuracy: its tolerance (NearRadius); single: kernel sums in single precision
  /// (kSinglePrecisionTolerance). The targets are the nodes. excluded (optional, one sorted list
  /// per node): the segments whose n-point rule the sum leaves out at that node (its near
  /// segments: δ < NearRadius(n), so their chunks are on the n-point rule, which is checked).
  void Build(const Matrix3X& nodes, const std::vector<int>& first_node, const VecX& eps,
             const std::vector<int>& rod_first_segment, int points, double accuracy, bool single,
             const std::vector<std::vector<int>>* excluded = nullptr);

  /// w (3 × M) = Σ_segments Σ_q w_q L S_ε(x_t − y_q) ((1 − α_q) f_a + α_q f_b), each rod with the
  /// rule Build chose for the target's group; density: the nodal force densities f (3 × M).
  void Apply(const Matrix3X& density, Matrix3X* w) const;

  /// Kernel evaluations per Apply; the same sum with n points everywhere (and no pair left out)
  /// would take pairs_at_n() (for the tests and the bench); excluded_pairs(): the (node, rule
  /// point) pairs left out.
  std::int64_t pairs() const { return pairs_; }
  std::int64_t pairs_at_n() const { return pairs_at_n_; }
  std::int64_t excluded_pairs() const { return excluded_pairs_; }

 private:
  struct Rule {
    int points = 0;
    int first_source = 0;  // its point q of segment s is source first_source + s × points + q
    const double* alpha = nullptr;
    const double* weight = nullptr;
  };
  void FillStrengths(const Matrix3X& density) const;

  bool single_ = false;
  std::vector<Rule> rules_;       // k = 2 … n
  std::vector<int> first_node_;   // per segment
  VecX length_;                   // per segment
  Matrix3X targets_;
  Eigen::Matrix3Xf targets_f_;    // relative to the nodes' mean (single precision)
  mutable MatX src_;              // sources × 7 (x, y, z, ε², g): g of the last Apply in double
  mutable Eigen::MatrixXf src_f_; // single precision: positions relative to that mean, and g
  // Per pass p over kPointSumTargets consecutive targets (the passes of a group one after the
  // other): the source ranges all its targets take, range_[range_start_[p] …), each one or more
  // consecutive chunks on one rule minus the pass's left-out points; per target t, the rest of
  // those points but its own, own_range_[own_start_[t] …).
  std::vector<int> range_start_, own_start_;
  std::vector<SourceRange> range_, own_range_;
  std::int64_t pairs_ = 0, pairs_at_n_ = 0, excluded_pairs_ = 0;
};

}  // namespace stokesrods
