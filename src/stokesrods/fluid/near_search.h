// The near-pair search of the matrix-free RSS mobility (mobility_operator.cc): the segments whose
// closed-form RSS a target needs instead of the far sum's rule, those with
//     |p − q|² + ε² < δ²|v|²     (q the segment's point closest to p, v = x_b − x_a).
// Segments are grouped in boxes: per rod and per chunk of kChunkSegments consecutive segments of a
// rod, each box with the largest reach δ|v| of its segments. A block of targets close together (a
// rod's nodes) finds the chunks near its bounding box once (ChunksNear); each of its targets then
// tests only those chunks' segments, vectorized (SegmentsNear). Without the boxes every target
// tests every segment: the reference the tests compare with.
#pragma once

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

  int num_segments() const { return static_cast<int>(ax_.size()); }

 private:
  // Per segment (structure of arrays): x_a, v = x_b − x_a, 1/|v|², ε², δ²|v|².
  std::vector<double> ax_, ay_, az_, vx_, vy_, vz_, inv_v2_, e2_, reach2_;
  std::vector<int> chunk_first_segment_;  ///< per chunk, and back() = segments
  std::vector<int> rod_first_chunk_;      ///< per rod, and back() = chunks
  std::vector<Eigen::AlignedBox3d> boxes_;  ///< rods first (index r), then chunks (rods + c)
  std::vector<double> box_reach_;
};

}  // namespace stokesrods
