// Regularized Stokeslet Segments over several rods (paper eqs. 13–16, 21).
// Every rod is a polyline of linear-density segments; the force density f_i [N/m] at node i is
// shared by the segments on either side. Collocation at the nodes gives (eq. 13, 15, 21)
//     U_i = (1/8πμ) Σ_rods Σ_segments (A_a f_a + A_b f_b)   =:   (A f)_i,
// with A_a, A_b of stokeslet_segment.h and ε = params.regularization × the radius of the rod that
// owns the segment. The nodal forces are F_i = Δl_i f_i (eq. 16), so U = A Λ⁻¹ F = 𝕄 F.
// DOF order: node i of all rods in order, (x, y, z) per node.
#pragma once

#include <vector>

#include "stokesrods/common/types.h"
#include "stokesrods/fluid/hydrodynamics.h"

namespace stokesrods {

/// A (3M × 3M), U = A f with f the nodal force densities [m²/(N·s)]. Not symmetric.
void AssembleRssDensityMobility(const FluidParams& params, const std::vector<HydroRod>& rods,
                                MatX* density_mobility);

/// Nodal mobility 𝕄 = A Λ⁻¹ (3M × 3M) [m/(N·s)].
void AssembleRssMobility(const FluidParams& params, const std::vector<HydroRod>& rods,
                         MatX* mobility);

/// u(x̂) = (1/8πμ) Σ (A_a f_a + A_b f_b) with f_i = F_i/Δl_i (eq. 9 summed over segments) [m/s].
Vec3 RssVelocityAt(const FluidParams& params, const std::vector<HydroRod>& rods,
                   const VecX& nodal_forces, const Vec3& point);

}  // namespace stokesrods
