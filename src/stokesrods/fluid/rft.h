// Resistive force theory: local drag per unit length F = Δl (c_∥ t tᵀ + c_⊥ (I − t tᵀ)) U, and the
// literature's coefficients. μ viscosity [Pa·s], r0 rod radius [m], coefficients [Pa·s].
#pragma once

#include <vector>

#include "stokesrods/common/types.h"
#include "stokesrods/fluid/hydrodynamics.h"

namespace stokesrods {

struct RftCoefficients {
  double parallel = 0.0;       ///< c_∥ [Pa·s]
  double perpendicular = 0.0;  ///< c_⊥ [Pa·s]
};

/// Lighthill (1976), "Flagellar hydrodynamics", SIAM Rev 18:161–230, his "optimal" local
/// coefficients for a helix:
///     c_⊥ = 4πμ / (ln(2q/r0) + 1/2),   c_∥ = 2πμ / ln(2q/r0),   q = 0.09 Λ,
/// Λ the wavelength measured along the filament (arc length of one helical turn,
/// Λ = √(λ² + (2πR)²) for pitch λ and helix radius R). Throws std::invalid_argument unless
/// μ, r0 > 0 and 2q/r0 > 1 (c_∥ > 0).
RftCoefficients LighthillCoefficients(double viscosity, double radius, double arc_wavelength);

/// Gray & Hancock (1955), J Exp Biol 32:802–814:
///     c_⊥ = 4πμ / (ln(2λ/r0) + 1/2),   c_∥ = 2πμ / (ln(2λ/r0) − 1/2),
/// λ the wavelength along the swimming axis. Throws std::invalid_argument unless μ, r0 > 0 and
/// ln(2λ/r0) > 1/2.
RftCoefficients GrayHancockCoefficients(double viscosity, double radius, double wavelength);

/// RFT nodal mobility (3M × 3M, block diagonal, rods in order) [m/(N·s)]:
///     𝕄_ii = (1/Δl_i) (t tᵀ / c_∥ + (I − t tᵀ)/c_⊥),
/// the inverse of the local resistance; t the unit tangent at the node (NodeTangents), Δl_i the
/// Voronoi length. Uses HydroRod::rft_parallel / rft_perpendicular, which must be > 0.
void AssembleRftMobility(const std::vector<HydroRod>& rods, MatX* mobility);

}  // namespace stokesrods
