// Lighthill slender body theory, discrete (paper appendix C, eq. C.2), in nodal forces F [N]:
//     u_q = (I − t_q t_qᵀ) F_q / (4πμΔ) + Σ_{p ≠ q} (1/8πμ|r|) (I + r rᵀ/|r|²) F_p,   r = x_q − x_p,
// Δ = 2δ = r0 √e the edge length the theory assumes (δ = r0√e/2 is Lighthill's cut-off: the
// Stokeslets within |s − s'| < δ are replaced by the local term, so with edges of exactly 2δ the
// cut-off interval around node q holds node q alone).
// Several rods: the local term belongs to the rod a node lies on (its own r0, its own tangent).
// For a node q of another rod there is no local term: the cut-off excludes a stretch of q's own
// filament, and another filament is never inside it, so its nodes act on q through their
// Stokeslets alone. This stays accurate only while the rods are apart by much more than Δ; when
// two rods come within ~Δ of each other the Oseen blocks grow like 1/|r| and the system becomes
// ill-conditioned (paper, section 4) — use RSS there.
#pragma once

#include <vector>

#include "stokesrods/common/types.h"
#include "stokesrods/fluid/hydrodynamics.h"

namespace stokesrods {

/// Δ = r0 √e [m]: the edge length LSBT assumes for a rod of radius r0 [m].
double LsbtEdgeLength(double radius);

/// Whether a rod's edges fit LSBT: |e_i|/Δ − 1 within ±tolerance for every edge.
struct LsbtDiscretizationCheck {
  bool fits = false;
  double target_edge_length = 0.0;      ///< Δ = r0 √e [m]
  double max_relative_deviation = 0.0;  ///< max_i | |e_i|/Δ − 1 |
  int worst_edge = -1;                  ///< index of that edge
  int edges_outside = 0;                ///< edges off by more than the tolerance
  int suggested_nodes = 0;              ///< N = 1 + round(arc length / Δ) for even edges
};

/// Checks the polyline x (3 × N, N ≥ 2) of radius r0 [m] against Δ = r0 √e with a relative
/// tolerance [–]. Note the paper's helix always has one edge (x1 → x2, length R√2) far from Δ:
/// a builder that accepts it must allow that edge explicitly (edges_outside == 1).
LsbtDiscretizationCheck CheckLsbtDiscretization(const Matrix3X& x, double radius,
                                                double tolerance = 0.05);

/// LSBT nodal mobility (3M × 3M), eq. C.2 over all nodes of all rods [m/(N·s)]. Symmetric.
/// Not positive definite: an alternating tangential force pattern on a straight stretch has
/// negative self-power (its Oseen sum is −(ln 2)/(2πμΔ) per unit force, with no local term to
/// offset it). Precondition: no two distinct nodes coincide.
void AssembleLsbtMobility(const FluidParams& params, const std::vector<HydroRod>& rods,
                          MatX* mobility);

}  // namespace stokesrods
