// Broad phase: candidate segment pairs whose axis-aligned bounding boxes overlap.
#pragma once

#include <vector>

#include "stokesrods/common/types.h"

namespace stokesrods {

struct SegmentId {
  int rod = 0;
  int index = 0;  ///< segment i joins nodes i and i+1
  friend bool operator==(const SegmentId&, const SegmentId&) = default;
};

struct SegmentPair {
  SegmentId a;  ///< (a.rod, a.index) < (b.rod, b.index) lexicographically
  SegmentId b;
  friend bool operator==(const SegmentPair&, const SegmentPair&) = default;
};

/// All pairs of segments whose bounding boxes, each inflated by `margin` [m], overlap; segments of
/// the same rod with |i − j| ≤ self_exclusion are left out. Output sorted lexicographically.
/// Cost about linear in the number of segments for rods that are not all piled in one place.
std::vector<SegmentPair> FindCandidatePairs(const std::vector<const Matrix3X*>& rods,
                                            double margin, int self_exclusion);

/// The same by testing every pair: the reference for tests.
std::vector<SegmentPair> FindCandidatePairsBruteForce(const std::vector<const Matrix3X*>& rods,
                                                      double margin, int self_exclusion);

}  // namespace stokesrods
