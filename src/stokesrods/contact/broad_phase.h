// Broad phase: candidate segment pairs whose axis-aligned bounding boxes overlap.
#pragma once

#include <cstdint>
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
std::vector<SegmentPair> FindCandidatePairs(const std::vector<const Matrix3X*>& rods, double margin,
                                            int self_exclusion);

/// Work counters of one FindCandidatePairs call (for tests of the scaling, not for physics).
struct BroadPhaseStats {
  std::int64_t segments = 0;      ///< segments with finite coordinates entered in the grid
  std::int64_t cell_entries = 0;  ///< (cell, segment) entries, ≤ 8 per segment up to round-off
  std::int64_t cell_pairs = 0;    ///< pairs of entries sharing a cell (the inner-loop visits)
  std::int64_t box_tests = 0;     ///< box–box overlap tests performed (brute force: ~n²/2)
};

/// As above, and fills `stats` when it is not null. Uniform grid whose cell edge is the largest
/// inflated box extent; cost O(n log n + k) for n segments and k pairs sharing a cell.
/// Preconditions (asserted): margin finite and ≥ 0, self_exclusion ≥ 0. Segments with a non-finite
/// coordinate pair with nothing.
std::vector<SegmentPair> FindCandidatePairs(const std::vector<const Matrix3X*>& rods, double margin,
                                            int self_exclusion, BroadPhaseStats* stats);

/// The same by testing every pair: the reference for tests.
std::vector<SegmentPair> FindCandidatePairsBruteForce(const std::vector<const Matrix3X*>& rods,
                                                      double margin, int self_exclusion);

}  // namespace stokesrods
