// The coarse level of the two-level preconditioner of the capacitance C = h 𝕄 + S X for the
// matrix-free mobility (sim/hydro_coupling.h): per rod, K chunks of consecutive nodes with a
// uniform force each (the columns Z, 3K per rod), W ≈ C Z and E = Zᵀ W. One application of the
// preconditioner is c = E⁻¹ Zᵀ r, y = Z c + D⁻¹ (r − W c) (D the per-rod blocks).
//
// W is not stored. Within a rod it is the exact block D_k summed over each chunk's columns
// (3N_k × 3K per rod). Between rods, chunk b acts on node i as one regularized point Stokeslet at
// the chunk's centroid X_b carrying the chunk's N_b nodal forces,
//     W_ib = h N_b S_ε(x_i − X_b) / (8πμ),
// so W c is a Stokeslet sum of 3 K per rod sources at M targets (fluid/stokeslet_sum.h: direct,
// in single precision, or the FMM when it pays): O(M K R) per application and no 3M × 3K matrix
// (187 MB for a hundred helices in double) to build or stream. A preconditioner needs no more
// than this: the between-rod coupling only has to carry the collective flow of many rods
// (tests/sim/hydro_coupling_test.cc: GMRES products against the node-to-node W it replaces).
#pragma once

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
};

class CoarseLevel {
 public:
  /// Chunks of consecutive nodes per rod (fewer when a rod has fewer nodes). Measured on the
  /// bench's lattices (one thread, 20 steps after 60, GMRES products per step at 4 / 6 / 8 / 16):
  /// lattice100 6.4 / 5.85 / 5.05 / 4.0, lattice50 6.0 / 5.0 / 5.0 / 4.0; 8 is the fastest
  /// (16: E's LU, (48 R)³ flops at every rebuild, and its solves cost more than they save).
  static constexpr int kChunksPerRod = 8;

  /// blocks[k] = D_k (3N_k × 3N_k), scale = h / (8πμ). False when E is singular (a zero pivot).
  bool Build(const std::vector<CoarseRod>& rods, const std::vector<MatX>& blocks, double scale);

  /// c = E⁻¹ Zᵀ v (3 per chunk).
  VecX Solve(const VecX& v) const;
  /// out = W c (3M).
  void ApplyW(const VecX& c, VecX* out) const;
  /// out += Z c: each chunk's force on its nodes.
  void AddZ(const VecX& c, VecX* out) const;

  int num_chunks() const { return static_cast<int>(chunk_first_.size()) - 1; }

 private:
  using NodeRows = Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::RowMajor>;
  /// Nodes nearer a chunk of another rod than kNearReach times the chunk's radius take the
  /// chunk's own nodes' Stokeslets instead of its centroid's: near_block_ is the difference.
  static constexpr double kNearReach = 2.0;
  void FindNearChunks(const NodeRows& x, const Matrix3X& centroids, const VecX& chunk_eps);

  std::vector<int> chunk_first_;   ///< first global node of each chunk; back() = M
  std::vector<int> chunk_rod_;
  std::vector<int> rod_first_chunk_;  ///< per rod, and back() = chunks
  std::vector<int> rod_first_node_;   ///< per rod, and back() = M
  /// Per rod: D_k Z_k (3N_k × 3K_k) minus the Stokeslets of its own chunks' centroids (which
  /// between_ adds), in single precision (ApplyW sums in double: GemvRowsMixed).
  std::vector<Eigen::MatrixXf> own_;
  VecX chunk_nodes_;               ///< N_b
  double scale_ = 0.0;
  std::unique_ptr<StokesletSum> between_;  ///< centroids → nodes
  DenseLu<float> lu_;              ///< of E = Zᵀ W (single precision: 12 R × 12 R, whose solve
                                   ///< streams the factors once per application)
  // W's corrections near chunks: node i takes near_block_[k] c_b, b = near_chunk_[k],
  // k ∈ [near_start_[i], near_start_[i + 1]).
  std::vector<int> near_start_, near_chunk_;
  std::vector<Mat3> near_block_;
  mutable Matrix3X strengths_, velocity_;
};

}  // namespace stokesrods
