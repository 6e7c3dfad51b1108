// Cell bodies as more sources of flow behind the MobilityOperator interface (issue 11), for an
// operator of the rods that holds no matrix (the matrix-free RSS).
//
// The unknowns are those of AssembleBorderedMobility: the rods' M nodal forces, the bodies' P
// point forces, then (U, Ω) of each free body. The product is assembled from its blocks:
//   rods ← rods    the rods' own operator (matrix-free: near closed forms + far Gauss sum);
//   rods ← bodies  the bodies' regularized point Stokeslets at the rod nodes;
//   bodies ← rods  the rods' segments at the body points, as the matrix-free operator does it:
//                  the far field by the same Gauss rule at the P points, the segments near a
//                  point (δ below the split's near radius) by their closed forms minus that rule,
//                  stored as 3 × 3 blocks (O(P × near segments)), found by the rods' operator as
//                  at its own nodes (MobilityOperator::FindNearBlocks);
//   bodies ← bodies  the points' regularized Stokeslets;
//   the point sums by the rods' operator's fast sum (fluid/stokeslet_sum.h, its options: direct
//   below direct_sum_below pairs, else the FMM where it pays), two per update: {Gauss points,
//   body points} at the body points, body points at the rod nodes; nothing O(P²) stored;
//   the free bodies' border, G V on their points' rows and Gᵀ f in their six rows.
// Its accuracy is the rods' operator's: every far segment–point pair by the rule the split
// chooses for max(tolerance, fast_sum_tolerance) (tests/fluid/mobility_sources_test.cc: against
// the dense bordered mobility). No wall here: its images are wrapped around it (wall_sources.h).
#pragma once

#include <memory>
#include <vector>

#include "stokesrods/fluid/mobility_operator.h"

namespace stokesrods {

/// `rods_operator`: the matrix-free operator of the rods alone (it takes Update and gives the
/// near blocks); the bodies are added here.
std::unique_ptr<MobilityOperator> MakeMobilityWithBodySources(
    const FluidParams& params, const MobilityOptions& options,
    std::unique_ptr<MobilityOperator> rods_operator);

}  // namespace stokesrods
