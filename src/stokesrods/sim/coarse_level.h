// The coarse level of the two-level preconditioner of the capacitance C = h 𝕄 + S X for the
// matrix-free mobility (sim/hydro_coupling.h): per rod, K chunks of consecutive nodes (a clamp's
// fixed nodes one of them where the layout says so: CoarseLayout::fixed_chunk), each with
// a force F (3 modes) or a force and a turn Ω about the chunk's centroid X_b (6 modes: the nodal
// forces F + Ω × (x_i − X_b) / ρ_b, ρ_b the chunk's RMS radius, so that a turn's columns are of
// a force's size): the columns Z, 3K or 6K per rod; W ≈ C Z and E = Zᵀ W. One
// application of the preconditioner is c = E⁻¹ Zᵀ r, y = Z c + D⁻¹ (r − W c) (D the per-rod
// blocks).
//
// W is not stored. Within a rod it is the exact block D_k times Z_k (3N_k × 3K or 6K per rod).
// Between rods, chunk b acts through P points (runs of consecutive nodes, centroids Y_s, N_s nodes
// each; P = 1: the chunk's centroid), each a regularized point Stokeslet carrying the nodal forces
// of its nodes,
//     W_is c = h N_s S_ε(x_i − Y_s) (F_b + Ω_b × (Y_s − X_b) / ρ_b) / (8πμ),
// so W c is a Stokeslet sum of P K per rod sources at M targets (fluid/stokeslet_sum.h: direct,
// in single precision, or the FMM when it pays): O(M K P R) per application and no 3M × 3K
// matrix (187 MB for a hundred helices in double) to build or stream. Nodes nearer a point than
// twice its radius take its nodes' own Stokeslets instead. A preconditioner needs no more than
// this: the between-rod coupling only has to carry the collective flow of many rods
// (tests/sim/hydro_coupling_test.cc: GMRES products against the node-to-node W it replaces).
//
// The turns carry a chunk's first moment (its torque and stresslet), whose flow at the next rod is
// a/d of its force's (a chunk's size over the rods' spacing: ≈ 1/2 for helices 4R apart). With W
// exact (docs/performance.md, session 25; GMRES products per step) four chunks with turns against
// eight with forces alone, the same 24 unknowns per rod: ring10 3.22 → 3.02, lattice20 4.0 → 3.15,
// lattice50 4.0 → 3.8, lattice100 4.2 → 4.1. They pay for a few tens of rods; from fifty the
// twice as many points in W's sum cost more than they save (CoarseLayout::For). A chunk on a line
// (a straight rod) has a turn of zero force; E's turn diagonals carry a thousandth of the force
// diagonal, which keeps E regular and leaves such a turn at zero.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "stokesrods/common/types.h"
#include "stokesrods/fluid/stokeslet_sum.h"
#include "stokesrods/solver/dense_lu.h"

namespace stokesrods {

struct CoarseRod {
  const Matrix3X* x = nullptr;  ///< node positions
  double eps = 0.0;             ///< regularization ε of its Stokeslets [m]
  int node_offset = 0;          ///< first global node
  int fixed_nodes = 0;          ///< leading nodes held in place (the clamp)
};

/// How the coarse space is laid out per rod.
struct CoarseLayout {
  int chunks_per_rod = 8;    ///< chunks of consecutive nodes (fewer when a rod has fewer nodes)
  bool turns = false;        ///< each chunk's turn beside its force (6 modes, else 3)
  int points_per_chunk = 1;  ///< points carrying a chunk's modes in W between rods
  /// A rod's fixed leading nodes (CoarseRod::fixed_nodes) as a chunk of their own, one of
  /// chunks_per_rod, the others over its free nodes, graded from the fixed ones
  /// (kFreeChunkGrading). C's rows there are h 𝕄 alone (no S X: they do not move),
  /// and next to them S X is small (a cantilever's compliance grows as s³ from its clamp), so
  /// one uniform force over fixed and nearly fixed nodes and the freer ones beyond fits neither;
  /// between rods the forces near the clamps act together (a hundred clamps in a plane). GMRES
  /// products per step (session 36, 40 steps after 60, eight chunks of forces): lattice50
  /// 4.05 → 3.4 (→ 3.1 graded), lattice100 4.35 → 3.8 (→ 3.575 graded). With four chunks and
  /// turns (the free nodes then in three chunks) lattice10 2.85 → 3.0, ring10 3.05 → 3.075,
  /// lattice20 3.175 → 3.025: For sets it for the forces' layout only.
  bool fixed_chunk = true;
  int modes() const { return turns ? 6 : 3; }

