// Hydrodynamic models: the mobility relation between nodal velocities and nodal forces.
//
// All models are written in one form, over every node of every rod at once (paper eq. 21):
//     U = 𝕄 F,
// U the 3M nodal velocities [m/s] (M nodes in total, rods in order, nodes in order), F the 3M
// nodal forces [N] that the rods exert on the fluid. The hydrodynamic force on the rods is −F, so
// the drag does negative work  −Fᵀ U = −Uᵀ 𝕄⁻¹ U < 0  when 𝕄 is positive definite.
//   rss : Regularized Stokeslet Segments (Cortez 2018; paper eqs. 7–16): 𝕄 = A Λ⁻¹ with A the
//         force-density mobility of eqs. 13–15 and Λ = diag(Δl_i) the current Voronoi lengths.
//   lsbt: Lighthill slender body theory, paper eq. C.2 (nodal forces directly).
//   rft : resistive force theory, local: F_i = Δl_i (c_∥ t tᵀ + c_⊥ (I − t tᵀ)) U_i.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "stokesrods/common/types.h"
#include "stokesrods/fluid/wall.h"

namespace stokesrods {

enum class FluidModel { kNone, kRss, kLsbt, kRft };

/// RSS and LSBT couple every node to every other (a mobility 𝕄); RFT and none are local.
inline bool IsNonlocal(FluidModel model) {
  return model == FluidModel::kRss || model == FluidModel::kLsbt;
}

struct FluidParams {
  FluidModel model = FluidModel::kRss;
  double viscosity = 1.0;       ///< μ [Pa·s]
  double regularization = 1.02; ///< RSS blob size ε in units of the rod radius r0 [–]
  /// RSS assembly: relative error allowed on each far segment–node interaction (0: round-off,
  /// the reference; see StokesletSegment) [–].
  double far_field_tolerance = 0.0;
  /// A plane no-slip wall (RSS only): every Stokeslet with its regularized images (wall.h).
  std::optional<Wall> wall;
};

/// Geometry of one rod as the fluid sees it.
struct HydroRod {
  const Matrix3X* x = nullptr;  ///< node positions (3 × N) [m]
  double radius = 0.0;          ///< r0 [m]
  /// RFT only: drag coefficients per unit length [Pa·s] (c_∥, c_⊥).
  double rft_parallel = 0.0;
  double rft_perpendicular = 0.0;
};

/// Voronoi lengths of the nodes of a polyline (3 × N, N ≥ 2): half the adjacent edge lengths
/// summed [m] (the end nodes get half their one edge).
VecX VoronoiLengths(const Matrix3X& x);

/// Unit tangents at the nodes of a polyline (3 × N, N ≥ 2, no zero-length edge): the normalized
/// sum of the unit tangents of the adjacent edges; the end nodes take their one edge's. Used by
/// the local terms of LSBT (f⊥) and RFT.
Matrix3X NodeTangents(const Matrix3X& x);

/// Total number of nodes M of the rods.
Eigen::Index TotalNodes(const std::vector<HydroRod>& rods);

/// Nodal mobility 𝕄 (3M × 3M) of the model for the rods as they are now [m/(N·s)].
/// kNone is a programmer error. RFT gives the block-diagonal inverse of its local resistance.
///   rss : 𝕄 = A Λ⁻¹ (rss.h), ε = params.regularization × the radius of the rod that owns the
///         segment; with params.wall, plus the images' part (rss_wall.h). 𝕄 is not symmetric (collocation of linear densities): solve it with LU, not
///         with a factorization that reads one triangle (LDLT, LLT).
///   lsbt: eq. C.2 (lsbt.h); symmetric but not positive definite at Δ = 2δ.
///   rft : rft.h.
void AssembleMobility(const FluidParams& params, const std::vector<HydroRod>& rods,
                      MatX* mobility);

/// Fluid velocity [m/s] at `point` induced by the nodal forces F (3M, as in U = 𝕄 F) of a solved
/// state: RSS evaluates the segments of eq. 9 with the force densities F_i/Δl_i (so at a node it
/// returns that node's velocity, the no-slip condition the solve imposed); LSBT and RFT use the
/// (singular) Stokeslets of the nodal forces, leaving out a node that coincides with `point`.
Vec3 FluidVelocityAt(const FluidParams& params, const std::vector<HydroRod>& rods,
                     const VecX& nodal_forces, const Vec3& point);

}  // namespace stokesrods
