// The vectorized inner loop shared by the Stokeslet sums (stokeslet_sum.cc, fmm_sum.cc): sources
// as the columns (x, y, z, ε², g_x, g_y, g_z) of an S × 7 matrix so that the loop over sources
// vectorizes (AVX-512/AVX2 clones chosen at run time; stokeslet_sum.cc is built with
// -fno-math-errno). Internal to the fluid module.
#pragma once

#include "stokesrods/common/types.h"

namespace stokesrods {

struct SourceColumns {
  const double *x, *y, *z, *e2, *gx, *gy, *gz;
};

/// The columns of an S × 7 source matrix.
SourceColumns Columns(const MatX& src);

/// The S × 7 source matrix of the points and blob sizes, strengths zero.
MatX SourceMatrix(const Matrix3X& sources, const VecX& regularization);

/// w += Σ_{s ∈ [begin, end)} S_ε_s(x − y_s) g_s, with
/// S_ε(r) g = (1/R + ε²/R³) g + (r·g) r / R³,  R² = |r|² + ε²  (ε = 0: the singular Stokeslet;
/// the caller keeps x off the sources then).
void AddPointSum(const SourceColumns& c, Eigen::Index begin, Eigen::Index end, const double* x,
                 double* w);

/// The same in single precision (twice the lanes, faster square roots and divisions): positions
/// relative to an origin near the points, the sum over [begin, end) in float, added to w in
/// double. Each term carries ~1e-7 of itself and the positions' rounding (~1e-7 of their extent
/// from the origin) relative to the distance; for sums whose tolerance is ≥ 1e-4 (fmm_sum.cc).
struct SourceColumnsF {
  const float *x, *y, *z, *e2, *gx, *gy, *gz;
};
void AddPointSumSingle(const SourceColumnsF& c, Eigen::Index begin, Eigen::Index end,
                       const float* x, double* w);

/// The width of the blocks of AddPointSumBlocks: every range it is given starts at a multiple of
/// it and holds a multiple of it (padded with sources of zero strength, which add exactly zero).
inline constexpr int kPointSumBlock = 16;

/// A range [begin, end) of sources for AddPointSumBlocks.
struct SourceRange {
  int begin = 0, end = 0;
};

/// AddPointSumSingle over several ranges of sources at once, each a whole number of blocks of
/// kPointSumBlock: no remainder loop, and one reduction of the lanes per target instead of one per
/// range (the near field of the FMM sums ~27 short ranges per target).
void AddPointSumBlocks(const SourceColumnsF& c, const SourceRange* ranges, int count,
                       const float* x, double* w);

/// The most targets the *Targets sums below take at once.
inline constexpr int kPointSumTargets = 4;

/// The sums at n ≤ kPointSumTargets targets x[k] (adding to w[k]) over the same ranges of sources
/// (any length: each masked at its end on AVX-512; without AVX-512 range by range): each block of
/// sources is read once for all n (one target alone reads 7 vectors per 16 pairs, and its loop ran
/// at less than half the rate of the multiply–add pipes on an Intel Xeon), and the lanes are
/// reduced once per target for all ranges. Each target's sum is bit for bit the one-target sum.
void AddPointSumRangesTargets(const SourceColumns& c, const SourceRange* ranges, int count, int n,
                              const double* const* x, double* const* w);
void AddPointSumRangesTargets(const SourceColumnsF& c, const SourceRange* ranges, int count, int n,
                              const float* const* x, double* const* w);
/// The same over ranges of whole blocks (AddPointSumBlocks' layout: its portable loop without
/// AVX-512).
void AddPointSumBlocksTargets(const SourceColumnsF& c, const SourceRange* ranges, int count,
                              int n, const float* const* x, double* const* w);

/// The compiler-vectorized loops behind AddPointSum, AddPointSumSingle and AddPointSumBlocks on
/// CPUs without AVX-512 (there the sums run on intrinsics; the tests check both paths).
void PointSumPortable(const SourceColumns& c, Eigen::Index begin, Eigen::Index end,
                      const double* x, double* w);
void PointSumSinglePortable(const SourceColumnsF& c, Eigen::Index begin, Eigen::Index end,
                            const float* x, double* w);
void PointSumBlocksPortable(const SourceColumnsF& c, const SourceRange* ranges, int count,
                            const float* x, double* w);

/// The columns of an S × 7 single-precision source matrix.
SourceColumnsF ColumnsF(const Eigen::MatrixXf& src);

}  // namespace stokesrods