  /// Up to kTurnsUpToRods rods: four chunks of six modes, four points each (a chunk's turn needs
  /// more than its centroid: with W exact lattice20 takes 3.15 products per step, with two
  /// points 3.75, with four 3.3); from there on eight chunks of forces at their centroids, the
  /// clamp's nodes one of them.
  /// Eight is the fastest of forces alone (one thread, GMRES products per step at 4 / 6 / 8 / 16
  /// chunks: lattice100 6.4 / 5.85 / 5.05 / 4.0, lattice50 6.0 / 5.0 / 5.0 / 4.0; 16: E's LU,
  /// (48 R)³ flops at every rebuild, and its solves cost more than they save).
  static constexpr int kTurnsUpToRods = 32;
  /// With a fixed chunk, free chunk k of K ends at n_free (k / K)^g from the fixed nodes: finer
  /// where S X is small beside h 𝕄 (sixty-three free nodes in seven chunks: 4, 7, 8, 10, 10,
  /// 12, 12 nodes). GMRES products per step at g = 1, 1.2, 1.3, 1.4, 1.5, 1.6, 1.7, 2 (session
  /// 36, one run each): lattice50 3.4, 3.15, 3.15, 3.1, –, 3.25, –, 3.475; lattice100 3.8, –,
  /// 3.625, 3.575, 3.55, –, 3.75, 3.925.
  static constexpr double kFreeChunkGrading = 1.4;
  static CoarseLayout For(int num_rods);
};

class CoarseLevel {
 public:
  /// blocks[k] = D_k (3N_k × 3N_k), scale = h / (8πμ), the layout CoarseLayout::For(rods). False
  /// when E is singular (a zero pivot).
  bool Build(const std::vector<CoarseRod>& rods, const std::vector<MatX>& blocks, double scale);
  bool Build(const std::vector<CoarseRod>& rods, const std::vector<MatX>& blocks, double scale,
             const CoarseLayout& layout);

  /// c = E⁻¹ Zᵀ v (modes per chunk).
  VecX Solve(const VecX& v) const;
  /// out = W c (3M).
  void ApplyW(const VecX& c, VecX* out) const;
  /// out += Z c: each chunk's force (and turn) at its nodes.
  void AddZ(const VecX& c, VecX* out) const;

  int num_chunks() const { return static_cast<int>(chunk_first_.size()) - 1; }
  const CoarseLayout& layout() const { return layout_; }

 private:
  using NodeRows = Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::RowMajor>;
  /// Nodes nearer a point of another rod than kNearReach times the point's radius take the
  /// point's own nodes' Stokeslets instead of its centroid's: near_block_ is the difference.
  static constexpr double kNearReach = 2.0;
  /// E's turn diagonal plus this share of its chunk's force diagonal (a chunk on a line has a
  /// turn of zero force: Build).
  static constexpr float kTurnRegularization = 1e-3f;
  /// W's sum between rods is direct below this many (point, node) pairs (BuildWith).
  static constexpr std::int64_t kCoarseDirectBelowPairs = 8'000'000;
  /// Build and FindNearPoints with K modes per chunk (fixed-size blocks: 3 or 6).
  template <int K>
  bool BuildWith(const std::vector<CoarseRod>& rods, const std::vector<MatX>& blocks);
  template <int K>
  void FindNearPoints(const NodeRows& x);

  CoarseLayout layout_;
  std::vector<int> chunk_first_;   ///< first global node of each chunk; back() = M
  std::vector<int> chunk_rod_;
  std::vector<int> rod_first_chunk_;  ///< per rod, and back() = chunks
  std::vector<int> rod_first_node_;   ///< per rod, and back() = M
  std::vector<int> point_first_;   ///< first global node of each point's run; back() = M
  std::vector<int> point_chunk_;
  std::vector<int> chunk_first_point_;  ///< first point of each chunk; back() = points
  Matrix3X centroids_;             ///< X_b, per chunk
  VecX chunk_radius_;              ///< ρ_b, the RMS distance of chunk b's nodes from X_b (1: one node)
  Matrix3X arms_;                  ///< (x_i − X_b) / ρ_b of each node in its chunk b
  Matrix3X point_arms_;            ///< (Y_s − X_b) / ρ_b of each point
  Matrix3X points_;                ///< Y_s, per point
  VecX point_nodes_;               ///< N_s
  VecX point_eps_;                 ///< ε of the point's rod
  /// Per rod: D_k Z_k (3N_k × modes K_k) minus the Stokeslets of its own chunks' points (which
  /// between_ adds), in single precision (ApplyW sums in double: GemvRowsMixed).
  std::vector<Eigen::MatrixXf> own_;
  double scale_ = 0.0;
  std::unique_ptr<StokesletSum> between_;  ///< points → nodes
  DenseLu<float> lu_;              ///< of E = Zᵀ W (modes K R square, factors in half precision
                                   ///< where the CPU allows: its solve streams them once per
                                   ///< application)
  // W's corrections near points: node i takes near_block_[k] c_b (3 × modes, column-major at
  // 3 modes k), b the chunk of point near_point_[k], k ∈ [near_start_[i], near_start_[i + 1]).
  std::vector<int> near_start_, near_point_;
  std::vector<double> near_block_;
  mutable Matrix3X strengths_, velocity_;
};

}  // namespace stokesrods
