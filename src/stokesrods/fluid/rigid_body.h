// Rigid bodies in the fluid, as more sources of flow beside the rods (issue 11's cell bodies).
//
// A body's surface carries N regularized point Stokeslets (the method of regularized Stokeslets,
// Cortez, Fauci & Medovikov 2005, Phys. Fluids 17:031504) with the blob of stokeslet_segment.h:
//     8πμ u(x) = Σ_j S_ε(x − x_j) F_j,   F_j the force the surface point j exerts on the fluid [N].
// A rigid motion (U, Ω) about the centre c prescribes u(x_i) = U + Ω × (x_i − c) at the points;
// solving 𝕄 F = u for the six unit motions gives the body's 6 × 6 resistance matrix
//     (F, T) = 𝓡 (U, Ω),   F = Σ F_j,   T = Σ (x_j − c) × F_j   (on the fluid; on the body −).
// The blob size is a fixed fraction of the point spacing d = √(area/N), so the surface converges
// as N grows (tests/fluid/rigid_body_test.cc: sphere 6πμaU and 8πμa³Ω, prolate spheroid).
#pragma once

#include <vector>

#include "stokesrods/common/types.h"
#include "stokesrods/fluid/hydrodynamics.h"
#include "stokesrods/fluid/wall.h"

namespace stokesrods {

/// Points of a body's surface with their blob size.
struct BodySurface {
  Matrix3X points;             ///< on the surface (3 × N) [m]
  double regularization = 0;   ///< ε [m]
  /// A free body (issue 11): its rigid motion (U, Ω) about `center` is an unknown with the
  /// balance of the fluid's force and torque on it (AssembleMobilityWithBodies' border).
  bool free = false;
  Vec3 center = Vec3::Zero();  ///< [m]
};

/// N ≥ 2 nearly uniform points on the unit sphere (Fibonacci lattice), deterministic.
Matrix3X FibonacciSphere(int n);

/// A sphere of `radius` [m] about `center` with N points and ε = blob_over_spacing · √(4πa²/N).
BodySurface SphereSurface(const Vec3& center, double radius, int n, double blob_over_spacing);

/// A spheroid about `center`: equatorial radius b = `radius`, polar semi-axis a = `half_length` along
/// the unit `axis` (prolate a > b, oblate a < b), N points (the Fibonacci sphere stretched by (b, b, a)
/// and turned from z to the axis; no longer equal-area), ε = blob_over_spacing · √(area/N).
BodySurface SpheroidSurface(const Vec3& center, double radius, double half_length, const Vec3& axis,
                            int n, double blob_over_spacing);

/// 𝕄 (3N × 3N) of the points: U = 𝕄 F with the regularized Stokeslets above [m/(N·s)]; with a
/// `wall`, the Stokeslets and their images (wall.h).
MatX PointStokesletMobility(const BodySurface& surface, double viscosity,
                            const Wall* wall = nullptr);

/// The resistance 𝓡 (6 × 6) of the rigid surface about `center`: (F, T) on the fluid from (U, Ω);
/// with a `wall`, in the half space above it.
Mat6 RigidResistance(const BodySurface& surface, const Vec3& center, double viscosity,
                     const Wall* wall = nullptr);

/// 𝕄 over the rods' nodes (RSS, as AssembleMobility) followed by the bodies' points, with every
/// coupling: rod segments at body points (eq. 8 with the rods' Voronoi lengths), body blobs at rod
/// nodes and at each other's points (each blob with its own ε); with params.wall, every source
/// with its images [m/(N·s)]. RSS only.
MatX AssembleMobilityWithBodies(const FluidParams& params, const std::vector<HydroRod>& rods,
                                const std::vector<BodySurface>& bodies);

/// The mobility of rods and bodies bordered by the free bodies' rigid motions (6 per free body):
///   [𝕄  G; Gᵀ 0],  G_j = [I, −[x_j − c]×] at a free body's points (u_j = U + Ω × (x_j − c)),
/// so that with f the forces of the fluid on the rods and bodies and V = (U, Ω),
///   [𝕄 f + G V; Gᵀ f] = [−(known velocities); 0]  is no slip and each free body's balance of
/// force and torque (it has no other load). Without free bodies, AssembleMobilityWithBodies.
MatX AssembleBorderedMobility(const FluidParams& params, const std::vector<HydroRod>& rods,
                              const std::vector<BodySurface>& bodies);

/// The velocity at `point` of the bodies' blobs carrying the forces F (3P, on the fluid, in the
/// order of AssembleMobilityWithBodies), with params.wall's images if any [m/s].
Vec3 BodyBlobVelocityAt(const FluidParams& params, const std::vector<BodySurface>& bodies,
                        const VecX& forces, const Vec3& point);

/// A rigid swimmer: one body and rigid rods fixed to it, the rods turned by a motor at rate ω
/// [rad/s] about `motor_axis` (unit) through `motor_point`, relative to the body; no external
/// force or torque. Its body moves with (U, Ω) about `center`, the rods with U + Ω × (x − c)
/// + ω a × (x − x_m). Force- and torque-free: Gᵀ 𝕄⁻¹ (G (U, Ω) + ω w) = 0, G the rigid motions at
/// all points and w the motor's. Returns (U, Ω) (6) [m/s, rad/s]. The reference calculation for
/// the free-swimming cell of issue 11.
Vec6 RigidSwimmerVelocity(const FluidParams& params, const std::vector<HydroRod>& rods,
                          const BodySurface& body, const Vec3& center, const Vec3& motor_axis,
                          const Vec3& motor_point, double omega);

}  // namespace stokesrods
