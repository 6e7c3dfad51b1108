// The coarse level of the two-level preconditioner (sim/coarse_level.h) on a 2 × 3 lattice of
// helices (tests/common/helix_lattice.h, 65 nodes each, moved to 2.4 cm apart so that some nodes
// lie near another rod's points), free or with two fixed leading nodes (a clamp), in both layouts
// (eight chunks of forces at their centroids, the fixed nodes one of them; four chunks of forces
// and turns, four points each):
//   - W c against W assembled here the straightforward way (own blocks times the modes, each
//     chunk's points' Stokeslets carrying their nodes' forces, the nodes' own near a point) for
//     random c, with the near corrections taking part;
//   - E = Zᵀ W (E is what the coarse solve inverts: c = E⁻¹ Zᵀ v must solve Zᵀ W c = Zᵀ v, to
//     the backward error of its half-precision LU), and Z c;
//   - the points' approximation against the node-to-node W (every node's point Stokeslet): the
//     error of a point's monopole at ≥ 2 radii is its quadrupole, O((a/d)²).
#include "stokesrods/sim/coarse_level.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>

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

// straight: the helices' axes instead (nodes on lines: a chunk cannot turn about its line);
// fixed: each rod's leading nodes held (CoarseRod::fixed_nodes).
Lattice MakeLattice(bool straight, int fixed) {
  Matrix3X all = testing::HelixLattice(2, 3).targets;
  if (straight)
    for (Eigen::Index i = 0; i < all.cols(); ++i)
      all.col(i).head<2>() = Vec3(0.04 * static_cast<double>(i / kNodes / 3), 0.04 * static_cast<double>(i / kNodes % 3), 0.0).head<2>();
  Lattice l;
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  const int num_rods = static_cast<int>(all.cols()) / kNodes;
  for (int r = 0; r < num_rods; ++r) {
    // Moved to 2.4 cm apart (a 4 mm gap between the helices): some nodes then lie near another
    // rod's points, so that W's near corrections are part of what the tests compare.
    const Vec3 shift(-0.4 * 0.04 * (r / 3), -0.4 * 0.04 * (r % 3), 0.0);
    l.x.push_back(all.middleCols(r * kNodes, kNodes).colwise() + shift);
    MatX d = MatX::NullaryExpr(3 * kNodes, 3 * kNodes, [&]() { return normal(rng); });
    l.blocks.push_back(d + 50.0 * MatX::Identity(3 * kNodes, 3 * kNodes));
  }
  for (int r = 0; r < num_rods; ++r)
    l.rods.push_back({.x = &l.x[static_cast<size_t>(r)], .eps = kEps, .node_offset = r * kNodes, .fixed_nodes = fixed});
  return l;
}

Vec3 Node(const Lattice& l, int i) { return l.x[static_cast<size_t>(i / kNodes)].col(i % kNodes); }

Vec3 Centroid(const Lattice& l, int begin, int end) {
  Vec3 c = Vec3::Zero();
  for (int j = begin; j < end; ++j) c += Node(l, j);
  return c / static_cast<double>(end - begin);
}

// The RMS distance of nodes [begin, end) from their centroid (1 for one node): a turn's unit.
double Radius(const Lattice& l, int begin, int end) {
  const Vec3 c = Centroid(l, begin, end);
  double sum = 0.0;
  for (int j = begin; j < end; ++j) sum += (Node(l, j) - c).squaredNorm();
  const double radius = std::sqrt(sum / static_cast<double>(end - begin));
  return radius > 0.0 ? radius : 1.0;
}

// The coarse space of one layout, written out as coarse_level.h defines it.
struct Space {
  CoarseLayout layout;
  int fixed = 0;  // the rods' fixed leading nodes
  int chunks() const { return layout.chunks_per_rod; }
  int modes() const { return layout.modes(); }
  // The chunks of rod r as CoarseLevel makes them: [first + a n / K, first + (a + 1) n / K), or
  // with a chunk of the f fixed nodes first, the other K − 1 over the n − f free ones, free chunk
  // j from first + f + round((n − f) (j / (K − 1))^g), g = kFreeChunkGrading (at 65 nodes no
  // chunk is left empty, so no edge is pushed apart: ShortClampedRodsKeepEveryChunk).
  int ChunkBegin(int r, int a) const {
    const int f = layout.fixed_chunk ? fixed : 0;
    if (f == 0) return r * kNodes + a * kNodes / chunks();
    if (a == 0) return r * kNodes;
    const double j = static_cast<double>(a - 1) / (chunks() - 1);
    return r * kNodes + f + static_cast<int>(std::lround((kNodes - f) * std::pow(j, CoarseLayout::kFreeChunkGrading)));
  }
  int ChunkEnd(int r, int a) const { return a + 1 < chunks() ? ChunkBegin(r, a + 1) : (r + 1) * kNodes; }
  // Z at d from the chunk's centroid in units of its radius: the nodal force F (+ Ω × d).
  MatX Modes(const Vec3& d) const {
    MatX z = MatX::Zero(3, modes());
    z.leftCols<3>() = Mat3::Identity();
    if (layout.turns)
      for (int k = 0; k < 3; ++k) z.col(3 + k) = Vec3::Unit(k).cross(d);
    return z;
  }
};

