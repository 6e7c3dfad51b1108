// The cell bodies of a model in time (issue 11): poses, surface points and their velocities.
// A body's pose (State::bodies) is its centre c and rotation R; its points are x_j = c + R X_j.
// A step of size h moves it rigidly with the (U, Ω) of the step, known ("fixed", "prescribed") or
// solved ("free"):  c ← c + h U,  R ← exp(h [Ω]×) R  (exact for constant U, Ω).
// In the hydrodynamic unknown f (3(M + P) + 6B, sim/hydro_coupling.h) body k's points follow all
// rods' nodes from M + body.point_offset (the force of the fluid on each point), and the free
// bodies' (U, Ω) come last, 6 per free body.
#pragma once

#include <vector>

#include "stokesrods/common/types.h"
#include "stokesrods/fluid/rigid_body.h"
#include "stokesrods/sim/model.h"
#include "stokesrods/sim/state.h"

namespace stokesrods {

/// The surfaces of all bodies at their poses, in model order; free bodies are marked so.
std::vector<BodySurface> BodySurfaces(const Model& model, const std::vector<BodyPose>& poses);

/// The known rigid velocities of all body points at their poses (3P) [m/s]: U + Ω × (x − c) of
/// fixed and prescribed bodies; 0 for free ones (their motion is an unknown of the step).
VecX BodyPointVelocities(const Model& model, const std::vector<BodyPose>& poses);

/// (U, Ω) of body k in the step that gave the hydrodynamic unknown f (free: read from f).
Vec6 BodyVelocity(const Model& model, int body, const VecX& f);

/// The poses after a step of size h with the velocities of f.
void AdvanceBodies(const Model& model, double h, const VecX& f, std::vector<BodyPose>* poses);

/// How the bodies move in one step of the integrator (docs/model.md, "Rods on a free body").
/// Every step is solved in implicit Euler's form: a free body goes from `start` by h_e V,
///   c_{k+1} = c̃ + h_e U,   R_{k+1} = exp(h_e [Ω]×) R̃,
/// with (c̃, R̃) its pose at t_k and h_e = h (implicit Euler) or Bdf2StartPose and h_e = 2h/3
/// (BDF2). Fixed and prescribed bodies go from t_k by h V (exact for their constant motion). The
/// clamps of rods on a body are moved rigidly from its pose at t_k (`current`, `current_q`).
struct BodyStep {
  std::vector<BodyPose> current;   ///< at t_k
  std::vector<BodyPose> start;     ///< the free bodies' start in implicit Euler's form
  std::vector<BodyPose> geometry;  ///< where 𝕄, the bodies' points and the balances' torques are
                                   ///< taken: t_k (implicit Euler) or the predictor (BDF2)
  VecX current_q;                  ///< q at t_k (with rods on free bodies: their clamps' origin)
  double h = 0.0;                  ///< the step [s] (the motors turn by h ω')
  double he = 0.0;                 ///< its implicit-Euler form [s]
};

/// BDF2's start pose from the poses at t_k and t_{k−1}: c̃ = (4c_k − c_{k−1})/3 and
/// R̃ = exp(−[φ]×/3) R_k, φ = log(R_{k−1} R_kᵀ) the rotation vector from R_k back to R_{k−1}
/// (BDF2 on the rotation vector relative to R_k, whose value at t_k is 0).
BodyPose Bdf2StartPose(const BodyPose& current, const BodyPose& previous);

/// The poses at the end of `step` with the velocities of f.
void EndPoses(const Model& model, const BodyStep& step, const VecX& f,
              std::vector<BodyPose>* poses);

/// Moves the clamps of rods on moving bodies (prescribed, or free with a guess of V) from the
/// poses `from` to `to`: the clamped nodes rigidly with the body, and θ0 by the body's spin about
/// the first edge (the angle about the new tangent between the parallel transport of the old frame
/// and its rigid rotation), on top of the motor's turn relative to the body (DriveBoundaryConditions).
void DriveBodyClamps(const Model& model, const std::vector<BodyPose>& from,
                     const std::vector<BodyPose>& to, VecX* q);

/// The clamps of rods on free bodies at the end of `step` with the bodies' V in f: Φ(V) of
/// sim/clamp_border.h, as Step's DriveBoundaryConditions and DriveBodyClamps place them (the
/// motor's turn by h ω', then the body's rigid motion from its pose at t_k to EndPoses').
void PlaceFreeClamps(const Model& model, const BodyStep& step, const VecX& f, VecX* q);

/// Force and torque (about the centre) of the fluid on body k at `pose` from f [N, N·m].
Vec6 BodyHydroLoad(const Model& model, int body, const BodyPose& pose, const VecX& f);

}  // namespace stokesrods
