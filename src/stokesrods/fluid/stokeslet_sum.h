// Sums of regularized point Stokeslets over many sources at many targets: the far field of the
// matrix-free RSS mobility (fluid/mobility_operator.h), where each rod segment is replaced by a
// few Gauss points once it is far enough from the target.
//
//     w(x_t) = Σ_s S_{ε_s}(x_t − y_s) g_s,   S_ε(r) = (1/R + ε²/R³) I + r rᵀ/R³,  R² = |r|² + ε²
//
// (8πμ times a velocity when g_s are point forces [N]; the kernel is RegularizedStokesletMatrix of
// stokeslet_segment.h). The positions are fixed by Build; Apply is then called many times with
// different source strengths g (a Krylov solve within one time step).
//
// Two implementations behind one interface: the direct O(S T) sum (the reference) and a fast
// summation whose relative error is bounded by `tolerance` (tests/fluid/stokeslet_sum_test.cc).
#pragma once

#include <cstdint>
#include <memory>

#include "stokesrods/common/types.h"

namespace stokesrods {

struct StokesletSumOptions {
  /// Requested accuracy of the fast sum: |w_fast − w_direct|_∞ ≤ tolerance · Σ_s |S(x_t−y_s)||g_s|
  /// per target (relative to the sum of magnitudes) [–].
  double tolerance = 1e-6;
  /// The fast sum sums directly when (sources × targets) is below this.
  std::int64_t direct_below_pairs = 1'000'000;
  /// Most points in a leaf of the source and target cluster trees.
  int leaf_size = 32;
  /// A block (target cluster τ, source cluster σ) is approximated at low rank when
  /// max(diam τ, diam σ) ≤ admissibility · dist(τ, σ) (bounding boxes) [–].
  double admissibility = 1.0;
  /// Memory for the low-rank factors; above it Build gives up and the sum is direct [MB].
  double max_megabytes = 300.0;
  /// Estimate the memory and the Apply cost of the hierarchical matrix before building it, and
  /// sum directly when it would not fit or not pay off (false: always build it, for tests).
  bool choose_by_cost = true;
};

/// What a Build produced (for tests and benchmarks).
struct StokesletSumStats {
  std::int64_t near_pairs = 0;  ///< (target, source) pairs summed exactly
  std::int64_t far_pairs = 0;   ///< (target, source) pairs in low-rank (far-field) blocks
  std::int64_t stored_values = 0;  ///< doubles stored by Build (low-rank factors, points)
  int max_rank = 0;                ///< largest rank of a far-field block
};

class StokesletSum {
 public:
  virtual ~StokesletSum() = default;
  /// Sets the geometry: sources (3 × S) with their blob sizes ε_s (S) [m], and targets (3 × T).
  virtual void Build(const Matrix3X& sources, const VecX& regularization,
                     const Matrix3X& targets) = 0;
  /// w (3 × T) from the source strengths g (3 × S). Thread-safe for concurrent calls: no.
  virtual void Apply(const Matrix3X& strengths, Matrix3X* w) const = 0;
  /// Counters of the last Build.
  virtual StokesletSumStats Stats() const = 0;
};

/// The direct sum (OpenMP over targets): exact to rounding, O(S T) per Apply.
std::unique_ptr<StokesletSum> MakeDirectStokesletSum();

/// The fast sum (tree code / fast multipole; see stokeslet_sum.cc for the method and its error
/// control). Falls back to the direct sum for small problems.
std::unique_ptr<StokesletSum> MakeFastStokesletSum(const StokesletSumOptions& options);

}  // namespace stokesrods
