// Contact between rods (paper section 2.3, eqs. 17–20, Algorithm 1), as forces in the step.
//
// After a Newton solve, every pair of segments (of different rods, or non-adjacent segments of
// one rod) closer than r_a + r_b is found; the displacements that would remove the penetration
// (contact/contact_response.h) become forces F = m Δx / h² (eq. 20) that are added to the
// contact force of the step, and the step is solved again, until no pair penetrates by more than
// the tolerance. Clamped nodes never move.
#pragma once

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "stokesrods/contact/broad_phase.h"
#include "stokesrods/sim/model.h"
#include "stokesrods/sim/state.h"

namespace stokesrods {

struct ContactSummary {
  int active = 0;    ///< pairs closer than the contact distance (1 − tolerance)
  int detected = 0;  ///< pairs closer than the contact distance (those that receive forces)
  /// Smallest center-line distance between segments of different rods [m] (∞ for one rod).
  double min_distance = std::numeric_limits<double>::infinity();
  double max_penetration = 0.0;  ///< largest (r_a + r_b − distance) over all pairs, ≥ 0 [m]
  /// Where that largest penetration is (meaningful when detected > 0): a segment pair (segment i
  /// of a rod joins its nodes i and i + 1, 0-based), or, when obstacle_node ≥ 0, node
  /// obstacle_node of rod deepest.a.rod against the wall (obstacle_body = −1) or a body.
  SegmentPair deepest;
  int obstacle_node = -1;
  int obstacle_body = -1;
  int deepest_body = -1;  ///< when ≥ 0: body deepest_body against obstacle_body (−1: the wall)
  double deepest_contact_distance = 0.0;  ///< r_a + r_b, or r0 against an obstacle [m]
};

/// "rod 1, segment 14 (nodes 14-15) against rod 2, segment 9 (nodes 9-10)", "rod 1, node 3
/// against the wall" or "body 1 against body 2" (rods and bodies from 1, nodes from 0).
std::string DescribeDeepest(const ContactSummary& summary);

/// Segments of one rod closer than this many indices apart are never in contact with each other.
int SelfContactExclusion(const RodModel& rod);

/// Measures the contacts at q without changing anything (min_distance is left at ∞: it needs
/// all pairs, see MinDistanceBetweenRods).
ContactSummary MeasureContacts(const Model& model, const VecX& q);

/// Smallest center-line distance between segments of different rods at q, over all pairs [m]
/// (∞ with a single rod).
double MinDistanceBetweenRods(const Model& model, const VecX& q);

/// The linear response of the step to an extra force F on the rods' DOFs and loads L on the free
/// bodies (force and torque about the centre, 6 each; empty without free bodies): the change dq
/// of q and dv of the free bodies' (U, Ω) (6 each) that J (the Newton matrix) gives them.
using LinearResponse =
    std::function<void(const VecX& force, const VecX& body_load, VecX* dq, VecX* dv)>;

/// Detects the pairs closer than the contact distance at q. If any penetrates by more than the
/// tolerance (model.newton.contact_tolerance × contact distance), adds contact forces for all
/// detected pairs to `contact_force` (global, like q); forces accumulate over the rounds of a step.
/// Each pair k gets a force along its normal distributed as eq. 19–20 distribute the displacement
/// (F_k = m Δx_k / h² for its own pair alone), scaled by λ_k ≥ 0 so that, to first order, every
/// penetration ε_j is removed: Σ_k W_jk λ_k = ε_j, with W_jk the change of the separation of pair
/// j under dq = J⁻¹ F_k. When inertia dominates J (J ≈ M/h²), λ = 1 and this is eq. 20 itself;
/// when the rod's stiffness or drag dominate, eq. 20 alone would close only a fraction
/// m/(h² J) of the gap per round. Returns what it found before the correction (active = 0 means
/// resolved).
/// The rods' contacts with the wall and the bodies at `poses` (obstacle_contact.h) and the bodies'
/// with each other and the wall (body_contact.h) join the same multipliers, W including the free
/// bodies' motion under each pair's loads; those loads accumulate in `body_loads` (6 per free
/// body). `candidates`: the broad phase kept across calls (CandidatePairList), or null.
ContactSummary AddContactForces(const Model& model, const VecX& q, double h,
                                const LinearResponse& respond, VecX* contact_force,
                                const std::vector<BodyPose>& poses = {},
                                VecX* body_loads = nullptr,
                                CandidatePairList* candidates = nullptr);

}  // namespace stokesrods
