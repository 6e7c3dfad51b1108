// The octree of the FMM Stokeslet sum (fmm_sum.cc): a cube around all points, cut uniformly down
// to a leaf level (boxes without points are not stored), with the interaction lists of each level.
// Points are sorted by Morton code, so the points of every box, at every level, are contiguous.
// The leaf level is chosen by a cost model (FmmCost) between a minimum leaf width and the level
// where the cost stops falling.
#pragma once

#include <cstdint>
#include <vector>

#include "stokesrods/common/types.h"

namespace stokesrods {

struct FmmBox {
  std::uint64_t code = 0;           ///< Morton code at the box's level (3 bits per level)
  int src_begin = 0, src_end = 0;   ///< sources [begin, end) in tree order
  int tgt_begin = 0, tgt_end = 0;   ///< targets [begin, end) in tree order
  int child_begin = 0, child_end = 0;  ///< children among the next level's boxes
  int parent = -1;                  ///< among the previous level's boxes
  bool has_sources() const { return src_end > src_begin; }
  bool has_targets() const { return tgt_end > tgt_begin; }
};

/// An interaction list in compressed-row form: entries [start[b], start[b + 1]) belong to box b.
struct FmmList {
  std::vector<int> start = {0};
  std::vector<int> box;     ///< the other box (same level)
  std::vector<int> offset;  ///< V lists: M2lIndex of (source box − target box)
};

/// Relative costs of the pieces of one Apply, in units of one kernel evaluation (one pair of the
/// direct sum).
struct FmmCost {
  double per_point = 0.0;  ///< S2M and L2T: a source or target against a surface
  double per_box = 0.0;    ///< the dense translations of one box (M2M, L2L, check → equivalent)
  double per_m2l = 0.0;    ///< one M2L (a V-list pair of boxes)
  /// A whole Apply over the sum of the pieces above and its near pairs (scales them all alike:
  /// it does not change the depth, only whether the tree pays).
  double apply_scale = 1.0;
  double per_point_build = 0.0;  ///< the Build's cost per point, per Apply it serves
};

struct FmmTree {
  Vec3 corner = Vec3::Zero();  ///< lowest corner of the root cube [m]
  double width = 0.0;          ///< root cube's side [m]
  int depth = 0;               ///< leaf level (0: no tree, sum directly)
  std::vector<int> source_order, target_order;  ///< tree order → input index
  std::vector<std::vector<FmmBox>> levels;      ///< levels[0 … depth]
  std::vector<FmmList> v_lists;                 ///< per level (empty below level 2)
  FmmList near;                                 ///< leaf level: neighbours with sources (incl. self)
  std::int64_t near_pairs = 0, m2l_count = 0;
  double cost = 0.0;           ///< FmmCost estimate of one Apply (pairs)
  double BoxWidth(int level) const { return width / static_cast<double>(1 << level); }
  Vec3 BoxCentre(int level, std::uint64_t code) const;
};

/// The tree over sources and targets with leaves no narrower than min_leaf_width [m], of the
/// depth of least estimated cost; depth 0 (no tree) when the points span nothing or no depth
/// ≥ 2 fits. When `force_tree` is false, also depth 0 when the direct sum (one unit per pair) is
/// estimated cheaper than the tree's Apply plus its share of the Build.
FmmTree BuildFmmTree(const Matrix3X& sources, const Matrix3X& targets, double min_leaf_width,
                     const FmmCost& cost, bool force_tree);

}  // namespace stokesrods
