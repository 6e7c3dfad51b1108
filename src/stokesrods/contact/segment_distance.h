// Minimum distance between two segments (paper eq. 17), and the first time two moving segments
// come within a contact distance (continuous collision detection, end of paper section 2.3).
#pragma once

#include <array>

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

/// Robust for parallel, collinear and degenerate (zero-length) segments: the returned distance is
/// the minimum up to round-off of the coordinates at any angle (tested down to 1e-9 rad).
/// Where a continuum of pairs is nearest ((anti)parallel overlapping segments) it returns the
/// middle of the overlap. A closest point at an end has s (or t) exactly 0 or 1.
SegmentClosestPoints ClosestPointsBetweenSegments(const Vec3& a0, const Vec3& a1, const Vec3& b0,
                                                  const Vec3& b1);

/// Result of CalcTimeOfContact.
struct TimeOfContact {
  bool hit = false;       ///< the segments come within the contact distance during the step
  bool converged = true;  ///< false if max_iterations ran out; `time` is then a lower bound
  double time = 1.0;      ///< fraction of the step τ ∈ [0, 1] of the first contact (1 if none)
  int iterations = 0;
  SegmentClosestPoints closest;  ///< at `time`
};

/// Continuous collision detection for two segments whose nodes move linearly over a step:
/// x_k(τ) = start_k + τ (end_k − start_k), τ ∈ [0, 1], nodes ordered (a0, a1, b0, b1). Finds the
/// first τ with δ_min(τ) ≤ contact_distance + tolerance [m] by conservative advancement: a point
/// of either segment moves with a convex combination of its nodes' velocities, so δ_min(τ) is
/// Lipschitz with V = max_{k∈a, l∈b} |Δx_k − Δx_l|, and advancing by (δ_min − contact_distance)/V
/// never steps over a contact. Guarantees δ_min(τ') > contact_distance for all τ' < time, and
/// δ_min(time) ≤ contact_distance + tolerance when hit. Grazing paths converge slowly: capped by
/// max_iterations. Preconditions: contact_distance ≥ 0, tolerance > 0.
TimeOfContact CalcTimeOfContact(const std::array<Vec3, 4>& start, const std::array<Vec3, 4>& end,
                                double contact_distance, double tolerance,
                                int max_iterations = 10000);

}  // namespace stokesrods
