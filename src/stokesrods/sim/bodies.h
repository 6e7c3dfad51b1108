// The cell bodies of a model in time (issue 11): pose, surface points and their velocities. A
// "fixed" or "prescribed" body's motion is known, so its pose at time t is a closed form (no
// state to integrate or checkpoint):
//     c(t) = c(0) + U t,   R(t) = exp(t [Ω]×),   x_j(t) = c(t) + R(t) X_j,
//     u_j = U + Ω × (x_j(t) − c(t)).
// In the drag vector (3(M + P), sim/hydro_coupling.h) body k's points follow all rods' nodes from
// M + body.point_offset; f there is the force of the fluid on the body's surface points.
#pragma once

#include <vector>

#include "stokesrods/common/types.h"
#include "stokesrods/fluid/rigid_body.h"
#include "stokesrods/sim/model.h"

namespace stokesrods {

Vec3 BodyCenterAt(const BodyModel& body, double time);
Mat3 BodyRotationAt(const BodyModel& body, double time);

/// The surfaces of all bodies at `time` (their points and blobs), in model order.
std::vector<BodySurface> BodySurfacesAt(const Model& model, double time);

/// The rigid velocities of all body points at `time` (3P) [m/s].
VecX BodyPointVelocities(const Model& model, double time);

/// Force and torque (about the centre at `time`) of the fluid on body k from the drag vector f
/// (3(M + P)) [N, N·m].
Vec6 BodyHydroLoad(const Model& model, int body, double time, const VecX& f);

}  // namespace stokesrods
