// The FMM tree's order of the points (fluid/fmm_tree.h) against its definition: by the Morton
// code of each point's cell at the finest level (2^20 cells per side of the root cube), ties in
// input order, as one sort of (code, index) pairs gives it. BuildFmmTree sorts by boxes first and
// then within each box (fmm_tree.cc, SortByCode); this test recomputes the codes bit by bit.
#include "stokesrods/fluid/fmm_tree.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <utility>
#include <vector>

#include "stokesrods/fluid/fmm_cost.h"

namespace stokesrods {
namespace {

constexpr int kFinestLevel = 20;

// The code of p's cell: bit b of the cell's x, y, z at bits 3b + 2, 3b + 1, 3b.
std::uint64_t ReferenceCode(const Vec3& p, const Vec3& corner, double width) {
  const double cells = static_cast<double>(1 << kFinestLevel);
  std::uint64_t code = 0;
  for (int d = 0; d < 3; ++d) {
    const auto cell = static_cast<std::uint64_t>(std::clamp<std::int64_t>(
        static_cast<std::int64_t>((p[d] - corner[d]) / width * cells), 0, (1 << kFinestLevel) - 1));
    for (int b = 0; b < kFinestLevel; ++b) code |= ((cell >> b) & 1u) << (3 * b + 2 - d);
  }
  return code;
}

std::vector<int> ReferenceOrder(const Matrix3X& p, const FmmTree& tree) {
  std::vector<std::pair<std::uint64_t, int>> keyed;
  for (Eigen::Index k = 0; k < p.cols(); ++k)
    keyed.emplace_back(ReferenceCode(p.col(k), tree.corner, tree.width), static_cast<int>(k));
  std::sort(keyed.begin(), keyed.end());
  std::vector<int> order;
  for (const auto& entry : keyed) order.push_back(entry.second);
  return order;
}

// Clusters of very different density, points repeated (ties), a flat slab: the boxes of the
// first sort hold from none to thousands of points.
Matrix3X Cloud(int n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> normal;
  Matrix3X p(3, n);
  for (int k = 0; k < n; ++k) {
    if (k % 3 == 0)
      p.col(k) = Vec3(unit(rng), unit(rng), 0.1 * unit(rng));  // a slab
    else if (k % 3 == 1)
      p.col(k) = Vec3(0.3, 0.6, 0.05) + 1e-4 * Vec3(normal(rng), normal(rng), normal(rng));
    else
      p.col(k) = p.col(k - 2);  // a repeated point
  }
  return p;
}

TEST(FmmTreeTest, PointsAreInMortonOrderWithTiesInInputOrder) {
  StokesletSumOptions options;
  options.tolerance = 1e-4;
  const FmmCost cost = EstimatedFmmCost(OrderFor(options), options);
  for (const int n : {10, 65, 700, 9000}) {
    const Matrix3X sources = Cloud(n, 1u + static_cast<std::uint32_t>(n));
    const Matrix3X targets = Cloud(n / 2 + 1, 2u + static_cast<std::uint32_t>(n));
    const FmmTree tree = BuildFmmTree(sources, targets, 1e-6, cost, /*force_tree=*/true);
    ASSERT_GT(tree.depth, 0) << n;
    EXPECT_EQ(tree.source_order, ReferenceOrder(sources, tree)) << n << " sources";
    EXPECT_EQ(tree.target_order, ReferenceOrder(targets, tree)) << n << " targets";
  }
}

}  // namespace
}  // namespace stokesrods
