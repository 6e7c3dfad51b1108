// Nonlocal hydrodynamics (RSS, LSBT) inside the implicit Euler step (paper eqs. 16, 21, 22).
//
// The mobility 𝕄 (U = 𝕄 F, fluid/mobility_operator.h) is taken at q(t_k) and kept for the step.
//   explicit (paper Algorithm 1): the drag f = −𝕄⁻¹ U(t_k), a constant force during the
//                                 Newton solve;
//   implicit (default):           the drag f on the rods is an unknown beside q, with
//                                 r_q = M(q − q_k − h v_k)/h² − F(q) − Sᵀ f = 0   (momentum)
//                                 r_u = S(q − q_k)/h + 𝕄 f = 0                   (no slip)
//                                 S the selection of the free position DOFs.
// Newton's matrix [B  −Sᵀ; S/h  𝕄] (B the banded per-rod part) is solved by eliminating δq:
//   y = −B⁻¹ r_q,  X = B⁻¹ Sᵀ,  C δf = −(h r_u + S y),  C = h 𝕄 + S X,  δq = y + X δf,
// C of size 3M and never 𝕄⁻¹. The capacitance C is solved
//   direct: by a dense LU of C at the current 𝕄 (the reference, refactorized whenever 𝕄 or B is),
//   krylov: by GMRES with products h 𝕄 v + S X v (𝕄 matrix-free or dense) and a preconditioner
//           kept across steps, rebuilt with the Newton factors or when GMRES slows:
//           up to 3(M + P) = 3000 with a dense 𝕄: the LU of the whole C (single precision);
//           else (matrix-free, or larger): blocks per rod and per body, bordered by the free
//           bodies' motions (sim/capacitance_preconditioner.h), and a coarse level
//           (sim/coarse_level.h: W ≈ C Z by a point Stokeslet per chunk, never stored).
// The kept preconditioner follows the rods' rotation (model.hydro.rotate_preconditioner): rod k's
// nodes turned rigidly by R_k turn its 𝕄 and elastic blocks into R_k(·)R_kᵀ (the RSS kernel and
// the elastic energy are invariant under rotation), so P₀ ≈ C₀⁻¹, built at the nodes X₀, is
// applied as Q P₀ Qᵀ, Q = diag(R_k) on each rod's nodes, R_k the rotation that best maps the
// rod's nodes at X₀ onto its nodes now (least squares about their centroids: Kabsch). The
// blocks between rods turned about different axes, a wall's images, and what deforms, are left
// to GMRES; rods clamped on a body, whose cell block holds the body's points, keep R_k = I.
// Fig. 1 turns each helix 0.063 rad per step at h = 40 ms. It is rebuilt when the solves since
// the rebuild have taken, beyond the first solve's count each, as many GMRES products as a
// rebuild costs (kRebuildCostInProducts), or when one solve took more than twice the first's
// plus two.
// Measured (docs/performance.md, session 19): Fig. 1 over 75 s at h = 40 ms 27 196 → 14 798
// products; ten helices at h = 10 ms 23.3 → 11.9 per step; unchanged at h = 1 ms from ten
// helices up.
// The matrix-free path's coarse level (E's LU, O(R³) for R rods) may outlive the blocks: it is
// rebuilt at every CoarseRebuildPeriod-th rebuild only, between them applied in its own frame with
// the rods' rotations since its build (CapacitancePreconditioner::Apply), unless h changed or GMRES
// slowed severely. The period is 1 (every rebuild) up to about 150 helices.
// Since r_u is linear in (q, f), after a full Newton step it is the GMRES residual / h; along a
// damped step it changes linearly, so line-search trials need no product with 𝕄.
#pragma once

#include <memory>
#include <vector>

#include <Eigen/LU>

#include "stokesrods/fluid/mobility_operator.h"
#include "stokesrods/sim/capacitance_preconditioner.h"
#include "stokesrods/sim/clamp_border.h"
#include "stokesrods/sim/forces.h"
#include "stokesrods/sim/model.h"
#include "stokesrods/sim/state.h"
#include "stokesrods/solver/banded_matrix.h"
#include "stokesrods/solver/dense_lu.h"

namespace stokesrods {

struct HydroSolveReport {
  bool ok = true;
  int krylov_iterations = 0;   ///< products with C (0 for the direct solve)
  double relative_residual = 0.0;
};

class HydroCoupling {
 public:
  /// The mobility operator and solver for the model (model.hydro_solver).
  void Init(const Model& model);

  /// The cell bodies' surfaces and point velocities at `time` (sim/bodies.h) for the next
  /// Prepare: their P points follow the M rod nodes in f and r_u (3(M + P)), with
  ///   r_u,body = 𝕄 f|_body + u_body = 0,   u_body = U + Ω × (x − c) known (fixed, prescribed);
  /// S has no rows there, so C = h𝕄 + S X extends by the bodies' rows and columns of h𝕄.
  /// Free bodies add 6 unknowns (U, Ω) each after the points, and 6 rows r_b = Gᵀ f (their
  /// balance of force and torque) to r_u: the bordered mobility of fluid/rigid_body.h. Rods
  /// clamped to a free body add their clamps' loads to r_b and border C (sim/clamp_border.h).
  void SetBodies(const Model& model, const std::vector<BodyPose>& poses);

