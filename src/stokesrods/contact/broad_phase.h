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

/// The broad phase kept across calls for rods that move little between them (a Verlet list). The
/// pairs are found by FindCandidatePairs with the margin grown by a skin s/2 per box, and found
/// again only once a node has moved by more than s/2 in some coordinate since (or the rods'
/// sizes, the margin or the exclusion changed). A segment's box then still lies inside its box
/// as found, grown by s/2: two boxes that overlap now at `margin` overlapped then at margin + s/2.
/// So Pairs() is a superset of FindCandidatePairs(rods, margin, self_exclusion), sorted the same
/// way, and a narrow phase that tests each pair on its own (DetectContacts) finds the same
/// contacts from either. The skin is the margin itself (the extra pairs are those within a
/// contact distance of touching): Fig. 1's flagella move 16 µm per step at h = 1 ms, a list then
/// serves ~30 steps. Where a list serves one call only (0.6 mm per step at h = 40 ms), the next
/// searches go without a skin (see Pairs).
class CandidatePairList {
 public:
  /// The pairs for the rods where they are now (see the class comment).
  const std::vector<SegmentPair>& Pairs(const std::vector<const Matrix3X*>& rods, double margin,
                                        int self_exclusion);
  /// Times the pairs were found (FindCandidatePairs called), for tests and benchmarks.
  long searches() const { return searches_; }

 private:
  /// Searches without a skin after a list with one served a single call.
  static constexpr int kPlainSearches = 8;
  std::vector<Matrix3X> found_at_;  ///< the rods' nodes when the pairs were found
  double skin_ = 0.0;               ///< of the pairs held: s, or 0 for FindCandidatePairs' own
  int calls_ = 0;                   ///< calls the pairs held have served
  int plain_searches_left_ = 0;
  double margin_ = -1.0;
  int self_exclusion_ = -1;
  std::vector<SegmentPair> pairs_;
  long searches_ = 0;
};

/// The same by testing every pair: the reference for tests.
std::vector<SegmentPair> FindCandidatePairsBruteForce(const std::vector<const Matrix3X*>& rods,
                                                      double margin, int self_exclusion);

}  // namespace stokesrods
