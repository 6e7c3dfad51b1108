// Minimum distance between two segments (paper eq. 17).
#pragma once

#include "stokesrods/common/types.h"

namespace stokesrods {

/// Closest points p = a0 + s (a1 − a0) and q = b0 + t (b1 − b0), s, t ∈ [0, 1], of two segments.
struct SegmentClosestPoints {
  double distance = 0.0;  ///< |p − q| [m]
  double s = 0.0;         ///< parameter on segment a: barycentric weights (1 − s, s) on (a0, a1)
  double t = 0.0;         ///< parameter on segment b
  Vec3 p = Vec3::Zero();
  Vec3 q = Vec3::Zero();
};

/// Robust for parallel, collinear and degenerate (zero-length) segments.
SegmentClosestPoints ClosestPointsBetweenSegments(const Vec3& a0, const Vec3& a1, const Vec3& b0,
                                                  const Vec3& b1);

}  // namespace stokesrods