  /// Takes 𝕄 at q_start; for the explicit coupling also solves for the drag of v_start.
  HydroSolveReport Prepare(const Model& model, const VecX& q_start, const VecX& v_start);

  /// The explicit coupling's constant drag on the nodes (3M) of the step.
  const VecX& explicit_force() const { return explicit_force_; }

  /// force += Sᵀ f: the nodal forces f (3M) on the rods' position DOFs.
  static void AddNodalForce(const Model& model, const VecX& f, VecX* force);

  /// r_u = S(q − q_start)/h + 𝕄 f (3M), plus the bodies' rows (3P) [m/s].
  void VelocityResidual(const Model& model, const VecX& q, const VecX& q_start, double h,
                        const VecX& f, VecX* r_u) const;

  /// Builds X and the capacitance's factors (direct) or preconditioner (krylov) from the
  /// unfactorized banded parts B in `jacobian` (fixed DOFs identity rows; factorized in place).
  /// False if B or C is singular.
  /// `borders`: the rods clamped to free bodies (sim/clamp_border.h), their Γ and K completed here
  /// and kept (by pointer) for the solves until the next call.
  bool FactorizeNewtonSystem(const Model& model, double h, std::vector<BandedMatrix>* jacobian,
                             std::vector<ClampBorder>* borders = nullptr);

  /// Solves [B −Sᵀ; S/h 𝕄][δq; δf] = −[r_q; r_u] with the factors of FactorizeNewtonSystem, and
  /// gives du = S δq/h + 𝕄 δf, the change of r_u along (δq, δf). The Krylov solve stops at
  /// model.hydro.krylov_tolerance relative to its right-hand side, or once the no-slip residual
  /// it leaves, |r_u| after the step, is below `velocity_tolerance` [m/s] (inexact Newton: no
  /// need to solve far below what the Newton test asks).
  HydroSolveReport SolveNewtonSystem(const Model& model, const std::vector<BandedMatrix>& jacobian,
                                     double h, const VecX& r_q, const VecX& r_u, VecX* dq,
                                     VecX* df, VecX* du, double velocity_tolerance = 0.0);

  /// True when the factors must be rebuilt: the direct solve after 𝕄 changed, or a Krylov
  /// preconditioner gone stale (GMRES needed clearly more iterations than right after it was
  /// built). The integrator then rebuilds the Newton factors.
  bool wants_refresh() const { return wants_refresh_ || (!krylov_ && mobility_changed_); }

  /// Forgets the preconditioners kept across steps, as a fresh HydroCoupling would have none,
  /// and takes `drag_guess` (3M, or empty) as the explicit drag's first GMRES guess. After it the
  /// next steps depend only on the state, the guess and the dense 𝕄's reuse history
  /// (mobility_reuse_history, which is kept): the point a checkpoint resumes from.
  void ForgetReuse(const VecX& drag_guess);
  /// The dense 𝕄's reuse history (fluid/mobility_reuse.h) for a checkpoint, and taking it back.
  MobilityReuseHistory mobility_reuse_history() const { return mobility_->reuse_history(); }
  void RestoreMobilityReuse(const MobilityReuseHistory& history) { mobility_->RestoreReuse(history); }

  const MobilityOperator& mobility() const { return *mobility_; }
  /// The worst Krylov solve since the last call to ResetSolveReport (for failure messages).
  const HydroSolveReport& worst_solve() const { return worst_solve_; }
  void ResetSolveReport() { worst_solve_ = HydroSolveReport{}; }
  long krylov_iterations() const { return krylov_total_; }  ///< over the whole run
  long preconditioner_builds() const { return preconditioner_builds_; }  ///< over the whole run
  /// Whether the preconditioner's coarse level is one kept from an earlier build.
  bool coarse_kept() const { return capacitance_blocks_.coarse_kept(); }

 private:
  void ApplyCapacitance(const Model& model, double h, const VecX& v, VecX* out) const;
  void BuildSchurBlocks(const Model& model);
  void SolveBanded(const Model& model, const VecX& nodal, const VecX* dofs, VecX* out) const;
  const std::vector<BandedMatrix>* jacobian_ = nullptr;  ///< the factorized B of the last rebuild
  std::vector<ClampBorder>* borders_ = nullptr;  ///< of the last FactorizeNewtonSystem
  mutable VecX scratch_dofs_;
  void Precondition(const VecX& v, VecX* out) const;
  // At a rebuild: the rods' nodes about their centroids.
  void StartPreconditionerRotations();
  // R_k of each rod since the preconditioner was built (see above), at every Prepare; and since
  // its coarse level was, where that one is kept from an earlier build.
  void UpdatePreconditionerRotations(const Model& model);
  // R_k of each rod from its nodes `built` (about their centroids) to positions_.
  void RotationsSince(const Model& model, const std::vector<Matrix3X>& built,
                      RodRotations* q) const;

