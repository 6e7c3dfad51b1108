// The translation operators of the kernel-independent FMM of the Stokeslet sum (fmm_sum.cc;
// Ying, Biros & Zorin, J. Comput. Phys. 196 (2004)), for a box of width 1 (half-width 1/2).
//
// A box's far field is represented by Stokeslets ("equivalent densities", 3 per point) on the
// p × p × p grid on the surface of a cube around it: the upward equivalent surface of ∞-radius
// r_in = 0.525 (encloses the box) reproduces the field of the box's sources outside the upward check
// surface r_out = 1.475, where it is fitted (the first point of a V-list box's targets is at 1.5);
// the downward equivalent surface r_out reproduces inside the box (checked on r_in) the field of
// the sources of all boxes that are not neighbours. The equivalent densities are singular
// Stokeslets S(r) = I/|r| + r rᵀ/|r|³, homogeneous of degree −1, so that every operator on the
// densities is independent of the box width (the width enters only S2M, ×w, and L2T, by the
// actual coordinates) and is computed once per order and process (GetFmmOperators).
//
// M2L, K_v = [S(x_i − y_j)] from the upward equivalent surface of the box at offset v (in box
// widths, v ∈ {−3..3}³, |v|_∞ ≥ 2: the V list) to the downward check surface, is stored as the
// dense 3n × 3n matrix for half of the offsets: the two surfaces coincide up to the shift, so
// K_{−v} = K_vᵀ. (Compressing all K_v by one SVD basis, as Fong & Darve do, gave ranks within 10 %
// of 3n at the tolerances of interest: the surfaces are already near minimal.)
#pragma once

#include <array>
#include <vector>

#include "stokesrods/common/types.h"

namespace stokesrods {

struct FmmOperators {
  int order = 0;                 ///< p, points per edge of the surfaces
  int points = 0;                ///< n = p³ − (p − 2)³ points on a surface
  double cutoff = 0.0;           ///< relative singular-value cutoff of the pseudo-inverses
  Matrix3X surface;              ///< the n points on the cube of ∞-radius 1
  MatX check_to_up;              ///< upward check (r_out) → upward equivalent (r_in) densities
  std::array<MatX, 8> m2m;       ///< child c's upward densities → the parent's
  std::array<MatX, 8> l2l;       ///< parent's downward densities → child c's
  MatX check_to_down;            ///< downward check (r_in) → downward equivalent (r_out)
  std::array<MatX, 343> m2l;     ///< K_v for M2lIndex(v) > 171 (see M2lMatrix), else empty
  std::array<Eigen::MatrixXf, 343> m2l_single;  ///< the same in single precision
};

inline constexpr double kFmmInnerRadius = 0.525;  ///< r_in in box widths
inline constexpr double kFmmOuterRadius = 1.475;  ///< r_out in box widths

/// The operators for p = order (2 ≤ p ≤ 12) and the relative cutoff of the pseudo-inverses;
/// computed on first use (thread-safe; 0.1, 0.4, 1.5 s for p = 4, 5, 6), then cached for the
/// process (K_v: 36, 110, 260 MB, and half that again in single precision).
const FmmOperators& GetFmmOperators(int order, double cutoff);

/// Index of offset v in FmmOperators::m2l; index 342 − i is offset −v.
inline int M2lIndex(int vx, int vy, int vz) { return (vx + 3) * 49 + (vy + 3) * 7 + (vz + 3); }

/// K_v for an M2L index: the stored matrix, or the transpose of the one of −v.
inline bool M2lIsTransposed(int index) { return index < 171; }
inline const MatX& M2lMatrix(const FmmOperators& op, int index) {
  return op.m2l[static_cast<size_t>(M2lIsTransposed(index) ? 342 - index : index)];
}
inline const Eigen::MatrixXf& M2lMatrixSingle(const FmmOperators& op, int index) {
  return op.m2l_single[static_cast<size_t>(M2lIsTransposed(index) ? 342 - index : index)];
}

}  // namespace stokesrods
