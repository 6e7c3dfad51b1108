#include "stokesrods/fluid/fmm_cost.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace stokesrods {
namespace {

// ORDER. Measured error (the header's norm; tests/fluid/stokeslet_sum_test.cc) with p points per
// edge, the worst of random clouds (6 000 × 3 000 and 20 000 × 5 000 points in a cube) and helix
// lattices (20 and 100 helices), pseudo-inverses cut at 1e-6 σ_max (smaller cutoffs were worse,
// 1e-9 gave 1e-4 at p = 5: the fits amplify rounding; kFmmCutoff):
//     p            4        5        6
//     3n           168      294      456      (n = p³ − (p−2)³ points per surface)
//     error        6.4e-5   1.4e-5   8.1e-7
// We take the smallest p whose error × 1.5 is within the tolerance: p = 4 from 1e-4, 5 from 2e-5,
// 6 from 1.25e-6; below that no order (p = 7 would store 0.5 GB of K_v) and the sum is direct.
// These are errors of many sources, where the exact near field dominates Σ|S||g|; one source
// alone against targets just past its neighbour boxes (one box width away) is approximated far
// worse, like any FMM on 1-separated boxes: worst of 20 placements 2e-2, 4e-2, 1.8e-4 relative
// at p = 4, 5, 6.
constexpr std::array<double, 3> kOrderError = {6.4e-5, 1.4e-5, 8.1e-7};  // p = 4, 5, 6

/// The far part's cost in a whole Apply over its estimate from BM_M2lLevel's constants.
constexpr double kFarCostInApply = 1.5;
/// A whole Apply over its estimate, and the Build per point in pairs of the direct sum (0.41 ns
/// each here), measured on five trees (BM_StokesletSum{Build,Apply}/{20,50,100}/4/2 and
/// BM_CentroidSum/{50,100}/2, one thread, idle): Apply 1.05, 1.19, 1.13, 1.29, 1.18 × its
/// estimate; Build 264, 338, 375, 308, 317 pairs per point (docs/performance.md, "Session 13").
constexpr double kApplyOverEstimate = 1.18;
constexpr double kBuildPerPoint = 350.0;

}  // namespace

int OrderFor(const StokesletSumOptions& options) {
  if (options.order > 0) return options.order;
  for (int p = 4; p <= 6; ++p)
    if (1.5 * kOrderError[static_cast<size_t>(p - 4)] <= options.tolerance) return p;
  return 0;
}

FmmCost EstimatedFmmCost(int order, const StokesletSumOptions& options) {
  const double n = order * order * order - (order - 2) * (order - 2) * (order - 2);
  // Costs in kernel evaluations (one pair of the near field): an M2L is n² of them (AddM2l),
  // an entry of the dense per-box translations ≈ 0.05 (BLAS products over all boxes).
  const double entries = 9.0 * n * n;
  FmmCost cost{.per_point = n, .per_box = 0.05 * 4.0 * entries, .per_m2l = n * n};
  if (options.m2l_by_fft) {
    // Measured (bench BM_M2lLevel, single precision, one thread, in near-field pairs of
    // 0.45 ns): a product 1.66 per frequency of the padded spectrum (155 ns at p = 4, 310 at
    // 5, 555 at 6); a box's transforms ≈ 2.5 × the 2 p H N (p + N) complex multiply–adds of
    // one column (3.0, 7.0, 13.4 µs), H = p frequencies along z, N = 2p − 1.
    const double grid = 2 * order - 1, stride = std::ceil(grid * grid * order / 16.0) * 16.0;
    cost.per_m2l = 1.66 * stride;
    cost.per_box += 2.5 * 2.0 * order * order * grid * (order + grid);
  }
  // Those constants are measured on one level of 64 boxes that stays in cache; in a whole
  // Apply the far part costs more (the 100-helix lattice ran 1.5× its estimate, at session
  // 11's constants): both ×1.5, which there takes the tree with 12.9 M near pairs instead of
  // 8.3 M, and a 4–5 % faster Apply (docs/performance.md, session 12).
  cost.per_m2l *= kFarCostInApply;
  cost.per_box *= kFarCostInApply;
  cost.apply_scale = kApplyOverEstimate;
  cost.per_point_build = kBuildPerPoint / std::max(1.0, options.applies_per_build);
  return cost;
}

}  // namespace stokesrods
