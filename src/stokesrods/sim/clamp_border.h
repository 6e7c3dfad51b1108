// Rods clamped to a free body (issue 11's swimming cell): the border of the implicit step's Newton
// system between the rods and the body's rigid velocity V = (U, Ω) (docs/model.md, "Rods on a free
// body").
//
// A rod on free body b holds its clamped DOFs q_c (its first nodes and θ0) in the body's frame:
// q_c(t + h) = Φ(V), the step start's clamp moved rigidly by (hU, hΩ) about the centre, θ0 turned
// by the body's spin about the first edge and by the motor (sim/bodies.h: PlaceFreeClamps),
// linearized as
//     δq_c = h G_c δV,   G_c = [I  −[x_i − c]×] at a clamped node,  [0  t0ᵀ] at θ0,
// with t0 the first tangent at the iterate and c = c_k the centre at the step's start: the fluid's
// load on the body is taken at its start pose too (as 𝕄 is), so that both torques of the body's
// balance are about one point (the kinematics' arm x_i − c_{k+1} differs by hU: a Jacobian
// approximation of order h², while Φ itself is exact). The clamp's reaction is the momentum
// residual at the clamped DOFs, λ = r_q,c (the force and moment the body exerts on the rod); the
// body, massless, balances it against the fluid in its six rows of r_u:
//     r_b = G_bᵀ f_b − G_cᵀ λ = 0.
// With B the rod's Jacobian ∂r_q/∂q as assembled, B̃ the same with the clamped rows and columns
// replaced by the identity (factorized), y = −B̃⁻¹ r_q and X = B̃⁻¹ Sᵀ (hydro_coupling.h),
//     δq = y + X δf + h Γ δV,   Γ = E_c G_c − B̃⁻¹ B_{:,c} G_c
// (E_c puts G_c on the clamped DOFs; B_{:,c} with its clamped rows zeroed: the free DOFs follow
// the clamp elastically), and the capacitance system C δf = b of hydro_coupling.h is bordered by δV:
//     node rows:   C δf + h S Γ δV
//     body rows:   h G_bᵀ δf_b + h G_cᵀ (S_cᵀ δf − B_{c,:} X δf) + h² K δV,   K = −G_cᵀ B_{c,:} Γ,
//     right side:  body rows  −h r_b + h G_cᵀ B_{c,:} y.
#pragma once

#include <vector>

#include "stokesrods/common/types.h"
#include "stokesrods/sim/model.h"
#include "stokesrods/sim/state.h"
#include "stokesrods/solver/banded_matrix.h"

namespace stokesrods {

/// One rod on a free body: its part of the border.
struct ClampBorder {
  int rod = 0;
  int unknown = 0;        ///< index of the body's V in the hydrodynamic unknown f
  std::vector<int> dofs;  ///< the rod's clamped DOFs (local, sorted)
  MatX g;                 ///< G_c (clamped DOFs × 6) at the iterate
  MatX columns;           ///< B_{:,c}, clamped rows zeroed (rod DOFs × clamped DOFs)
  MatX rows;              ///< B_{c,:} (clamped DOFs × rod DOFs)
  MatX gamma;             ///< Γ (rod DOFs × 6), by CompleteClampBorders
  Mat6 k = Mat6::Zero();  ///< K, by CompleteClampBorders
  MatX row_x;             ///< B_{c,:} X (clamped DOFs × 3N), for the dense capacitance
};

/// True when some rod is clamped to a free body.
bool HasFreeClamps(const Model& model);

/// G_c of rod r at q, about its body's centre at the step's start.
MatX ClampRigidMotions(const Model& model, int r, const std::vector<BodyPose>& start_poses,
                       const VecX& q);

/// The borders (one per rod on a free body) from the rods' Jacobians as assembled, before their
/// clamped rows and columns are fixed.
void CaptureClampBorders(const Model& model, const std::vector<BodyPose>& start_poses,
                         const VecX& q, const std::vector<BandedMatrix>& jacobian,
                         std::vector<ClampBorder>* borders);

/// G_cᵀ λ of each free body (6 per free body, in the order of their V): the force and torque
/// about the centre that its rods' clamps take from it, λ the momentum residual before the
/// clamped entries are zeroed [N, N·m].
void ClampLoads(const Model& model, const std::vector<BodyPose>& start_poses, const VecX& q,
                const VecX& residual, VecX* loads);

/// Γ and K once the rods' B̃ are factorized.
void CompleteClampBorders(const Model& model, const std::vector<BandedMatrix>& factorized,
                          std::vector<ClampBorder>* borders);

/// The border's blocks added to the dense capacitance C (needs row_x).
void AddClampBordersToCapacitance(const Model& model, double h,
                                  const std::vector<ClampBorder>& borders, MatX* capacitance);

/// out += the border's part of C v, with z = X v (the rods' DOFs, B̃⁻¹ Sᵀ v).
void ApplyClampBorders(const Model& model, double h, const std::vector<ClampBorder>& borders,
                       const VecX& v, const VecX& z, VecX* out);

/// sy's body rows −h G_cᵀ B_{c,:} y (the right side is −(h r_u + sy)).
void AddClampBorderRhs(const Model& model, double h, const std::vector<ClampBorder>& borders,
                       const VecX& y, VecX* sy);

/// dq += h Γ δV, with δV in df.
void AddClampMotion(const Model& model, double h, const std::vector<ClampBorder>& borders,
                    const VecX& df, VecX* dq);

}  // namespace stokesrods
