// A plane no-slip wall as more sources of flow behind the MobilityOperator interface (issue 11),
// for an operator that holds no matrix (the matrix-free RSS, with or without cell bodies).
//
// The wall adds the images of every source seen at every target (wall.h: the regularized image
// system W − S_ε of a blob): the sources are the rods' segments and the bodies' surface points,
// the targets the rods' nodes and the bodies' points. The free-space operator it wraps gives the
// rest. The images of a segment are integrated like the free part is by the matrix-free RSS:
//   far   an n-point Gauss–Legendre rule on every segment, its point images summed directly at
//         every target (O((nS + P)(M + P)) per product, no storage);
//   near  where the target is close to the mirrored segment (δ* = √(d*² + ε²)/L below a radius
//         set by the tolerance, wall.h WallImageDelta), the accurate images
//         (StokesletSegmentWallImages) minus that rule, stored as 3 × 3 blocks.
// The rule's points n and the near radius come from the images' measured rule error
// (WallImageRuleError) for the rods' far-field accuracy max(tolerance, fast_sum_tolerance): every
// far segment–target pair of the images to that relative accuracy, as the free part
// (tests/fluid/wall_sources_test.cc: against the dense mobility with the wall). A body point is a
// blob: its images are evaluated exactly.
#pragma once

#include <memory>

#include "stokesrods/fluid/mobility_operator.h"

namespace stokesrods {

/// Near/far split of the images: the rule's points and the near radius δ* for an accuracy, the
/// fewest points whose near radius is at most `max_near_delta` segment lengths.
NearFarSplit ChooseWallImageSplit(double tolerance, double max_near_delta = 12.0);

/// `free_space`: the matrix-free operator of the rods (and bodies) without the wall; `params`
/// holds the wall. Sizes and layout are free_space's.
std::unique_ptr<MobilityOperator> MakeMobilityWithWallImages(
    const FluidParams& params, const MobilityOptions& options,
    std::unique_ptr<MobilityOperator> free_space);

}  // namespace stokesrods