// W (3M × modes × chunks) column by column; node_to_node: every node's Stokeslet between rods;
// otherwise the definition of coarse_level.h (each point's Stokeslet at its centroid carrying its
// nodes' forces, its nodes' own near it). near_blocks: how many (node, point) pairs were near.
MatX ReferenceW(const Lattice& l, const Space& z, bool node_to_node, int* near_blocks = nullptr) {
  if (near_blocks) *near_blocks = 0;
  const int rods = static_cast<int>(l.x.size()), m = rods * kNodes, modes = z.modes();
  MatX w = MatX::Zero(3 * m, modes * rods * z.chunks());
  for (int rb = 0; rb < rods; ++rb)
    for (int a = 0; a < z.chunks(); ++a) {
      const int b = rb * z.chunks() + a, begin = z.ChunkBegin(rb, a), end = z.ChunkEnd(rb, a);
      const int points = std::min(z.layout.points_per_chunk, end - begin);  // as many as nodes at most
      const Vec3 centroid = Centroid(l, begin, end);
      const double rho = Radius(l, begin, end);
      for (int i = 0; i < m; ++i) {
        const int ri = i / kNodes;
        const Vec3 p = Node(l, i);
        MatX block = MatX::Zero(3, modes);
        if (ri == rb) {
          for (int j = begin; j < end; ++j)
            block += l.blocks[static_cast<size_t>(ri)].block<3, 3>(3 * (i % kNodes), 3 * (j - rb * kNodes)) *
                     z.Modes((Node(l, j) - centroid) / rho);
        } else if (node_to_node) {
          for (int j = begin; j < end; ++j)
            block += kScale * Stokeslet(p - Node(l, j), kEps) * z.Modes((Node(l, j) - centroid) / rho);
        } else {
          for (int q = 0; q < points; ++q) {
            const int p0 = begin + q * (end - begin) / points, p1 = begin + (q + 1) * (end - begin) / points;
            const Vec3 y = Centroid(l, p0, p1);
            double radius = 0.0;
            for (int j = p0; j < p1; ++j) radius = std::max(radius, (Node(l, j) - y).norm());
            if ((p - y).norm() < 2.0 * radius) {
              if (near_blocks) ++*near_blocks;
              for (int j = p0; j < p1; ++j)
                block += kScale * Stokeslet(p - Node(l, j), kEps) * z.Modes((Node(l, j) - centroid) / rho);
            } else {
              block += kScale * static_cast<double>(p1 - p0) * Stokeslet(p - y, kEps) * z.Modes((y - centroid) / rho);
            }
          }
        }
        w.block(3 * i, modes * b, 3, modes) = block;
      }
    }
  return w;
}

// Zᵀ w: per chunk, w's rows summed (forces) and their moments Σ d_i × w_i (turns).
MatX ZTranspose(const Lattice& l, const Space& z, const MatX& w) {
  const int rods = static_cast<int>(l.x.size()), modes = z.modes();
  MatX out = MatX::Zero(modes * rods * z.chunks(), w.cols());
  for (int r = 0; r < rods; ++r)
    for (int a = 0; a < z.chunks(); ++a) {
      const Vec3 centroid = Centroid(l, z.ChunkBegin(r, a), z.ChunkEnd(r, a));
      const double rho = Radius(l, z.ChunkBegin(r, a), z.ChunkEnd(r, a));
      for (int i = z.ChunkBegin(r, a); i < z.ChunkEnd(r, a); ++i)
        out.middleRows(modes * (r * z.chunks() + a), modes) +=
            z.Modes((Node(l, i) - centroid) / rho).transpose() * w.middleRows<3>(3 * i);
    }
  return out;
}

class CoarseLevelLayout : public ::testing::TestWithParam<CoarseLayout> {};

