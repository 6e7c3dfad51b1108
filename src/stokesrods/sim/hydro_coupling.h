// Nonlocal hydrodynamics (RSS, LSBT) inside the implicit Euler step (paper eqs. 16, 21, 22).
//
// The mobility 𝕄 (U = 𝕄 F, fluid/hydrodynamics.h) is assembled at q(t_k) and kept for the step.
//   explicit (paper Algorithm 1): F^h = −𝕄⁻¹ U(t_k), a constant force during the Newton solve;
//   implicit (default):           F^h = −𝕄⁻¹ U(t_{k+1}), U = (x − x(t_k))/h, whose Jacobian
//                                 𝕄⁻¹/h is dense over all nodes of all rods.
// The implicit Newton system J δ = r with J = B + Sᵀ 𝕄⁻¹ S / h (B the banded per-rod part, S the
// selection of free position DOFs) is solved by the Woodbury identity
//   J⁻¹ r = B⁻¹ r − X (h 𝕄 + S X)⁻¹ S B⁻¹ r,   X = B⁻¹ Sᵀ,
// which needs one dense LU of size 3M per Newton iteration instead of one of size 4M, and no
// inverse of 𝕄.
#pragma once

#include <vector>

#include <Eigen/LU>

#include "stokesrods/sim/forces.h"
#include "stokesrods/sim/model.h"
#include "stokesrods/solver/banded_matrix.h"

namespace stokesrods {

class HydroCoupling {
 public:
  /// Assembles and factorizes 𝕄 at q_start; for the explicit coupling also F^h(v_start).
  void Prepare(const Model& model, const VecX& q_start, const VecX& v_start);

  /// Adds F^h at the trial DOFs q into the global `force`.
  void AddTo(const Model& model, const StepContext& ctx, const VecX& q, VecX* force);

  /// Factorizes J = B + Sᵀ 𝕄⁻¹ S / h (implicit coupling), `jacobian` the unfactorized per-rod
  /// banded parts B (fixed DOFs already identity rows; factorized in place). False if singular.
  bool FactorizeNewtonSystem(const Model& model, double h, std::vector<BandedMatrix>* jacobian);
  /// Solves J δ = rhs in place with the factors of the last FactorizeNewtonSystem.
  void SolveNewtonSystem(const Model& model, const std::vector<BandedMatrix>& jacobian,
                         VecX* rhs);

  /// Nodal hydrodynamic forces on the rods (3M) at the last AddTo [N].
  const VecX& nodal_force() const { return nodal_force_; }
  const MatX& mobility() const { return mobility_; }

 private:
  MatX mobility_;                    ///< 𝕄 at q(t_k), 3M × 3M
  Eigen::PartialPivLU<MatX> lu_;     ///< of 𝕄
  bool explicit_ = false;
  VecX explicit_force_;              ///< 3M, explicit coupling
  VecX nodal_force_;                 ///< 3M, last evaluated F^h
  // Scratch of the Woodbury solve.
  std::vector<MatX> x_blocks_;       ///< X_k = B_k⁻¹ S_kᵀ per rod (n_k × 3N_k)
  MatX capacitance_;                 ///< h 𝕄 + S X
  Eigen::PartialPivLU<MatX> capacitance_lu_;
  VecX velocity_;                    ///< 3M scratch
};

/// Gathers the node velocities (x − x_start)/h of all rods into a 3M vector.
void GatherNodeVelocities(const Model& model, const VecX& q, const VecX& q_start, double h,
                          VecX* u);

/// The hydrodynamic rods (positions at q) as the fluid module sees them.
std::vector<HydroRod> MakeHydroRods(const Model& model, const std::vector<Matrix3X>& positions);

}  // namespace stokesrods
