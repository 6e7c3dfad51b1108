// Broad phase on a uniform grid.
//
// Each segment's box, inflated by `margin`, is entered in every grid cell it touches. The cell edge
// is the largest inflated box extent over all segments, so a box touches at most 2 cells per axis
// (≤ 8 cells). Two boxes can overlap only if they share a cell, and a pair is tested only in the
// cell that holds the lower corner of the intersection of the two boxes, cell index
// max(lo_a, lo_b) per axis, which both boxes touch: each pair is tested once, no hash set needed.
// The (cell, segment) entries are sorted by cell instead of hashed, which is deterministic and
// allocation-light; the cost is O(n log n + k) for n segments and k pairs sharing a cell.
//
// The cell size follows the longest segment: a soup with one very long segment among many short
// ones degrades towards the brute force. Rods of the DER discretization have comparable edges.
#include "stokesrods/contact/broad_phase.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#include "stokesrods/common/assert.h"

namespace stokesrods {
namespace {

struct Box {
  SegmentId id;
  Vec3 lo;
  Vec3 hi;
};

/// Inflated boxes of all segments; segments with a non-finite coordinate are left out (they would
/// overlap nothing in the brute force either, NaN comparisons being false).
std::vector<Box> CalcBoxes(const std::vector<const Matrix3X*>& rods, double margin) {
  std::vector<Box> boxes;
  for (std::size_t r = 0; r < rods.size(); ++r) {
    SR_ASSERT(rods[r] != nullptr, "null rod");
    const Matrix3X& x = *rods[r];
    for (Eigen::Index i = 0; i + 1 < x.cols(); ++i) {
      if (!x.col(i).allFinite() || !x.col(i + 1).allFinite()) continue;
      const Vec3 lo = x.col(i).cwiseMin(x.col(i + 1)).array() - margin;
      const Vec3 hi = x.col(i).cwiseMax(x.col(i + 1)).array() + margin;
      boxes.push_back({{static_cast<int>(r), static_cast<int>(i)}, lo, hi});
    }
  }
  return boxes;
}

bool Overlap(const Box& a, const Box& b) {
  return (a.lo.array() <= b.hi.array()).all() && (b.lo.array() <= a.hi.array()).all();
}

bool Excluded(const SegmentId& a, const SegmentId& b, int self_exclusion) {
  return a.rod == b.rod && std::abs(a.index - b.index) <= self_exclusion;
}

bool Less(const SegmentId& a, const SegmentId& b) {
  return a.rod != b.rod ? a.rod < b.rod : a.index < b.index;
}

SegmentPair MakePair(const SegmentId& a, const SegmentId& b) {
  return Less(a, b) ? SegmentPair{a, b} : SegmentPair{b, a};
}

void SortPairs(std::vector<SegmentPair>* pairs) {
  std::sort(pairs->begin(), pairs->end(), [](const SegmentPair& p, const SegmentPair& q) {
    if (!(p.a == q.a)) return Less(p.a, q.a);
    return Less(p.b, q.b);
  });
  pairs->erase(std::unique(pairs->begin(), pairs->end()), pairs->end());
}

void CheckArguments(double margin, int self_exclusion) {
  SR_ASSERT(margin >= 0.0 && std::isfinite(margin), "margin must be finite and >= 0");
  SR_ASSERT(self_exclusion >= 0, "self_exclusion must be >= 0 (a segment never pairs itself)");
}

using CellIndex = std::array<std::int64_t, 3>;

struct CellEntry {
  std::uint64_t cell = 0;  ///< the cell's key (Grid::Key)
  int box = 0;
};

struct Grid {
  std::array<std::uint64_t, 3> stride{};  ///< of the key per axis
  std::vector<CellIndex> lower;    ///< per box: cell of its lower corner
  std::vector<CellEntry> entries;  ///< every (cell, box) a box touches, sorted by cell

