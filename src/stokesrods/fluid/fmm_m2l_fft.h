// The M2L translations of the FMM (fmm_sum.cc) by discrete Fourier transforms, as in Ying, Biros
// & Zorin (2004, §3.3) and PVFMM: the surfaces' points are a p × p × p lattice, so one V-list
// translation is a convolution, and a level's translations are one transform per box and one
// product per V-list entry and frequency.
//
// In box widths, the downward check point a of a box and the upward equivalent point b of the box
// at offset v (a, b ∈ {0 … p−1}³ on the cube's surface, spacing η = 2 r_in / (p − 1)) are
// x_a = −r_in + η a and y_b = v − r_in + η b, so
//     check[a] = Σ_v Σ_b S(η (a − b) − v) g_v[b] = Σ_v Σ_b T_v[a − b] g_v[b],
// a linear convolution with the kernel T_v[d] = S(η d − v), d ∈ {−(p−1) … p−1}³ (singular
// Stokeslets, as the direct M2L of fmm_operators.h). On the periodic grid of N = 2p − 1 points
// per axis (the least without wrap-around: T_v at d mod N), with ĝ[k] = Σ_b g[b] e^{−2πi k·b/N}
// and T̂_v likewise (real data: k_z ∈ {0 … (N−1)/2} kept),
//     check[a] = N⁻³ Re Σ_k w_{k_z} e^{2πi k·a/N} Σ_v T̂_v[k] ĝ_v[k],   w_0 = 1, w_{k_z>0} = 2.
// The T̂_v (6 components of the symmetric 3 × 3 kernel, N⁻³ folded in) are computed once per
// order (M2lSpectra). Per V-list entry the product costs 9 complex multiply–adds per frequency,
// N²(N+1)/2 = 196 frequencies at p = 4: 7 056 real multiply–adds in SIMD lanes, against the
// 3 136 kernel evaluations (≈ 18 operations each) of the direct M2L. The transforms are
// separable, one axis at a time, vectorized across all boxes and components of a level.
#pragma once

#include <vector>

#include "stokesrods/common/types.h"
#include "stokesrods/fluid/fmm_operators.h"
#include "stokesrods/fluid/fmm_tree.h"

namespace stokesrods {

/// The kernel spectra T̂_v of one order, for every offset v ∈ {−3 … 3}³ at M2lIndex(v) (zero for
/// the 27 neighbours, which have no M2L): 6 components × (re, im) × `stride` frequencies each,
/// stored by blocks of 16 frequencies (block, offset, component's re and im, frequency).
struct M2lSpectra {
  int order = 0;       ///< p
  int grid = 0;        ///< N = 2p − 1
  int frequencies = 0;  ///< F = N² (N + 1) / 2
  int stride = 0;      ///< F rounded up to whole SIMD blocks (the padding is zero)
  std::vector<double> values;        ///< stride × 343 × 12
  std::vector<float> values_single;  ///< the same in single precision
  std::vector<int> surface_cell;     ///< surface point j → its lattice cell (a_x p + a_y) p + a_z
  std::vector<int> interior_cell;    ///< the (p − 2)³ cells inside the surface
};

/// The spectra of the operators' order (computed on first use, then cached with them).
const M2lSpectra& GetM2lSpectra(const FmmOperators& op);

/// The transforms' factors e^{∓2πi k j / N} (fmm_m2l_fft.cc), made at the first Apply.
template <class T>
struct FftTwiddles {
  int order = 0, grid = 0;
  std::vector<T> forward_z_re, forward_z_im, forward_re, forward_im;
  std::vector<T> inverse_re, inverse_im, inverse_z_re, inverse_z_im;
};

/// Reusable buffers of AddM2lByFft.
template <class T>
struct M2lFftScratch {
  std::vector<T> grid, spectrum_re, spectrum_im, temp_re, temp_im, temp2_re, temp2_im, boxes, sums;
  FftTwiddles<T> twiddles;
};

/// A level's V-list entries (target box t, source box s) grouped by offset, as AddM2lByFft takes
/// them: made once per tree. Stable: each box's entries keep their list order within an offset.
struct M2lByOffset {
  std::vector<int> bucket;          ///< offset o's entries are [bucket[o], bucket[o + 1])
  std::vector<int> target, source;  ///< per entry
};
M2lByOffset SortByOffset(const FmmList& v_list);

/// check (3n × boxes, the level's downward check potentials) += Σ over each box's V list of the
/// translations of the source boxes' upward densities (up, 3n × boxes), for boxes of width 1: the
/// same sums as AddM2l over the level, in precision T (float for the single-precision sums of
/// fmm_sum.cc). Deterministic: each box's entries in list order, on any number of threads.
template <class T>
void AddM2lByFft(const M2lSpectra& spectra, const M2lByOffset& entries, const MatX& up,
                 MatX* check, M2lFftScratch<T>* scratch);

extern template void AddM2lByFft<float>(const M2lSpectra&, const M2lByOffset&, const MatX&,
                                        MatX*, M2lFftScratch<float>*);
extern template void AddM2lByFft<double>(const M2lSpectra&, const M2lByOffset&, const MatX&,
                                         MatX*, M2lFftScratch<double>*);

}  // namespace stokesrods
