// Contact of rods with the wall and the cell bodies (issue 11), beside the rods' contact with each
// other (contact_forces.h), in the same solve–detect–re-solve rounds of a step.
//
// Node-based: a rod node x closer than the rod's radius r0 to an obstacle is a pair, its distance
// d = n·(x − p) to the wall (n its unit normal into the fluid) or |x − c| − a to a sphere, its
// normal n or (x − c)/|x − c|, its penetration r0 − d. The obstacle does not give way in the
// displacement that removes the penetration (x ← x + (r0 − d) n, eq. 20's F = m Δx / h² on the
// node), and the force's multiplier is solved with the rods' pairs (W λ = ε). A pair's separation
// changes by n·δx under the response δx. Clamped nodes are never in such a pair (a clamp sits on
// its body). On a free body the force's reaction −F at the contact point enters its balance of
// force and torque (momentum is conserved); a fixed or prescribed body or the wall takes it.
// Node-based contact misses a segment's midpoint only by the sagitta of an edge over the sphere,
// ℓ²/(8a) (0.14 mm for the paper's 4.8 mm edges on a 2 cm body), and never on the plane.
#pragma once

#include <vector>

#include "stokesrods/common/types.h"
#include "stokesrods/sim/model.h"
#include "stokesrods/sim/state.h"

namespace stokesrods {

struct ObstaclePair {
  int rod = 0;
  int node = 0;
  int body = -1;              ///< model index; −1: the wall
  Vec3 normal = Vec3::UnitZ();  ///< out of the obstacle, at the node
  Vec3 point = Vec3::Zero();    ///< the obstacle's surface point closest to the node [m]
  double penetration = 0.0;     ///< r0 − d > 0 [m]
};

/// The rods' free nodes closer than their radius to the wall (model.fluid.wall) or a body at
/// `poses`.
std::vector<ObstaclePair> DetectObstacleContacts(const Model& model, const VecX& q,
                                                 const std::vector<BodyPose>& poses);

/// The force and torque (about the centre at `poses`) that `force` on the pair's node exerts, by
/// reaction, on a free body (6 per free body, added into `loads`); nothing for other obstacles.
void AddObstacleReaction(const Model& model, const ObstaclePair& pair, const Vec3& force,
                         const std::vector<BodyPose>& poses, VecX* loads);

}  // namespace stokesrods