  /// One integer per cell (row-major over the grid's cells): a single comparison in the sort.
  std::uint64_t Key(const CellIndex& c) const {
    return static_cast<std::uint64_t>(c[0]) * stride[0] + static_cast<std::uint64_t>(c[1]) * stride[1] +
           static_cast<std::uint64_t>(c[2]);
  }
};

/// Enters the (≥ 1) boxes in a grid whose cell edge is the largest box extent.
Grid BuildGrid(const std::vector<Box>& boxes) {
  Vec3 origin = boxes.front().lo;
  Vec3 top = boxes.front().hi;
  double cell = 0.0;
  for (const Box& b : boxes) {
    origin = origin.cwiseMin(b.lo);
    top = top.cwiseMax(b.hi);
    cell = std::max(cell, (b.hi - b.lo).maxCoeff());
  }
  // At most 2^20 cells per axis, so that a cell's key fits in 64 bits (a larger cell is still a
  // valid grid, only less selective), and the cell size > 0 when everything is one point.
  constexpr double kMaxCellsPerAxis = 1 << 20;
  cell = std::max({cell, (top - origin).maxCoeff() / kMaxCellsPerAxis,
                   std::numeric_limits<double>::min()});
  const auto index_of = [&](const Vec3& x) {
    CellIndex c;
    for (int k = 0; k < 3; ++k) {
      c[k] = static_cast<std::int64_t>(std::floor((x[k] - origin[k]) / cell));
    }
    return c;
  };

  Grid grid;
  const CellIndex last = index_of(top);
  grid.stride = {static_cast<std::uint64_t>(last[1] + 1) * static_cast<std::uint64_t>(last[2] + 1),
                 static_cast<std::uint64_t>(last[2] + 1), 1};
  grid.lower.resize(boxes.size());
  std::vector<CellEntry>& entries = grid.entries;
  entries.reserve(8 * boxes.size());
  for (std::size_t n = 0; n < boxes.size(); ++n) {
    const CellIndex lo = index_of(boxes[n].lo);
    const CellIndex hi = index_of(boxes[n].hi);
    grid.lower[n] = lo;
    for (std::int64_t i = lo[0]; i <= hi[0]; ++i) {
      for (std::int64_t j = lo[1]; j <= hi[1]; ++j) {
        for (std::int64_t k = lo[2]; k <= hi[2]; ++k) {
          entries.push_back({grid.Key({i, j, k}), static_cast<int>(n)});
        }
      }
    }
  }
  std::sort(entries.begin(), entries.end(), [](const CellEntry& p, const CellEntry& q) {
    return p.cell != q.cell ? p.cell < q.cell : p.box < q.box;
  });
  return grid;
}

}  // namespace

std::vector<SegmentPair> FindCandidatePairs(const std::vector<const Matrix3X*>& rods, double margin,
                                            int self_exclusion) {
  return FindCandidatePairs(rods, margin, self_exclusion, nullptr);
}

std::vector<SegmentPair> FindCandidatePairs(const std::vector<const Matrix3X*>& rods, double margin,
                                            int self_exclusion, BroadPhaseStats* stats) {
  CheckArguments(margin, self_exclusion);
  const std::vector<Box> boxes = CalcBoxes(rods, margin);
  std::vector<SegmentPair> pairs;
  if (stats != nullptr) *stats = BroadPhaseStats{};
  if (boxes.size() < 2) return pairs;

  const Grid grid = BuildGrid(boxes);
  const std::vector<CellIndex>& lower = grid.lower;
  const std::vector<CellEntry>& entries = grid.entries;

  std::int64_t visited = 0;
  std::int64_t tested = 0;
  for (std::size_t begin = 0; begin < entries.size();) {
    std::size_t end = begin + 1;
    while (end < entries.size() && entries[end].cell == entries[begin].cell) ++end;
    const std::uint64_t here = entries[begin].cell;
    for (std::size_t u = begin; u < end; ++u) {
      const int m = entries[u].box;
      for (std::size_t v = u + 1; v < end; ++v) {
        const int n = entries[v].box;
        ++visited;
        CellIndex owner;
        for (int k = 0; k < 3; ++k) owner[k] = std::max(lower[m][k], lower[n][k]);
        if (grid.Key(owner) != here) continue;  // this pair is tested in another cell
        const Box& a = boxes[m];
        const Box& b = boxes[n];
        if (Excluded(a.id, b.id, self_exclusion)) continue;
        ++tested;
        if (Overlap(a, b)) pairs.push_back(MakePair(a.id, b.id));
      }
    }
    begin = end;
  }
  if (stats != nullptr) {
    stats->segments = static_cast<std::int64_t>(boxes.size());
    stats->cell_entries = static_cast<std::int64_t>(entries.size());
    stats->cell_pairs = visited;
    stats->box_tests = tested;
  }
  SortPairs(&pairs);
  return pairs;
}

std::vector<SegmentPair> FindCandidatePairsBruteForce(const std::vector<const Matrix3X*>& rods,
                                                      double margin, int self_exclusion) {
  CheckArguments(margin, self_exclusion);
  const std::vector<Box> boxes = CalcBoxes(rods, margin);
  std::vector<SegmentPair> pairs;
  for (std::size_t m = 0; m < boxes.size(); ++m) {
    for (std::size_t n = m + 1; n < boxes.size(); ++n) {
      if (Excluded(boxes[m].id, boxes[n].id, self_exclusion)) continue;
      if (Overlap(boxes[m], boxes[n])) pairs.push_back(MakePair(boxes[m].id, boxes[n].id));
    }
  }
  SortPairs(&pairs);
  return pairs;
}

const std::vector<SegmentPair>& CandidatePairList::Pairs(const std::vector<const Matrix3X*>& rods,
                                                        double margin, int self_exclusion) {
  CheckArguments(margin, self_exclusion);
  bool valid = margin == margin_ && self_exclusion == self_exclusion_ &&
               found_at_.size() == rods.size();
  for (std::size_t r = 0; r < rods.size() && valid; ++r) {
    SR_ASSERT(rods[r] != nullptr, "null rod");
    const Matrix3X& now = *rods[r];
    // Not valid on a non-finite coordinate either (the comparison is false).
    valid = now.cols() == found_at_[r].cols() &&
            (now.cols() == 0 ||
             (now - found_at_[r]).cwiseAbs().maxCoeff<Eigen::PropagateNaN>() <= 0.5 * skin_);
  }
  if (valid) {
    ++calls_;
    return pairs_;
  }
  // A list with a skin that served only the call that found it (the rods move by more than half
  // the skin per call: large time steps) cost a search with the larger margin for nothing: the
  // next kPlainSearches are made without one (FindCandidatePairs' pairs exactly), then the skin is
  // tried again.
  if (skin_ > 0.0 && calls_ <= 1) plain_searches_left_ = kPlainSearches;
  skin_ = plain_searches_left_ > 0 ? 0.0 : margin;
  plain_searches_left_ = std::max(plain_searches_left_ - 1, 0);
  pairs_ = FindCandidatePairs(rods, margin + 0.5 * skin_, self_exclusion);
  ++searches_;
  calls_ = 1;
  margin_ = margin;
  self_exclusion_ = self_exclusion;
  found_at_.resize(rods.size());
  for (std::size_t r = 0; r < rods.size(); ++r) found_at_[r] = *rods[r];
  return pairs_;
}

}  // namespace stokesrods
