// The time step (paper section 2.4, Algorithm 1) and the static solve.
//
// One step of implicit Euler (eq. 22) or BDF2 solved by Newton's method (Jacobian eq. 23 plus the
// Jacobians of the implicit external forces):
//     r(q) = M (q − q_k − h v_k) / h² − F_int(q) − F_ext(q) − F^h − F^c = 0,
// q_{k+1} = q, v_{k+1} = (q_{k+1} − q_k)/h; with a nonlocal fluid and the implicit coupling the
// drag F^h = f is an unknown beside q with its no-slip equation (sim/hydro_coupling.h). Step never
// prints, writes files or exits: failures come back as a report, and the state is left as it was
// before the step.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "stokesrods/sim/bodies.h"
#include "stokesrods/sim/clamp_border.h"
#include "stokesrods/sim/contact_forces.h"
#include "stokesrods/sim/forces.h"
#include "stokesrods/sim/hydro_coupling.h"
#include "stokesrods/sim/model.h"
#include "stokesrods/sim/state.h"
#include "stokesrods/solver/banded_matrix.h"

namespace stokesrods {

struct NewtonReport {
  bool converged = false;
  int iterations = 0;
  double residual = 0.0;   ///< weighted ∞-norm of r at the last iterate [N]
  double tolerance = 0.0;  ///< what it had to reach [N]
  int krylov_iterations = 0;
  int damped_iterations = 0;     ///< iterations whose step the line search shortened (α < 1)
  double last_reduction = 1.0;   ///< residual after / before the last iteration
};

struct StepReport {
  bool ok = false;
  std::string message;       ///< why it failed (empty on success)
  int newton_iterations = 0; ///< summed over contact rounds
  int contact_rounds = 0;
  int contact_pairs = 0;     ///< most pairs that received contact forces in one round
  int krylov_iterations = 0; ///< GMRES products with the capacitance (implicit nonlocal drag)
  ContactSummary contact;    ///< at the end of the step
};

/// Scratch reused from step to step (MuJoCo's mjData scratch): nothing in the loop allocates
/// once the sizes are set.
struct Workspace {
  explicit Workspace(const Model& model);

