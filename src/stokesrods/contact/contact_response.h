// Contact detection and the displacement response of paper section 2.3 (eqs. 17–20).
//
// DetectContacts finds every pair of segments closer than the sum of their rods' radii (eq. 18 with
// r_a + r_b in place of 2 r0); AddContactDisplacements turns one contact into nodal displacements
// that remove its penetration depth (eq. 19 as we read it, see below). The caller turns them into
// forces F_i = m_i Δx_i / h² (eq. 20) and re-solves the step (Algorithm 1).
#pragma once

#include <vector>

#include "stokesrods/common/types.h"
#include "stokesrods/contact/broad_phase.h"
#include "stokesrods/contact/segment_distance.h"

namespace stokesrods {

/// One penetrating pair of segments.
struct ContactPair {
  SegmentPair segments;           ///< a < b lexicographically; a = (rod, i) joins nodes i, i+1
  SegmentClosestPoints closest;   ///< p = (1 − s) x_a,i + s x_a,i+1, q likewise on b; δ_min [m]
  double contact_distance = 0.0;  ///< r_a + r_b [m]
  double penetration = 0.0;       ///< ε = contact_distance − δ_min > 0 [m]  (paper eq. 18)
  Vec3 normal = Vec3::UnitX();    ///< unit, from p towards q (see CalcContactNormal)
};

/// Unit normal of a contact between segments (a0, a1) and (b0, b1) with closest points `closest`:
/// (q − p)/|q − p| when δ_min > 1e-9 (r_a + r_b) (plus coordinate round-off). Otherwise, in order:
///  1. `previous_normal` (the pair's normal at the previous detection) when given: it remembers on
///     which side each segment was before they met;
///  2. the common perpendicular d_a × d_b of crossing segments (angle > 1e-6), oriented along the
///     vector from the middle of a to the middle of b (or, if perpendicular to it, so that its
///     largest component is positive);
///  3. for (anti)parallel or zero-length segments, the part of (middle of b − middle of a)
///     perpendicular to the longer segment, if above the coordinates' round-off; else a fixed unit
///     vector perpendicular to it (x if both have zero length).
/// Case 2 and 3 are not continuous in the input (no normal at distance 0 can be); the caller keeps
/// continuity across steps by passing the previous normal.
Vec3 CalcContactNormal(const Vec3& a0, const Vec3& a1, const Vec3& b0, const Vec3& b1,
                       const SegmentClosestPoints& closest, double contact_distance,
                       const Vec3* previous_normal = nullptr);

/// All pairs of segments with δ_min < r_a + r_b (paper eqs. 17–18), found by the broad phase with
/// margin max(radii) and then the exact segment distance, sorted by `segments`.
///  - rods[r] holds the nodes of rod r (3 × N_r, [m]); radii[r] > 0 its radius [m].
///  - Self-contact: segments i, j of the same rod pair only when |i − j| > self_exclusion ≥ 0.
///    Segments that share a node are always at distance 0, so self_exclusion ≥ 1 is needed, and
///    about ⌈(r_a + r_b)/edge length⌉ + 1 for a rod that bends.
///  - A contact at a shared node is reported once: a pair whose closest point is the first node of
///    a segment (s = 0, or t = 0) is dropped when the pair with the preceding segment is itself
///    eligible, since that pair contains the same point, so is at least as close and is reported
///    (or itself hands the contact further down). Without this, a kink pointing at another rod
///    would be pushed twice.
///  - previous: the contacts of the previous detection (sorted, as returned), used for the normal
///    of pairs at distance ~0 (CalcContactNormal); may be null.
///  - candidates: a broad phase kept across calls (CandidatePairList, broad_phase.h), or null for
///    a new one (FindCandidatePairs); the contacts found are the same either way.
std::vector<ContactPair> DetectContacts(const std::vector<const Matrix3X*>& rods,
                                        const std::vector<double>& radii, int self_exclusion,
                                        const std::vector<ContactPair>* previous = nullptr,
                                        CandidatePairList* candidates = nullptr);

/// Adds to `displacements` (3 × N_r per rod, [m]) the nodal displacements that remove the
/// penetration of `contact`:
///   Δx_k = (ε / W) w_k c_k n,   W = Σ_k w_k c_k²,
/// over the four nodes k = (a_i, a_i+1, b_j, b_j+1) with barycentric coefficients
/// c = (−(1 − s), −s, 1 − t, t) and inverse masses w_k = inverse_masses[rod](node) [1/kg].
/// This is the smallest mass-weighted displacement, Σ m_k |Δx_k|² minimal, that moves the contact
/// point q − p by exactly ε n, i.e. the separation along n to r_a + r_b to first order:
///  - it is the normalized form of eq. 19. The paper writes Δx_i = −½ n_ij w_i with |n_ij| = δ_min,
///    which would move the nodes by the whole distance; we use the penetration depth ε (eq. 18).
///    Spreading d over the nodes with weights (1 − s, s) alone moves p by ((1 − s)² + s²) d,
///    down to d/2 at s = ½; dividing by W makes p and q move apart by exactly ε.
///  - with equal masses and s = t it is eq. 19: each side moves by ε/2, weighted (1 − s, s).
///  - momentum is conserved: Σ_k m_k Δx_k = 0 when all w_k > 0, as Σ_k c_k = 0.
///  - a clamped node has w_k = 0 and never moves; the other nodes take the whole displacement.
///    If all four nodes are clamped nothing is added.
/// Segments move along n and may tilt, so the new δ_min equals r_a + r_b up to O((ε/ℓ)²) relative
/// (exactly for s = t = ½); Algorithm 1 re-detects until no pair penetrates.
/// Displacements of several contacts add up (as the forces of eq. 20 do): a node pushed by two
/// contacts in the same direction moves by the sum.
/// Preconditions (asserted): inverse_masses[r].size() == displacements[r].cols() == N_r, w_k ≥ 0.
void AddContactDisplacements(const ContactPair& contact, const std::vector<VecX>& inverse_masses,
                             std::vector<Matrix3X>* displacements);

/// Sum of AddContactDisplacements over `contacts`, starting from zero (3 × N_r per rod, N_r taken
/// from inverse_masses[r].size()).
std::vector<Matrix3X> CalcContactDisplacements(const std::vector<ContactPair>& contacts,
                                               const std::vector<VecX>& inverse_masses);

}  // namespace stokesrods
