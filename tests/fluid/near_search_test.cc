// The near-pair search (fluid/near_search.h) against its definition tested pair by pair: for every
// target, the segments with |p − q|² + ε² < δ²|v|² (q the closest point), on rods long enough to
// have several chunks of kChunkSegments segments, with targets on the rods, around them and far.
#include "stokesrods/fluid/near_search.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "stokesrods/rod/geometry.h"

namespace stokesrods {
namespace {

// The reference: every segment tested against p.
std::vector<int> NearByDefinition(const Matrix3X& nodes, const std::vector<int>& first_node,
                                  const VecX& eps, double delta, const Vec3& p) {
  std::vector<int> near;
  for (std::size_t s = 0; s < first_node.size(); ++s) {
    const Vec3 a = nodes.col(first_node[s]), v = nodes.col(first_node[s] + 1) - a;
    const double t = std::clamp((p - a).dot(v) / v.squaredNorm(), 0.0, 1.0);
    const double eps2 = eps(static_cast<Eigen::Index>(s)) * eps(static_cast<Eigen::Index>(s));
    if ((p - a - t * v).squaredNorm() + eps2 < delta * delta * v.squaredNorm())
      near.push_back(static_cast<int>(s));
  }
  return near;
}

TEST(NearSegmentSearch, FindsExactlyTheSegmentsNearEachTargetByTheirDefinition) {
  // Three helices of 40, 65 and 7 nodes (3, 5 and 1 chunks), 3R apart, with different ε.
  const std::vector<int> sizes = {40, 65, 7};
  std::vector<Matrix3X> rods;
  for (std::size_t r = 0; r < sizes.size(); ++r) {
    HelixGeometry helix;
    helix.nodes = sizes[r];
    helix.base = Vec3(0.03 * static_cast<double>(r), 0.0, 0.0);
    rods.push_back(HelixNodes(helix));
  }
  int m = 0;
  for (const Matrix3X& x : rods) m += static_cast<int>(x.cols());
  Matrix3X nodes(3, m);
  std::vector<int> first_node, rod_first_segment = {0};
  std::vector<double> eps_list;
  int offset = 0;
  for (std::size_t r = 0; r < rods.size(); ++r) {
    nodes.middleCols(offset, rods[r].cols()) = rods[r];
    for (int j = 0; j + 1 < rods[r].cols(); ++j) {
      first_node.push_back(offset + j);
      eps_list.push_back(1e-4 * static_cast<double>(r + 1));
    }
    rod_first_segment.push_back(static_cast<int>(first_node.size()));
    offset += static_cast<int>(rods[r].cols());
  }
  const VecX eps = Eigen::Map<const VecX>(eps_list.data(), static_cast<Eigen::Index>(eps_list.size()));
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.004, 0.004), far(-0.2, 0.2);
  for (const double delta : {2.0, 6.0}) {
    NearSegmentSearch search;
    search.Build(nodes, first_node, eps, rod_first_segment, delta);
    ASSERT_EQ(search.num_segments(), static_cast<int>(first_node.size()));
    int total_near = 0, targets_tested = 0;
    std::vector<int> chunks, near;
    std::vector<unsigned char> flags;
    // Blocks of 16 targets: the nodes moved a little (on and around the rods), then far points.
    for (int begin = 0; begin < m + 64; begin += 16) {
      Matrix3X targets(3, 16);
      for (int k = 0; k < 16; ++k) {
        const int i = begin + k;
        targets.col(k) = i < m ? Vec3(nodes.col(i) + Vec3(jitter(rng), jitter(rng), jitter(rng)))
                               : Vec3(far(rng), far(rng), far(rng));
      }
      Eigen::AlignedBox3d box;
      for (int k = 0; k < 16; ++k) box.extend(Vec3(targets.col(k)));
      search.ChunksNear(box, &chunks);
      for (int k = 0; k < 16; ++k) {
        search.SegmentsNear(targets.col(k), chunks, &flags, &near);
        const std::vector<int> expected =
            NearByDefinition(nodes, first_node, eps, delta, targets.col(k));
        EXPECT_EQ(near, expected) << "delta " << delta << ", target " << begin + k;
        total_near += static_cast<int>(expected.size());
        ++targets_tested;
      }
    }
    // The test must see near pairs (and not only near pairs) to mean anything.
    EXPECT_GT(total_near, targets_tested);
    EXPECT_LT(total_near, targets_tested * static_cast<int>(first_node.size()) / 2);
  }
}

}  // namespace
}  // namespace stokesrods
