// The near-pair search of the matrix-free RSS mobility (mobility_operator.cc): the segments whose
// closed-form RSS a target needs instead of the far sum's rule, those with
//     |p − q|² + ε² < δ²|v|²     (q the segment's point closest to p, v = x_b − x_a).
// Segments are grouped in boxes: per rod and per chunk of kChunkSegments consecutive segments of a
// rod, each box with the largest reach δ|v| of its segments. A block of targets close together (a
// rod's nodes) finds the chunks near its bounding box once (ChunksNear); each of its targets then
// tests only those chunks' segments, vectorized (SegmentsNear). Without the boxes every target
// tests every segment: the reference the tests compare with.
#pragma once

#include <algorithm>
#include <vector>

#include <Eigen/Geometry>

#include "stokesrods/common/types.h"

namespace stokesrods {

class NearSegmentSearch {
 public:
  static constexpr int kChunkSegments = 16;

  /// Segment s runs from nodes.col(first_node[s]) to the next column, with blob size eps[s]; rod
  /// r's segments are [rod_first_segment[r], rod_first_segment[r + 1]). delta: δ.
  void Build(const Matrix3X& nodes, const std::vector<int>& first_node, const VecX& eps,
             const std::vector<int>& rod_first_segment, double delta);

  /// The chunks whose box comes within its reach of `box`, in rod order.
  void ChunksNear(const Eigen::AlignedBox3d& box, std::vector<int>* chunks) const;

  /// The segments near p among those of `chunks` (from ChunksNear of a box holding p), as global
  /// indices in rod order. `flags` is scratch.
  void SegmentsNear(const Vec3& p, const std::vector<int>& chunks,
                    std::vector<unsigned char>* flags, std::vector<int>* near) const;

  /// The segments near each of `targets` (by blocks of kTargetBlock consecutive columns: a rod's
  /// nodes, close together, find the chunks near their block's box once), to
  /// `visit(t, near segments, scratch)`, in parallel; Scratch is default-constructed per thread.
  template <typename Scratch, typename Visit>
  void ForEachTarget(const Matrix3X& targets, const Visit& visit) const;

  /// The segments near p among `candidates` (ascending; a superset of the near ones), as
  /// SegmentsNear finds them. `flags` is scratch.
  void SegmentsNearAmong(const Vec3& p, const std::vector<int>& candidates,
                         std::vector<unsigned char>* flags, std::vector<int>* near) const;

  int num_segments() const { return static_cast<int>(ax_.size()); }
  static constexpr int kTargetBlock = 16;

 private:
  // Per segment (structure of arrays): x_a, v = x_b − x_a, 1/|v|², ε², δ²|v|².
  std::vector<double> ax_, ay_, az_, vx_, vy_, vz_, inv_v2_, e2_, reach2_;
  std::vector<int> chunk_first_segment_;  ///< per chunk, and back() = segments
  std::vector<int> rod_first_chunk_;      ///< per rod, and back() = chunks
  std::vector<Eigen::AlignedBox3d> boxes_;  ///< rods first (index r), then chunks (rods + c)
  std::vector<double> box_reach_;
};

template <typename Scratch, typename Visit>
void NearSegmentSearch::ForEachTarget(const Matrix3X& targets, const Visit& visit) const {
  const int m = static_cast<int>(targets.cols());
  // (a test per target and rod was O(targets × rods): 5 % of the step at 100 helices)
  const int num_blocks = (m + kTargetBlock - 1) / kTargetBlock;
#pragma omp parallel
  {
    std::vector<int> near, block_chunks;
    std::vector<unsigned char> flags;
    Scratch scratch;
#pragma omp for schedule(dynamic, 1)
    for (int tb = 0; tb < num_blocks; ++tb) {
      const int t_begin = tb * kTargetBlock, t_end = std::min(m, t_begin + kTargetBlock);
      Eigen::AlignedBox3d block_box;
      for (int t = t_begin; t < t_end; ++t) block_box.extend(Vec3(targets.col(t)));
      ChunksNear(block_box, &block_chunks);
      for (int t = t_begin; t < t_end; ++t) {
        SegmentsNear(targets.col(t), block_chunks, &flags, &near);
        visit(t, near, &scratch);
      }
    }
  }
}

/// The near segments of every node, kept across calls as a Verlet list: each node's candidates
/// are found once with the near radius grown to (1 + kSkin) δ, and later calls test only those
/// (SegmentsNearAmong: the same test as a new search, so the same lists) while
///     2Δ ≤ δ ((1 + kSkin) |v₀| − |v|)   for every segment,
/// Δ the largest distance a node has moved since the search, |v₀| and |v| a segment's length then
/// and now. Why that suffices: a pair that was no candidate had D₀ = √(d₀² + ε²) ≥ (1 + kSkin) δ
/// |v₀|; the distance from the target to the segment has shrunk by at most 2Δ (the target and the
/// segment's points each moved by at most Δ), so √(d² + ε²) ≥ D₀ − 2Δ ≥ δ |v|: it is not near.
/// (Rods that keep their lengths may move by kSkin δ |v| / 2 before a new search: 0.7 segment
/// lengths at δ = 5.8.) Where a list serves one call only (the rods move farther per step), the
/// next kPlainSearches calls search without the skin, then it is tried again (as
/// contact/broad_phase.h's CandidatePairList).
class NearSegmentList {
 public:
  static constexpr double kSkin = 0.25;
  static constexpr int kPlainSearches = 8;

  /// near[t]: the segments near node t (nodes.col(t)), as NearSegmentSearch finds them, for the
  /// segments and δ of NearSegmentSearch::Build.
  void Find(const Matrix3X& nodes, const std::vector<int>& first_node, const VecX& eps,
            const std::vector<int>& rod_first_segment, double delta,
            std::vector<std::vector<int>>* near);
  /// Finds that searched (with or without the skin) and that tested the kept candidates.
  long searches() const { return searches_; }
  long kept() const { return kept_; }

 private:
  bool Holds(const Matrix3X& nodes, const std::vector<int>& first_node, const VecX& eps,
             const std::vector<int>& rod_first_segment, double delta) const;
  // near from the kept candidates (a search at δ for their test's values, without its boxes'
  // use).
  void Filter(const Matrix3X& nodes, const std::vector<int>& first_node, const VecX& eps,
              const std::vector<int>& rod_first_segment, double delta,
              std::vector<std::vector<int>>* near);

  NearSegmentSearch search_;
  std::vector<std::vector<int>> candidates_;  ///< per node (empty: no list)
  Matrix3X searched_at_;                       ///< the nodes at the candidates' search
  std::vector<int> first_node_, rod_first_segment_;
  VecX eps_;
  double delta_ = 0.0;
  std::vector<double> searched_length_;        ///< |v₀| per segment
  int calls_ = 0;                              ///< Finds the kept list served
  int plain_searches_left_ = 0;
  long searches_ = 0, kept_ = 0;
};

}  // namespace stokesrods
