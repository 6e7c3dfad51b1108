// The Krylov preconditioner of the implicit step's capacitance C = h𝕄 + S X (sim/hydro_coupling.h)
// when C is not factorized whole (a matrix-free 𝕄, or a large one): blocks, bordered by the free
// bodies' motions, and a coarse level.
//
// The unknowns are those of the bordered mobility: the rods' M nodal forces, the bodies' P point
// forces, then V = (U, Ω) of each free body (fluid/rigid_body.h).
//   Fine level: A, the block diagonal of C over the rods (D_k = h 𝕄_kk + S_k X_k), over the
//     bodies (h 𝕄_bb, the regularized Stokeslets of a body's points among themselves) and over
//     the cells: a body and the rods clamped on it as one block (its D_k, h 𝕄_bb and the flow
//     between them, h 𝕄_kb, h 𝕄_bk, h 𝕄_kl, as the dense bordered mobility has them:
//     fluid/rigid_body.h AssembleMobilityWithBodies), each by its LU in single precision;
//     bordered exactly by each free body's six unknowns, which couple
//     to its own points (h G_b, h G_bᵀ: u_j = U + Ω × (x_j − c)) and to the rods clamped on it
//     (h S Γ_c, h G_cᵀ (S_cᵀ − B_c X), h² K_c: sim/clamp_border.h). With B the columns of V and
//     Cᵀ its rows, [A B; Cᵀ K] y = r is solved by the Schur complement on V (6 × 6 per body):
//         z = A⁻¹ r,   y_V = Σ⁻¹ (r_V − Cᵀ z),   y = z − A⁻¹ B y_V,   Σ = K − Cᵀ A⁻¹ B
//     (A⁻¹ B once per build: the body's and its rods' blocks solved for six columns each). So a
//     swimming cell's body, flagella, the flow between them and its motion are one exact block
//     (without the flow between a body and its own flagella GMRES needed 3.5× more products:
//     docs/performance.md).
//   Coarse level (optional, sim/coarse_level.h): per rod, chunks of consecutive nodes with a
//     force (and a turn) each (columns Z), E = Zᵀ W with W ≈ C Z on the rods' rows (zero on the
//     bodies' and their motions' rows). One application: c = E⁻¹ Zᵀ r,
//     y = Z c + Fine⁻¹ (r − W c). Block Jacobi alone misses the collective flow of many rods
//     (GMRES then needs 5–6× more products).
#pragma once

#include <vector>

#include <Eigen/LU>

#include "stokesrods/common/types.h"
#include "stokesrods/fluid/rigid_body.h"
#include "stokesrods/sim/clamp_border.h"
#include "stokesrods/sim/coarse_level.h"
#include "stokesrods/sim/model.h"
#include "stokesrods/solver/dense_lu.h"

namespace stokesrods {

/// Per rod, a rotation R_k of its nodes' entries (3 per node from 3 first_node[k]); the other
/// entries (the bodies' points, the free bodies' motions) are left as they are.
struct RodRotations {
  std::vector<Mat3> rotation;   ///< per rod; empty: none
  std::vector<int> first_node;  ///< per rod
  std::vector<int> nodes;       ///< per rod
  bool empty() const { return rotation.empty(); }
  /// x ← Q x, or Qᵀ x when `transpose`.
  void Apply(bool transpose, VecX* x) const;
};

class CapacitancePreconditioner {
 public:
  /// `rod_blocks`: D_k of each rod (3N_k square); `rods`: the rods as the fluid sees them (for
  /// the cell blocks and the coarse level); `bodies`: the surfaces at the step's start (the
  /// model's order); `borders`: the rods on free bodies (Γ, K and row_x completed) or nullptr;
  /// `coarse`: with the coarse level. C = h𝕄 + …: h scales the bodies' blocks and borders (1 for
  /// 𝕄 itself). `keep_coarse`: the coarse level of the previous Build stays as it was built (the
  /// caller applies it in its own frame: the four-argument Apply). False if a block or a Schur
  /// complement is singular.
  bool Build(const Model& model, double h, const std::vector<MatX>& rod_blocks,
             const std::vector<HydroRod>& rods, const std::vector<BodySurface>& bodies,
             const std::vector<ClampBorder>* borders, bool coarse, bool keep_coarse = false);
  /// out ≈ C⁻¹ v at the positions of the build.
  void Apply(const VecX& v, VecX* out) const;
  /// out ≈ C⁻¹ v with the rods turned since the build: Q P₀ Qᵀ v, Q = `fine` (empty: none). A
  /// coarse level kept from an earlier build (Build's keep_coarse) is applied in its own frame,
  /// Q = `coarse`, the rods' rotations since that build.
  void Apply(const VecX& v, VecX* out, const RodRotations& fine, const RodRotations& coarse) const;
  /// Whether the coarse level is one kept from an earlier build.
  bool coarse_kept() const { return coarse_kept_; }
  /// E's size: the coarse level's unknowns (0 without one).
  int coarse_unknowns() const {
    return coarse_ ? coarse_level_.num_chunks() * coarse_level_.layout().modes() : 0;
  }

 private:
  /// A diagonal block of the fine level: the unknowns of one rod, one body, or a cell (a body
  /// and the rods clamped on it), which need not be contiguous.
  struct Block {
    std::vector<std::pair<int, int>> ranges;  ///< (first entry, size), in the block's order
    int size = 0;
    int rod = -1;   ///< a rod alone: its index
    int body = -1;  ///< a body (and its rods): its index
    DenseLu<float> lu;  ///< single precision: a preconditioner needs no more
    VecX Gather(const VecX& v) const;
    void Scatter(const Eigen::VectorXd& x, VecX* out) const;  ///< out(ranges) += x
  };
  /// Where a rod's or a body's unknowns sit: its block and its first entry in the block.
  struct Place {
    int block = 0;
    int offset = 0;
  };
  struct FreeBody {
    int unknown = 0;  ///< first entry of its V
    // The columns B (3 × points of the body and of its clamped rods, × 6) and rows Cᵀ, with
    // A⁻¹ B, per block they touch.
    std::vector<int> blocks;
    std::vector<MatX> columns_solved;  ///< A⁻¹ B, per block
    std::vector<MatX> rows;            ///< Cᵀ, per block (6 × block size)
    Eigen::PartialPivLU<Mat6> schur;   ///< of Σ = K − Cᵀ A⁻¹ B
  };
  void MakeBlocks(const Model& model, const std::vector<BodySurface>& bodies);
  MatX BlockMatrix(const Model& model, double h, const Block& block,
                   const std::vector<MatX>& rod_blocks, const std::vector<HydroRod>& rods,
                   const std::vector<BodySurface>& bodies) const;
  void SolveBlocks(const VecX& v, VecX* out) const;
  void SolveFine(const VecX& v, VecX* out) const;
  bool BuildFreeBody(const Model& model, double h, int body, const std::vector<BodySurface>& bodies,
                     const std::vector<ClampBorder>* borders);
  std::vector<Block> blocks_;
  std::vector<Place> rod_place_, body_place_;
  std::vector<FreeBody> free_bodies_;
  int size_ = 0;
  bool coarse_ = false;
  bool coarse_kept_ = false;  ///< the coarse level is from an earlier Build
  CoarseLevel coarse_level_;
  mutable VecX turned_, coarse_w_, coarse_z_;  ///< the four-argument Apply's vectors
};

}  // namespace stokesrods