  std::vector<std::unique_ptr<ExternalForce>> local_forces;
  HydroCoupling hydro;
  bool nonlocal_fluid = false;   ///< RSS or LSBT
  /// The drag on the nodes (3M) [N]: implicit coupling, an unknown of the Newton iterate beside q
  /// (kept from step to step as the first guess); explicit, the constant of the step.
  VecX hydro_force, hydro_force_try;
  VecX velocity_residual, velocity_residual_try;  ///< r_u at the iterate and at the trial
  VecX hydro_delta, hydro_rate, simplified_hydro_delta, simplified_hydro_rate;  ///< δf, du
  /// Rods clamped to free bodies (sim/clamp_border.h): the border of the last Evaluate with the
  /// Jacobian, and the clamps' loads G_cᵀ λ on the bodies (6 per free body) of the last Evaluate.
  bool free_clamps = false;
  std::vector<ClampBorder> clamp_borders;
  VecX clamp_loads;
  VecX q;                        ///< the Newton iterate q(t_{k+1})
  VecX q_try;                    ///< line-search trial
  std::vector<RodFrames> frames; ///< frames transported to q
  std::vector<RodFrames> frames_try;
  VecX force;                    ///< F_int + F_ext + F^h + F^c at q (after a converged solve)
  VecX residual, residual_try, delta, simplified;
  VecX contact_force;            ///< F^c, constant during a Newton solve
  CandidatePairList contact_candidates;  ///< the contact's broad phase, kept across steps
  /// The loads on the free bodies (force, torque about the centre; 6 each), constant in a Newton
  /// solve: their own (BodyModel::force, torque) and the contacts' reactions.
  VecX body_load;
  VecX previous_velocity;        ///< q̇(t_{k−1}), for the predictors and BDF2
  VecX previous_q;               ///< q(t_{k−1}), for BDF2
  double previous_h = 0.0;       ///< the step that led to t_k
  VecX older_velocity;           ///< q̇(t_{k−2}), for the cubic predictor (empty when unknown)
  double older_h = 0.0;          ///< the step that led to t_{k−1}
  /// The cubic predictor came closer to the last step's solution than the damped one (Predict):
  /// this step's Newton starts from it.
  bool cubic_predictor = false;
  double damped_miss = 0.0;      ///< how far the damped predictor missed the last step [m]
  VecX damped_guess, cubic_guess;  ///< this step's two predictors
  bool have_cubic_guess = false;   ///< cubic_guess is this step's (implicit Euler, history known)
  VecX edge_lengths;               ///< the lengths Newton's first guess gets (ExtrapolateEdgeLengths)
  bool used_cubic = false;       ///< this step's Newton started from the cubic predictor
  /// The implicit drag at t_{k−1} and t_{k−2}, of steps of size previous_h (empty when unknown):
  /// the next step's first guess extrapolates the drag through them (PredictDrag).
  std::array<VecX, 2> earlier_drags;
  VecX drag_at_start;            ///< the drag at t_k (3M), restored when the step fails
  bool drag_extrapolated = false; ///< this step's first guess of the drag was extrapolated
  bool extrapolate_drag = true;   ///< off while a failed step is retried from f_k (Step)
  std::vector<BodyPose> previous_poses;  ///< the bodies at t_{k−1}, for BDF2
  BodyStep body_step;            ///< how the bodies move in the step (sim/bodies.h)
  State step_start;              ///< the start of the step in implicit Euler's form (see Step)
  State step_geometry;           ///< BDF2: the predictor, where 𝕄 and the local drag are taken
  std::vector<BandedMatrix> jacobian;  ///< per rod
  double load_factor = 1.0;      ///< static load continuation
  // Reuse of the factorized Newton matrix across iterations and steps (modified Newton).
  bool factors_valid = false;    ///< ws.jacobian (and the capacitance's data) hold usable factors
  double factors_h = -1.0;       ///< the step size they were built for (0: static)
  int factors_age = 0;           ///< steps since they were built
  int last_iterations = 0;       ///< Newton iterations of the last converged solve
  /// The last converged solve took one full step that met the tolerance (no simplified
  /// correction): its factors may serve the next step (SolveNewton).
  bool last_clean = false;
  /// Steps before kept factors may serve again, after steps that kept them and were not clean
  /// (SolveNewton), and the wait after the last such step (doubled by each, cleared by a clean one).
  int reuse_wait = 0;
  int reuse_backoff = 0;
};

/// What the next step reads from the steps before it, besides the State: BDF2's history and the
/// drag's first guess. A checkpoint saves it with the State (io/checkpoint.h).
struct StepHistory {
  VecX previous_q;          ///< q(t_{k−1}) (empty before the first step)
  VecX previous_velocity;   ///< q̇(t_{k−1})
  double previous_h = 0.0;  ///< [s]
  VecX older_velocity;      ///< q̇(t_{k−2}) (empty when unknown)
  double older_h = 0.0;     ///< [s]
  bool cubic_predictor = false;  ///< the predictor of the next step (Workspace)
  double damped_miss = 0.0;      ///< [m] (Workspace)
  VecX hydro_force;         ///< the nodal drag of the last step (3M; empty without a nonlocal fluid)
  std::array<VecX, 2> earlier_drags;  ///< the drag at t_{k−1}, t_{k−2} (Workspace)
  std::vector<BodyPose> previous_poses;  ///< the bodies at t_{k−1} (empty before the first step)
  MobilityReuseHistory mobility_reuse;   ///< the dense 𝕄's reuse (assembled again on restore)
};
StepHistory CaptureHistory(const Workspace& ws);
void RestoreHistory(const StepHistory& history, Workspace* ws);

/// Forgets every factorization and preconditioner kept across steps (the Newton matrix and its
/// age, the Krylov preconditioner of the drag): the next step rebuilds them, as it would in a
/// fresh Workspace. A run calls it at each checkpoint, so that a run resumed from the checkpoint
/// (a fresh Workspace with the saved StepHistory) steps exactly as the uninterrupted one. The
/// dense 𝕄's reuse is not forgotten: its history is in the StepHistory, and RestoreHistory
/// assembles its matrices again.
void ForgetReuse(Workspace* ws);

/// The lengths the predictor's guess q(t_{k+1}) gives each edge (SetEdgeLengths), extrapolated
/// linearly from q_before (q_{k−1}, of a step of the same h) and q_start (q_k): 2|e_k| − |e_{k−1}|,
/// or |e_k| without q_before; edge i of a rod at rod.node_offset + i of `lengths` (num_nodes).
/// A polynomial through node positions that turn by a sizeable angle per step changes the
/// edges' chords, and the stretching residual that makes (EA ≫ EI/L²) is most of what Newton then
/// undoes. The lengths are extrapolated, not kept: the edges do stretch in time, and at small
/// steps setting them back to |e_k| moved a close guess by more than it missed (on paper Fig. 1
/// at h = 1 ms, kept Newton factors then took 1.5 iterations per step instead of 1.0).
void ExtrapolateEdgeLengths(const Model& model, const VecX& q_start, const VecX* q_before,
                            VecX* lengths);

/// Each edge of the guess q set to its length in `lengths` (ExtrapolateEdgeLengths), walked from
/// the rod's first node: each edge from its first node (as placed) towards its second node's
/// guessed position; a fixed node left where the step drives it (the next edge starts there);
/// twist angles as guessed; rods clamped on bodies as they are.
void SetEdgeLengths(const Model& model, const VecX& lengths, VecX* q);

/// What depends on the start of a step only: the local forces' caches, the mobility 𝕄 at q_k (and
/// the explicit drag), the contact force reset. Step calls it; Evaluate needs it first.
void PrepareStep(const Model& model, const State& start, Workspace* ws);

/// The residual r_q(q, f) of the step from `start` (h = 0: the static problem, without inertia
/// and velocity-dependent forces) with the frames transported to q into `frames`, and, when
/// `with_jacobian`, the per-rod banded Jacobians ∂r_q/∂q in ws->jacobian. `hydro_force` is the
/// nodal drag f (3M) of a nonlocal fluid model (ignored otherwise); with the implicit coupling it
/// is an unknown beside q, its equation r_u = 0 is HydroCoupling's. Fixed DOFs: r = 0, identity rows.
void Evaluate(const Model& model, const State& start, double h, const VecX& q,
              const VecX& hydro_force, bool with_jacobian, Workspace* ws,
              std::vector<RodFrames>* frames, VecX* residual);

/// The drive of the boundary conditions: the target values of the fixed DOFs at t_k + h
/// (θ0 ← θ0 + h ω' for driven rods, everything else held).
void DriveBoundaryConditions(const Model& model, double h, VecX* q);

/// One step of size h from `state` (Algorithm 1 with the contact rounds): implicit Euler, or
/// BDF2 when model.integrator says so and the previous step (same h) is known.
StepReport Step(const Model& model, double h, State* state, Workspace* ws);

/// Static equilibrium F_int + F_ext = 0 under the loads and boundary conditions, by Newton with
/// line search and load continuation. Velocity-dependent forces and inertia are absent.
StepReport SolveStatic(const Model& model, State* state, Workspace* ws);

/// Generalized force on the fixed DOFs summed per rod (paper eq. 25): the sum of elastic and
/// external forces on the clamped nodes (force) and their moment about ẑ through node 0,
/// including the twist moment on θ0 (torque_z). Uses ws.force of the last converged solve.
struct ClampLoad {
  Vec3 force = Vec3::Zero();
  double torque_z = 0.0;
};
ClampLoad CalcClampLoad(const Model& model, const State& state, const Workspace& ws, int rod);

}  // namespace stokesrods
