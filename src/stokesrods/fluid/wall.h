// A plane no-slip wall: the regularized Stokeslet and its image system (issue 11).
//
// Wall through `point` with unit normal n into the fluid; a blob of size ε at x0, height
// h = (x0 − p)·n > 0, force f; its image point x0* = x0 − 2h n; r = x − x0, R = x − x0*,
// Δ = I − 2 n nᵀ, R_ε² = |R|² + ε², S_ε of stokeslet_segment.h. Then 8πμ u(x) = W f with
//   W = S_ε(r) − S_ε(R)                                                   (Stokeslet and image)
//     + 2h² (Δ/R_ε³ − 3 R (ΔR)ᵀ/R_ε⁵) − 6h²ε² Δ/R_ε⁵                     (potential dipole, blob)
//     + 2h [n (ΔR)ᵀ (|R|² + 4ε²)/R_ε⁵ − Δ (R·n)/R_ε³ + R nᵀ/R_ε³
//           + 3 R (ΔR)ᵀ (R·n)/R_ε⁵]                                       (Stokes doublet)
//     + 6hε² ((R·n) I − n Rᵀ)/R_ε⁵                                        (rotlet)
// The structure is that of Ainley, Durkin, Embid, Boindala & Cortez (J Comput Phys 227:4600,
// 2008; Smith, Proc R Soc A 465:3605, 2009 corrects a sign); we did not have the paper's final
// formula and derived the last (rotlet) term ourselves by requiring W = 0 on the wall for every ε.
// Checked (tests/fluid/wall_test.cc): W = 0 on the wall to round-off for all ε, h and
// orientations; ∇·u = 0 (finite differences); ε → 0 gives Blake's (1971) singular image system,
// coded independently from its potentials; a sphere's drag parallel and normal to the wall against
// Faxén's and Brenner's (1961) results.
#pragma once

#include "stokesrods/common/types.h"
#include "stokesrods/fluid/stokeslet_segment.h"

namespace stokesrods {

struct Wall {
  Vec3 point = Vec3::Zero();     ///< a point of the wall [m]
  Vec3 normal = Vec3::UnitZ();   ///< unit normal, pointing into the fluid
};

/// W above (8πμ times the mobility of a point force) [1/m]. Precondition: x0 above the wall.
Mat3 RegularizedBlakeletMatrix(const Wall& wall, const Vec3& x, const Vec3& x0,
                               double regularization);

/// A_a, A_b of a Regularized Stokeslet Segment (as StokesletSegment) above the wall: the free
/// part by its closed forms, the images' part L ∫ φ(α) (W − S_ε)(x̂, x_α) dα by 20-point
/// Gauss–Legendre on panels no longer than the distance from x̂ to the mirrored segment (that
/// part's nearest singularity), which is exact to rounding there (stokeslet_segment.cc).
/// Precondition: the segment and x̂ above the wall.
SegmentMobility StokesletSegmentNearWall(const Wall& wall, const Vec3& xa, const Vec3& xb,
                                         double regularization, const Vec3& point);

/// The images' part alone (StokesletSegmentNearWall minus StokesletSegment): what a wall adds to
/// the free-space segment mobility. With `tolerance` > 0, the fewest Gauss–Legendre points on the
/// whole segment (2 … kWallImageRuleMaxPoints) whose WallImageRuleError meets it, when some do.
SegmentMobility StokesletSegmentWallImages(const Wall& wall, const Vec3& xa, const Vec3& xb,
                                           double regularization, const Vec3& point,
                                           double tolerance = 0.0);

/// The most points WallImageRuleError is calibrated for.
inline constexpr int kWallImageRuleMaxPoints = 5;

/// The images' part by an n-point Gauss–Legendre rule on the whole segment (1 ≤ n ≤ 20): the far
/// rule of the matrix-free wall (fluid/wall_sources.h).
SegmentMobility StokesletSegmentWallImagesGauss(const Wall& wall, const Vec3& xa, const Vec3& xb,
                                                double regularization, const Vec3& point, int n);

/// δ* = √(d*² + ε²)/L of the images' part: d* the distance from `point` to the mirrored segment,
/// where the images are singular (the free part's δ with the segment mirrored) [–].
double WallImageDelta(const Wall& wall, const Vec3& xa, const Vec3& xb, double regularization,
                      const Vec3& point);

/// Bound on the relative error (Frobenius, of (A_a, A_b) of the images' part) of the n-point rule
/// at δ* ≥ 1: twice the measured worst case e*_n(δ*) ≈ c*_n δ*^−(2n−2), c*_n ≈ 2.2e-2 ·
/// 11.5^−(n−2) (one power of δ* slower than the free part's rule: the images hold doublets and
/// dipoles; calibration in tests/fluid/wall_sources_test.cc) [–].
double WallImageRuleError(int n, double delta);

/// 8πμ times the mobility of a point blob at x0 seen at x: the regularized Stokeslet, or with a
/// `wall` (may be null) the Blakelet above [1/m].
Mat3 PointBlobMatrix(const Wall* wall, const Vec3& x, const Vec3& x0, double regularization);

}  // namespace stokesrods
