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
// widths, v ∈ {−3..3}³, |v|_∞ ≥ 2: the V list) to the downward check surface, is not stored. The
// FMM applies it by Fourier transforms (fmm_m2l_fft.h, 9× faster at p = 4); AddM2l here is the
// reference it is tested against: a sum of n singular Stokeslets at n points, evaluated on the
// fly by the vectorized kernel of the direct sum, which costs n² kernel evaluations per
// translation (3136 at p = 4, 0.6 µs in single precision on session 8's host) where the stored dense 3n × 3n matrix cost 9n² multiply–adds read
// from memory, batched by offset into BLAS products of a few columns (5.8 µs each on the
// 100-helix lattice, half of it OpenBLAS packing K_v). (Compressing all K_v by one SVD basis, as
// Fong & Darve do, gave ranks within 10 % of 3n at the tolerances of interest: the surfaces are
// already near minimal.)
#pragma once

#include <array>

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
  /// M2M and L2L rounded to single precision: the translations between levels of the sums in
  /// single precision (tolerance ≥ 1e-4, p = 4; fmm_sum.cc). The fits check_to_up and
  /// check_to_down stay in double there (see fmm_sum.cc).
  std::array<Eigen::MatrixXf, 8> m2m_single, l2l_single;
};

inline constexpr double kFmmInnerRadius = 0.525;  ///< r_in in box widths
inline constexpr double kFmmOuterRadius = 1.475;  ///< r_out in box widths

/// The operators for p = order (2 ≤ p ≤ 12) and the relative cutoff of the pseudo-inverses;
/// computed on first use (thread-safe), then cached for the process.
const FmmOperators& GetFmmOperators(int order, double cutoff);

/// Index of offset v in {−3..3}³ (the V lists' offsets; index 342 − i is offset −v).
inline int M2lIndex(int vx, int vy, int vz) { return (vx + 3) * 49 + (vy + 3) * 7 + (vz + 3); }

/// The reusable buffer of AddM2l (the translations' sources, S × 7).
struct M2lScratch {
  MatX sources;
  Eigen::MatrixXf sources_single;
};

/// M2L into one target box: check (3n, its downward check potentials) += Σ_e K_{v_e} up(:, box_e)
/// over its V list (`count` entries: the source boxes' columns of `up`, 3n × boxes, and their
/// offsets as M2lIndex), for boxes of width 1. The sum runs over the n equivalent Stokeslets of
/// each source box at each check point (in single precision when `single`: positions in box
/// widths, |v| ≤ 3.5, carry ~1e-7 of the distance). Deterministic: one sum, in list order.
void AddM2l(const FmmOperators& op, const int* boxes, const int* offsets, int count,
            const MatX& up, bool single, M2lScratch* scratch, double* check);

}  // namespace stokesrods
