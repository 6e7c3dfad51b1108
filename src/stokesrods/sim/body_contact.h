// Contact of the cell bodies with each other and with the wall (issue 11), in the same multiplier
// solve and rounds as the rods' contacts (contact_forces.h, obstacle_contact.h).
//
// Two spheres a and b are a pair when their centres are closer than a_a + a_b (the surfaces
// touch); a sphere and the wall when its centre is closer to the plane than its radius. At least
// one side must be free: fixed and prescribed bodies move as they are told, and nothing could
// resolve a pair of two of them. A pair's force acts along the line of centres (the wall's
// normal), on the body pushed away +F n, on the other −F n, each at its own surface point; for
// spheres the arms are parallel to n, so no torque. Its trial magnitude is the drag that moves a
// lone sphere of the smaller radius a by the penetration ε within the step, F = 6πμ a ε/h (as
// eq. 20's m Δx/h² for the rods' nodes: the multiplier solve scales it). The separation changes
// by n·(δx_b − δx_a) under the response, δx = h (δU + δΩ × (p − c)) of a free body at its
// contact point p, 0 for the others and the wall. The bodies are massless, so every load a pair
// puts on them enters their balance of force and torque (sim/hydro_coupling.h), as the clamps'
// and the rods' contacts do.
#pragma once

#include <vector>

#include "stokesrods/common/types.h"
#include "stokesrods/sim/model.h"
#include "stokesrods/sim/state.h"

namespace stokesrods {

struct BodyPair {
  int body = 0;                  ///< model index of the body pushed along `normal`
  int other = -1;                ///< the body pushed along −normal; −1: the wall
  Vec3 normal = Vec3::UnitZ();   ///< from the other (or the wall) towards `body`, unit
  double penetration = 0.0;      ///< contact distance − distance > 0 [m]
  double contact_distance = 0.0; ///< a + a' (a against the wall) [m]
};

/// The pairs of bodies at `poses` that touch each other or the wall (model.fluid.wall), with at
/// least one free side.
std::vector<BodyPair> DetectBodyContacts(const Model& model, const std::vector<BodyPose>& poses);

/// The loads (force, torque about the centre; 6 per free body, added into `loads`) of the pair's
/// force of magnitude `magnitude` [N] on its free sides.
void AddBodyPairLoads(const Model& model, const BodyPair& pair, double magnitude,
                      const std::vector<BodyPose>& poses, VecX* loads);

/// The pair's trial force magnitude 6πμ a ε / h [N] (a the smaller radius).
double BodyPairTrialForce(const Model& model, const BodyPair& pair, double h);

/// The change of the pair's separation along its normal when the free bodies' (U, Ω) change by
/// dv (6 per free body) for a step of size h [m].
double BodyPairSeparationChange(const Model& model, const BodyPair& pair,
                                const std::vector<BodyPose>& poses, double h, const VecX& dv);

/// The displacement in a step of size h of the point x of body k when the free bodies' (U, Ω)
/// change by dv (0 for fixed and prescribed bodies and for k = −1, the wall) [m].
Vec3 BodyPointShift(const Model& model, int k, const std::vector<BodyPose>& poses,
                    const Vec3& x, double h, const VecX& dv);

}  // namespace stokesrods
