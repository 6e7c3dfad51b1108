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

/// Moves the clamps of rods on moving bodies (prescribed, or free with a guess of V) from the
/// poses `from` to `to`: the clamped nodes rigidly with the body, and θ0 by the body's spin about
/// the first edge (the angle about the new tangent between the parallel transport of the old frame
/// and its rigid rotation), on top of the motor's turn relative to the body (DriveBoundaryConditions).
void DriveBodyClamps(const Model& model, const std::vector<BodyPose>& from,
                     const std::vector<BodyPose>& to, VecX* q);

/// The clamps of rods on free bodies at the end of a step from `start_q` and `start_poses` with the
/// bodies' V in f: Φ(V) of sim/clamp_border.h, as Step's DriveBoundaryConditions and
/// DriveBodyClamps place them (the motor's turn, then the body's rigid motion).
void PlaceFreeClamps(const Model& model, const VecX& start_q,
                     const std::vector<BodyPose>& start_poses, double h, const VecX& f, VecX* q);

/// Force and torque (about the centre) of the fluid on body k at `pose` from f [N, N·m].
Vec6 BodyHydroLoad(const Model& model, int body, const BodyPose& pose, const VecX& f);

}  // namespace stokesrods
