// The coarse level of the two-level preconditioner (sim/coarse_level.h) on a 2 × 3 lattice of
// helices (tests/common/helix_lattice.h, 65 nodes each, 4 cm apart):
//   - W c against W assembled here the straightforward way (own blocks, node-to-node Stokeslets
//     near a chunk, the centroid's Stokeslet beyond) for random c;
//   - E = Zᵀ W (E is what the coarse solve inverts: c = E⁻¹ Zᵀ v must solve Zᵀ W c = Zᵀ v, to
//     the backward error of its single-precision LU);
//   - the centroid approximation against the node-to-node W it replaced (every node's point
//     Stokeslet): the error of a chunk's monopole at ≥ 2 chunk radii is its quadrupole, O((a/d)²).
#include "stokesrods/sim/coarse_level.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "common/helix_lattice.h"
#include "stokesrods/solver/dense_spectral.h"

namespace stokesrods {
namespace {

constexpr int kNodes = 65;
constexpr double kEps = 1.02e-3, kScale = 0.37;

Mat3 Stokeslet(const Vec3& r, double eps) {
  const double big_r2 = r.squaredNorm() + eps * eps, big_r = std::sqrt(big_r2);
  return (1.0 / big_r + eps * eps / (big_r2 * big_r)) * Mat3::Identity() +
         r * r.transpose() / (big_r2 * big_r);
}

struct Lattice {
  std::vector<Matrix3X> x;
  std::vector<MatX> blocks;
  std::vector<CoarseRod> rods;
};

Lattice MakeLattice() {
  const Matrix3X all = testing::HelixLattice(2, 3).targets;
  Lattice l;
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  const int num_rods = static_cast<int>(all.cols()) / kNodes;
  for (int r = 0; r < num_rods; ++r) {
    l.x.push_back(all.middleCols(r * kNodes, kNodes));
    MatX d = MatX::NullaryExpr(3 * kNodes, 3 * kNodes, [&]() { return normal(rng); });
    l.blocks.push_back(d + 50.0 * MatX::Identity(3 * kNodes, 3 * kNodes));
  }
  for (int r = 0; r < num_rods; ++r) l.rods.push_back({.x = &l.x[static_cast<size_t>(r)], .eps = kEps, .node_offset = r * kNodes});
  return l;
}

// The chunks of rod r as CoarseLevel makes them: [first + a n / K, first + (a + 1) n / K).
int ChunkBegin(int r, int a) { return r * kNodes + a * kNodes / CoarseLevel::kChunksPerRod; }

// W (3M × 3 chunks) column by column; node_to_node: every node's Stokeslet between rods (the W
// of before); otherwise the definition of coarse_level.h.
MatX ReferenceW(const Lattice& l, bool node_to_node) {
  const int rods = static_cast<int>(l.x.size()), k = CoarseLevel::kChunksPerRod, m = rods * kNodes;
  MatX w = MatX::Zero(3 * m, 3 * rods * k);
  for (int rb = 0; rb < rods; ++rb)
    for (int a = 0; a < k; ++a) {
      const int b = rb * k + a, begin = ChunkBegin(rb, a), end = a + 1 < k ? ChunkBegin(rb, a + 1) : (rb + 1) * kNodes;
      Matrix3X chunk(3, end - begin);
      for (int j = begin; j < end; ++j) chunk.col(j - begin) = l.x[static_cast<size_t>(rb)].col(j - rb * kNodes);
      const Vec3 centroid = chunk.rowwise().mean();
      double radius = 0.0;
      for (int j = 0; j < chunk.cols(); ++j) radius = std::max(radius, (chunk.col(j) - centroid).norm());
      for (int i = 0; i < m; ++i) {
        const int ri = i / kNodes;
        const Vec3 p = l.x[static_cast<size_t>(ri)].col(i % kNodes);
        Mat3 block = Mat3::Zero();
        if (ri == rb) {
          for (int j = begin; j < end; ++j)
            block += l.blocks[static_cast<size_t>(ri)].block<3, 3>(3 * (i % kNodes), 3 * (j - rb * kNodes));
        } else if (node_to_node || (p - centroid).norm() < 2.0 * radius) {
          for (int j = 0; j < chunk.cols(); ++j) block += kScale * Stokeslet(p - chunk.col(j), kEps);
        } else {
          block = kScale * static_cast<double>(chunk.cols()) * Stokeslet(p - centroid, kEps);
        }
        w.block<3, 3>(3 * i, 3 * b) = block;
      }
    }
  return w;
}

MatX ZTranspose(int rods, const MatX& w) {  // rows summed over each chunk
  const int k = CoarseLevel::kChunksPerRod;
  MatX z = MatX::Zero(3 * rods * k, w.cols());
  for (int r = 0; r < rods; ++r)
    for (int a = 0; a < k; ++a) {
      const int end = a + 1 < k ? ChunkBegin(r, a + 1) : (r + 1) * kNodes;
      for (int i = ChunkBegin(r, a); i < end; ++i) z.middleRows<3>(3 * (r * k + a)) += w.middleRows<3>(3 * i);
    }
  return z;
}

TEST(CoarseLevel, ProductMatchesTheAssembledW) {
  const Lattice l = MakeLattice();
  CoarseLevel coarse;
  ASSERT_TRUE(coarse.Build(l.rods, l.blocks, kScale));
  ASSERT_EQ(coarse.num_chunks(), 6 * CoarseLevel::kChunksPerRod);
  const MatX w = ReferenceW(l, false);
  std::mt19937 rng(3);
  std::normal_distribution<double> normal;
  for (int trial = 0; trial < 3; ++trial) {
    const VecX c = VecX::NullaryExpr(w.cols(), [&]() { return normal(rng); });
    VecX wc;
    coarse.ApplyW(c, &wc);
    // Between rods in single precision (the Stokeslet sum at tolerance 1e-3): float rounding.
    EXPECT_LT((wc - w * c).norm(), 1e-5 * (w * c).norm());
  }
}

TEST(CoarseLevel, SolveInvertsZTransposeW) {
  const Lattice l = MakeLattice();
  CoarseLevel coarse;
  ASSERT_TRUE(coarse.Build(l.rods, l.blocks, kScale));
  const MatX ztw = ZTranspose(6, ReferenceW(l, false));
  std::mt19937 rng(5);
  std::normal_distribution<double> normal;
  const VecX v = VecX::NullaryExpr(ReferenceW(l, false).rows(), [&]() { return normal(rng); });
  const VecX c = coarse.Solve(v);
  const VecX ztv = ZTranspose(6, v);
  // E's LU factors are kept in half precision (DenseLu kHalf, where the CPU allows it, else in
  // single): rounding them perturbs E by at most u |L||U| entrywise, u = 2⁻¹¹ (4.9e-4), which
  // partial pivoting keeps near u ‖E‖ (the factorization's own single-precision error is 500×
  // smaller). Residual within 2 u ‖E‖₂ ‖c‖ (measured 0.13 u ‖E‖₂ ‖c‖, which E's conditioning
  // makes 1.1 % of ‖Zᵀv‖; below 7e-4 of it with single-precision factors, the bound of before);
  // an E inconsistent with W would miss by O(‖Zᵀv‖).
  MatX u_svd, v_svd;
  VecX sigma;
  ASSERT_TRUE(ThinSvd(ztw, &u_svd, &sigma, &v_svd));
  const double norm_e = sigma(0);
  const double residual = (ztw * c - ztv).norm();
  std::printf("  coarse solve: residual %.2e of ‖E‖‖c‖, %.2e of ‖Zᵀv‖\n",
              residual / (norm_e * c.norm()), residual / ztv.norm());
  EXPECT_LT(residual, 2.0 * 4.9e-4 * norm_e * c.norm());
  EXPECT_LT(residual, 0.05 * ztv.norm());
  VecX y = VecX::Zero(v.size());
  coarse.AddZ(c, &y);  // Z c: each node takes its chunk's c
  EXPECT_EQ(y.segment<3>(3 * (kNodes + 1)), c.segment<3>(3 * CoarseLevel::kChunksPerRod));
}

TEST(CoarseLevel, CentroidsApproximateTheNodeToNodeCoupling) {
  const Lattice l = MakeLattice();
  const MatX mine = ReferenceW(l, false), node_to_node = ReferenceW(l, true);
  // Between rods, block by block: beyond 2 chunk radii the monopole's error is the quadrupole's,
  // ≲ (a/d)² ≤ 1/4 of the block (measured here: see the printout).
  double worst = 0.0;
  for (Eigen::Index i = 0; i < mine.rows() / 3; ++i)
    for (Eigen::Index b = 0; b < mine.cols() / 3; ++b) {
      if (i / kNodes == b / CoarseLevel::kChunksPerRod) continue;
      const Mat3 ref = node_to_node.block<3, 3>(3 * i, 3 * b);
      worst = std::max(worst, (mine.block<3, 3>(3 * i, 3 * b) - ref).norm() / ref.norm());
    }
  std::printf("worst relative error of a between-rod block: %.3f\n", worst);
  EXPECT_LT(worst, 0.25);
}

}  // namespace
}  // namespace stokesrods