  std::unique_ptr<MobilityOperator> mobility_;
  std::vector<Matrix3X> positions_;  ///< at the last Prepare (the operator points into them)
  std::vector<BodySurface> bodies_;  ///< of the last SetBodies
  VecX body_velocity_;               ///< 3P, of the last SetBodies
  bool krylov_ = false;
  bool explicit_ = false;
  bool mobility_changed_ = true;   ///< 𝕄 was updated since the capacitance was factorized
  VecX explicit_force_;            ///< 3M
  std::vector<MatX> sx_blocks_;    ///< S_k B_k⁻¹ S_kᵀ (3N_k × 3N_k), for the preconditioner only
  // Direct: the LU of C; krylov: the preconditioner (the LU of C in single precision — a
  // preconditioner needs no more, and its solves stream half the memory —, or two levels).
  Eigen::PartialPivLU<MatX> capacitance_lu_;  ///< direct: the reference, Eigen's own LU
  DenseLu<float> capacitance_lu_float_;
  CapacitancePreconditioner capacitance_blocks_;  ///< blocks and coarse level
  bool block_preconditioner_ = false;
  int iterations_after_refresh_ = -1;
  bool have_preconditioner_ = false;
  double preconditioner_h_ = -1.0;
  int preconditioner_age_ = 0;     ///< steps (Prepare calls) since the preconditioner was built
  bool wants_refresh_ = false;
  bool rotate_preconditioner_ = false;
  std::vector<Matrix3X> preconditioner_positions_;  ///< the rods' nodes when it was built,
                                                    ///< about their centroids
  RodRotations preconditioner_rotations_;           ///< R_k; empty: applied as built
  // The matrix-free path's coarse level, kept across coarse_period_ builds of the preconditioner
  // (CoarseRebuildPeriod): the rods' nodes about their centroids at its build, the rods'
  // rotations since then (empty while it is the current build's), the builds that kept it (its
  // h is preconditioner_h_: a change of h rebuilds it).
  std::vector<Matrix3X> coarse_positions_;
  RodRotations coarse_rotations_;
  int builds_since_coarse_ = 0;
  int coarse_period_ = 1;
  bool slowed_severely_ = false;  ///< the last solve took more than twice the rebuild's products
  int excess_products_ = 0;  ///< GMRES products beyond the first solve's since the rebuild
  long preconditioner_builds_ = 0;
  long krylov_total_ = 0;
  HydroSolveReport worst_solve_;
  DenseLu<double> explicit_lu_;  ///< the explicit coupling's LU of a dense 𝕄 (every step)
  // The explicit coupling's solve with a matrix-free 𝕄: block LU of the self-mobilities.
  std::unique_ptr<SelfMobilityPreconditioner> explicit_blocks_;
  int explicit_blocks_age_ = 0;
  mutable VecX scratch_;
};

/// Gathers the node velocities (x − x_start)/h of all rods into a 3M vector.
void GatherNodeVelocities(const Model& model, const VecX& q, const VecX& q_start, double h,
                          VecX* u);

/// Each rod's Newton matrix solved in place on its DOFs of x (the model's DOFs): B_k⁻¹ x_k. The
/// rods are split among the threads as a static OpenMP loop splits them, and each thread's rods
/// are solved two at a time (SolveEach: bit for bit each rod's own Solve).
void SolveRodsBanded(const Model& model, const std::vector<BandedMatrix>& jacobian, VecX* x);

/// How many rebuilds of the block preconditioner one build of its coarse level serves, for
/// `coarse_unknowns` (E's size) and M nodes (model.hydro.coarse_rebuild_period 0: by this). E's
/// LU costs (2/3) n_c³ flops, a GMRES product O(M): the coarse rebuild in products grows as
/// n_c³ / M (as R² for R rods), and with its staleness growing steadily from its build the
/// period that minimizes rebuilds plus extra products goes as the square root of that cost:
/// round(√(n_c³ / (κ M))), κ = kCoarseKeepScale, 1 at a hundred helices (where the age limit of
/// 40 steps for both levels was measured to pay), 2 at two hundred, 4 at four hundred.
int CoarseRebuildPeriod(int coarse_unknowns, int nodes);

/// The mobility operator of the model: model.hydro.mobility's, with the bodies' points behind a
/// matrix-free one (fluid/mobility_sources.h).
std::unique_ptr<MobilityOperator> MakeModelMobility(const Model& model);

/// The hydrodynamic rods (positions at q) as the fluid module sees them.
std::vector<HydroRod> MakeHydroRods(const Model& model, const std::vector<Matrix3X>& positions);

}  // namespace stokesrods
