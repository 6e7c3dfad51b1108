// Rest shapes: the paper's helix (section 3, Fig. 5a; SPEC), a straight rod, explicit points.
#pragma once

#include "stokesrods/common/types.h"

namespace stokesrods {

struct HelixGeometry {
  int nodes = 65;             ///< N ≥ 4
  double axis_length = 0.2;   ///< l0: the last node lies l0 below the base [m]
  double pitch = 0.05;        ///< λ [m]
  double helix_radius = 0.01; ///< R [m]
  bool right_handed = true;   ///< geometric handedness (a right-hand screw)
  Vec3 base = Vec3::Zero();   ///< position of node 0 [m]
  /// false: l0 spans node 0 to the last node (SPEC). true: the helical part x2 … x_{N−1} spans
  /// l0 axially and the first edge and the lead-in x1 → x2 sit above it (the last node lies
  /// a + R + l0 below the base).
  bool lead_in_above = false;
};

/// The paper's helix hanging down from `base` (SPEC "Geometry of shape = helix"):
///   x0 = base; x1 = base − a ẑ (first edge on the axis, along −z);
///   x2 = x1 + R x̂ − R ẑ; x2 … x_{N−1} on the helix of radius R about the vertical axis through
///   base, evenly spaced in helical arc length Δs, with x_{N−1} at height base_z − l0.
/// The first-edge length a is not fixed by the paper: we take a = Δs, which gives
///   a = (l0 − R) c / (N − 3 + c),  c = √(1 + (2πR/λ)²)  (arc length per unit axial drop),
/// so that N = 65 gives Δs = 4.80 mm and a total arc length of 0.3165 m (paper: Δl ≈ 5 mm, L ≈ 0.32 m).
/// Right-handed (positive torsion): x = R cos φ, y = −R sin φ, z = z2 − λ φ / 2π, φ ≥ 0.
Matrix3X HelixNodes(const HelixGeometry& g);

/// N nodes from `base` straight down (−z) over `axis_length`, evenly spaced.
Matrix3X StraightNodes(int nodes, double axis_length, const Vec3& base);

}  // namespace stokesrods
