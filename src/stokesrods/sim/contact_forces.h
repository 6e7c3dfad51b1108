// Contact between rods (paper section 2.3, eqs. 17–20, Algorithm 1), as forces in the step.
//
// After a Newton solve, every pair of segments (of different rods, or non-adjacent segments of
// one rod) closer than r_a + r_b is found; the displacements that would remove the penetration
// (contact/contact_response.h) become forces F = m Δx / h² (eq. 20) that are added to the
// contact force of the step, and the step is solved again, until no pair penetrates by more than
// the tolerance. Clamped nodes never move.
#pragma once

#include <limits>

#include "stokesrods/sim/model.h"

namespace stokesrods {

struct ContactSummary {
  int active = 0;    ///< pairs closer than the contact distance (1 − tolerance)
  int detected = 0;  ///< pairs closer than the contact distance (those that receive forces)
  /// Smallest center-line distance between segments of different rods [m] (∞ for one rod).
  double min_distance = std::numeric_limits<double>::infinity();
  double max_penetration = 0.0;  ///< largest (r_a + r_b − distance) over all pairs, ≥ 0 [m]
};

/// Segments of one rod closer than this many indices apart are never in contact with each other.
int SelfContactExclusion(const RodModel& rod);

/// Measures the contacts at q without changing anything (min_distance is left at ∞: it needs
/// all pairs, see MinDistanceBetweenRods).
ContactSummary MeasureContacts(const Model& model, const VecX& q);

/// Smallest center-line distance between segments of different rods at q, over all pairs [m]
/// (∞ with a single rod).
double MinDistanceBetweenRods(const Model& model, const VecX& q);

/// Detects the pairs closer than the contact distance at q. If any penetrates by more than the
/// tolerance (model.newton.contact_tolerance × contact distance), adds the forces m Δx / h² of all
/// detected pairs to `contact_force` (global, like q); forces accumulate over the rounds of a step.
/// Returns what it found before the correction (active = 0 means resolved).
ContactSummary AddContactForces(const Model& model, const VecX& q, double h,
                                VecX* contact_force);

}  // namespace stokesrods
