// The FMM's order and cost model (fmm_sum.cc): which expansion order p meets a tolerance, and what
// each piece of an Apply and of a Build costs in kernel evaluations (pairs of the direct sum), from
// which the tree's depth and whether it pays at all are chosen (fmm_tree.h, BuildFmmTree).
#pragma once

#include "stokesrods/fluid/fmm_tree.h"
#include "stokesrods/fluid/stokeslet_sum.h"

namespace stokesrods {

/// The relative cutoff of the pseudo-inverses of the FMM's fits (GetFmmOperators).
inline constexpr double kFmmCutoff = 1e-6;

/// p for the options (their `order` if set); 0 when no order reaches the tolerance.
int OrderFor(const StokesletSumOptions& options);

/// The costs of a tree of order p for a sum with these options (its M2L by transforms or not,
/// the Applies a Build serves).
FmmCost EstimatedFmmCost(int order, const StokesletSumOptions& options);

}  // namespace stokesrods
