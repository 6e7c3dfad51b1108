// The Krylov preconditioner of the implicit step's capacitance C = h𝕄 + S X (sim/hydro_coupling.h)
// when C is not factorized whole (a matrix-free 𝕄, or a large one): blocks, bordered by the free
// bodies' motions, and a coarse level.
//
// The unknowns are those of the bordered mobility: the rods' M nodal forces, the bodies' P point
// forces, then V = (U, Ω) of each free body (fluid/rigid_body.h).
//   Fine level: A, the block diagonal of C over the rods (D_k = h 𝕄_kk + S_k X_k) and over the
//     bodies (h 𝕄_bb, the regularized Stokeslets of a body's points among themselves), each by
//     its LU in single precision; bordered exactly by each free body's six unknowns, which couple
//     to its own points (h G_b, h G_bᵀ: u_j = U + Ω × (x_j − c)) and to the rods clamped on it
//     (h S Γ_c, h G_cᵀ (S_cᵀ − B_c X), h² K_c: sim/clamp_border.h). With B the columns of V and
//     Cᵀ its rows, [A B; Cᵀ K] y = r is solved by the Schur complement on V (6 × 6 per body):
//         z = A⁻¹ r,   y_V = Σ⁻¹ (r_V − Cᵀ z),   y = z − A⁻¹ B y_V,   Σ = K − Cᵀ A⁻¹ B
//     (A⁻¹ B once per build: the body's and its rods' blocks solved for six columns each). So a
//     swimming cell's body, flagella and motion are one exact block but for the flow they make
//     at each other.
//   Coarse level (optional, sim/coarse_level.h): per rod, 4 chunks of consecutive nodes with a
//     uniform force each (columns Z), E = Zᵀ W with W ≈ C Z on the rods' rows (zero on the
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

class CapacitancePreconditioner {
 public:
  /// `rod_blocks`: D_k of each rod (3N_k square); `bodies`: the surfaces at the step's start (the
  /// model's order); `borders`: the rods on free bodies (Γ, K and row_x completed) or nullptr;
  /// `positions`: the rods' nodes for the coarse level, or nullptr for the fine level alone.
  /// C = h𝕄 + …: h scales the bodies' blocks and borders (1 for 𝕄 itself). False if a block or
  /// a Schur complement is singular.
  bool Build(const Model& model, double h, const std::vector<MatX>& rod_blocks,
             const std::vector<BodySurface>& bodies, const std::vector<ClampBorder>* borders,
             const std::vector<Matrix3X>* positions);
  /// out ≈ C⁻¹ v.
  void Apply(const VecX& v, VecX* out) const;

 private:
  struct FreeBody {
    int body = 0;             ///< index among the bodies
    int unknown = 0;          ///< first entry of its V
    // The columns B (3 × points of the body and of its clamped rods, × 6) and rows Cᵀ, with
    // A⁻¹ B, each per block: first entry and the block's part.
    std::vector<int> first;
    std::vector<MatX> columns_solved;  ///< A⁻¹ B, per block
    std::vector<MatX> rows;            ///< Cᵀ, per block (6 × block size)
    Eigen::PartialPivLU<Mat6> schur;   ///< of Σ = K − Cᵀ A⁻¹ B
  };
  void SolveBlocks(const VecX& v, VecX* out) const;
  void SolveFine(const VecX& v, VecX* out) const;
  bool BuildFreeBody(const Model& model, double h, int body, const std::vector<BodySurface>& bodies,
                     const std::vector<ClampBorder>* borders);
  std::vector<int> block_first_;          ///< first entry of each block (rods, then bodies); back()
  std::vector<DenseLu<float>> block_lu_;  ///< single precision: a preconditioner needs no more
  std::vector<FreeBody> free_bodies_;
  int size_ = 0;
  bool coarse_ = false;
  CoarseLevel coarse_level_;
};

}  // namespace stokesrods