TEST_P(CoarseLevelLayout, ProductMatchesTheAssembledW) {
  for (const int fixed : {0, 2}) {
    SCOPED_TRACE(fixed);
    const Lattice l = MakeLattice(false, fixed);
    const Space z{GetParam(), fixed};
    CoarseLevel coarse;
    ASSERT_TRUE(coarse.Build(l.rods, l.blocks, kScale, z.layout));
    ASSERT_EQ(coarse.num_chunks(), 6 * z.chunks());
    int near_blocks = 0;
    const MatX w = ReferenceW(l, z, false, &near_blocks);
    std::printf("  %d fixed nodes: nodes near a point of another rod: %d\n", fixed, near_blocks);
    ASSERT_GT(near_blocks, 0);  // the near corrections are part of what is compared
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
}

// E as the coarse level factorizes it: Zᵀ W, with turns plus a thousandth of each chunk's mean
// force diagonal on its turn diagonal (what keeps E regular when a chunk lies on a line).
MatX RegularizedE(const Space& z, MatX e) {
  if (z.layout.turns)
    for (Eigen::Index a = 0; a < e.rows() / 6; ++a) {
      const double tau = 1e-3 * (e(6 * a, 6 * a) + e(6 * a + 1, 6 * a + 1) + e(6 * a + 2, 6 * a + 2)) / 3.0;
      for (int k = 3; k < 6; ++k) e(6 * a + k, 6 * a + k) += tau;
    }
  return e;
}

// On the helices and on straight rods (a chunk on a line: a turn of zero force, E regular only by
// its regularization).
TEST_P(CoarseLevelLayout, SolveInvertsZTransposeW) {
  for (const bool straight : {false, true}) {
    for (const int fixed : {0, 2}) {
      SCOPED_TRACE(fixed);
      const Lattice l = MakeLattice(straight, fixed);
      const Space z{GetParam(), fixed};
      CoarseLevel coarse;
      ASSERT_TRUE(coarse.Build(l.rods, l.blocks, kScale, z.layout)) << straight;
      const MatX w = ReferenceW(l, z, false);
      const MatX e = RegularizedE(z, ZTranspose(l, z, w));
      std::mt19937 rng(5);
      std::normal_distribution<double> normal;
      const VecX v = VecX::NullaryExpr(w.rows(), [&]() { return normal(rng); });
      const VecX c = coarse.Solve(v);
      ASSERT_TRUE(c.allFinite()) << straight;
      const VecX ztv = ZTranspose(l, z, v);
      // E's LU factors are kept in half precision (DenseLu kHalf, where the CPU allows it, else in
      // single): rounding them perturbs E by at most u |L||U| entrywise, u = 2⁻¹¹ (4.9e-4), which
      // partial pivoting keeps near u ‖E‖ (the factorization's own single-precision error is 500×
      // smaller). Residual within 2 u ‖E‖₂ ‖c‖ (measured 0.13 u ‖E‖₂ ‖c‖ with forces alone, which
      // E's conditioning makes 1.1 % of ‖Zᵀv‖); an E inconsistent with W would miss by O(‖Zᵀv‖).
      MatX u_svd, v_svd;
      VecX sigma;
      ASSERT_TRUE(ThinSvd(e, &u_svd, &sigma, &v_svd));
      const double norm_e = sigma(0);
      const double residual = (e * c - ztv).norm();
      std::printf("  %s: coarse solve residual %.2e of ‖E‖‖c‖, %.2e of ‖Zᵀv‖, cond %.3g\n",
                  straight ? "straight rods" : "helices", residual / (norm_e * c.norm()),
                  residual / ztv.norm(), sigma(0) / sigma(sigma.size() - 1));
      EXPECT_LT(residual, 2.0 * 4.9e-4 * norm_e * c.norm()) << straight;
      // With a fixed chunk (two nodes) these synthetic blocks (random + 50 I, weaker than the two
      // nodes' Stokeslets to the other rods) leave E near singular (condition 1.2e5 with forces
      // alone on straight rods, 6.5e5 with turns, against 1e4 and 6.5e4 without): the backward
      // test above (an inconsistent E misses it by its own relative error) is then the one that
      // can hold.
      if (fixed == 0) {
        EXPECT_LT(residual, 0.05 * ztv.norm()) << straight;
      }
      VecX y = VecX::Zero(v.size());
      coarse.AddZ(c, &y);  // Z c: each node takes its chunk's force (and turn), F + Ω × (x_i − X_b) / ρ_b
      const int node = kNodes + 1, chunk = z.chunks();  // rod 1's second node, in its first chunk
      const Vec3 d = (Node(l, node) - Centroid(l, z.ChunkBegin(1, 0), z.ChunkEnd(1, 0))) /
                     Radius(l, z.ChunkBegin(1, 0), z.ChunkEnd(1, 0));
      const VecX mine = c.segment(z.modes() * chunk, z.modes());
      EXPECT_LT((y.segment<3>(3 * node) - z.Modes(d) * mine).norm(), 1e-12 * mine.norm()) << straight;
    }
  }
}

TEST_P(CoarseLevelLayout, PointsApproximateTheNodeToNodeCoupling) {
  const Lattice l = MakeLattice(false, 2);
  const Space z{GetParam(), 2};
  const MatX mine = ReferenceW(l, z, false), node_to_node = ReferenceW(l, z, true);
  // Between rods, block by block (3 × modes): beyond 2 radii of a point its monopole's error is
  // the quadrupole's, ≲ (a/d)² ≤ 1/4 of the block (measured here: see the printout).
  double worst = 0.0;
  const int modes = z.modes();
  for (Eigen::Index i = 0; i < mine.rows() / 3; ++i)
    for (Eigen::Index b = 0; b < mine.cols() / modes; ++b) {
      if (i / kNodes == b / z.chunks()) continue;
      const MatX ref = node_to_node.block(3 * i, modes * b, 3, modes);
      worst = std::max(worst, (mine.block(3 * i, modes * b, 3, modes) - ref).norm() / ref.norm());
    }
  std::printf("worst relative error of a between-rod block: %.3f\n", worst);
  EXPECT_LT(worst, 0.25);
}

INSTANTIATE_TEST_SUITE_P(
    Layouts, CoarseLevelLayout,
    ::testing::Values(CoarseLayout{},  // eight chunks of forces at their centroids, one fixed
                      CoarseLayout{.chunks_per_rod = 4, .turns = true, .points_per_chunk = 4,
                                   .fixed_chunk = false},
                      CoarseLayout{.chunks_per_rod = 4, .turns = true, .points_per_chunk = 4}),
    [](const ::testing::TestParamInfo<CoarseLayout>& param) {
      return std::string(param.param.turns ? "ForcesAndTurns" : "Forces") +
             (param.param.fixed_chunk ? "FixedChunk" : "");
    });

// Rods of a few nodes, two of them fixed: every chunk keeps at least one node (the graded edges
// of the free chunks pushed apart), E stays regular and the solve finite.
TEST(CoarseLevel, ShortClampedRodsKeepEveryChunk) {
  std::vector<Matrix3X> x;
  std::vector<MatX> blocks;
  std::vector<CoarseRod> rods;
  std::mt19937 rng(11);
  std::normal_distribution<double> normal;
  int offset = 0, expected_chunks = 0;
  for (const int n : {3, 9, 10, 12, 20}) {
    Matrix3X p(3, n);
    for (int i = 0; i < n; ++i)
      p.col(i) = Vec3(0.01 * std::cos(0.8 * i) + 0.04 * static_cast<double>(x.size()), 0.01 * std::sin(0.8 * i), 0.005 * i);
    x.push_back(p);
    blocks.push_back(MatX::NullaryExpr(3 * n, 3 * n, [&]() { return normal(rng); }) + 50.0 * MatX::Identity(3 * n, 3 * n));
    expected_chunks += 1 + std::min(CoarseLayout{}.chunks_per_rod - 1, n - 2);
  }
  for (std::size_t r = 0; r < x.size(); ++r) {
    rods.push_back({.x = &x[r], .eps = kEps, .node_offset = offset, .fixed_nodes = 2});
    offset += static_cast<int>(x[r].cols());
  }
  CoarseLevel coarse;
  ASSERT_TRUE(coarse.Build(rods, blocks, kScale, CoarseLayout{}));
  EXPECT_EQ(coarse.num_chunks(), expected_chunks);
  const VecX v = VecX::NullaryExpr(3 * offset, [&]() { return normal(rng); });
  const VecX c = coarse.Solve(v);
  EXPECT_TRUE(c.allFinite());
  VecX w;
  coarse.ApplyW(c, &w);
  EXPECT_TRUE(w.allFinite());
}

TEST(CoarseLevel, LayoutBySize) {  // turns for a few tens of rods, forces alone beyond
  EXPECT_TRUE(CoarseLayout::For(10).turns);
  EXPECT_TRUE(CoarseLayout::For(CoarseLayout::kTurnsUpToRods).turns);
  EXPECT_FALSE(CoarseLayout::For(CoarseLayout::kTurnsUpToRods).fixed_chunk);
  EXPECT_FALSE(CoarseLayout::For(CoarseLayout::kTurnsUpToRods + 1).turns);
  EXPECT_TRUE(CoarseLayout::For(CoarseLayout::kTurnsUpToRods + 1).fixed_chunk);
}

}  // namespace
}  // namespace stokesrods
