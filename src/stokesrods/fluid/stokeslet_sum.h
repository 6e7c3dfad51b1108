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
// Two implementations behind one interface: the direct O(S T) sum (the reference) and a
// kernel-independent fast multipole method (fmm_sum.cc) whose error, measured on clouds and helix
// lattices, is within `tolerance` (tests/fluid/stokeslet_sum_test.cc); it sums directly where its
// cost model says the tree would not pay.
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
  /// Sum directly when the cost model of the tree says it would not pay (false: build the tree
  /// whenever the points allow one, for tests).
  bool choose_by_cost = true;
  /// Points per edge of the FMM's surfaces; 0: chosen from the tolerance (fmm_sum.cc).
  int order = 0;
  /// The FMM's V-list translations by Fourier transforms (fmm_m2l_fft.h); false: each evaluated
  /// directly as a sum of the source box's equivalent Stokeslets (the reference, for tests).
  bool m2l_by_fft = true;
  /// Applies expected per Build: the tree's cost model charges each Apply this share of the
  /// Build's (fmm_sum.cc). The mobility's far sum is built every step and applied ~5 times; the
  /// preconditioner's coarse sum is built with the preconditioner (at most every 40 steps).
  double applies_per_build = 5.0;
};

/// What a Build produced (for tests and benchmarks).
struct StokesletSumStats {
  std::int64_t near_pairs = 0;  ///< (target, source) pairs summed exactly
  std::int64_t far_pairs = 0;   ///< (target, source) pairs summed by expansions
  std::int64_t stored_values = 0;  ///< doubles stored by Build (points, expansions)
  int max_rank = 0;                ///< rank of the compressed M2L translations
  /// Estimated cost of one Apply with its share of the Build, in kernel evaluations (the direct
  /// sum: sources × targets).
  double cost = 0.0;
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

/// The direct sum (OpenMP over targets): exact to rounding, O(S T) per Apply. In single precision
/// (the fast sum's fallback at tolerances ≥ kSinglePrecisionTolerance) each term is exact to
/// ~1e-7 of itself plus the positions' rounding (point_stokeslet.h).
std::unique_ptr<StokesletSum> MakeDirectStokesletSum(bool single_precision = false);

/// The fast sum computes its kernel evaluations in single precision from this tolerance on:
/// float's ~6e-8 rounding of the terms and of positions (~1e-7 of the lattice's extent, 1e-5 of
/// ε = 1 mm at 0.4 m) stays ten times below it (measured: tests/fluid/stokeslet_sum_test.cc).
inline constexpr double kSinglePrecisionTolerance = 1e-4;

/// The fast sum (a kernel-independent fast multipole method; see fmm_sum.cc for the method and
/// its error control). Falls back to the direct sum for small problems and where it does not pay.
std::unique_ptr<StokesletSum> MakeFastStokesletSum(const StokesletSumOptions& options);

}  // namespace stokesrods
