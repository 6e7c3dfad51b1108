// The vectorized inner loop shared by the Stokeslet sums (stokeslet_sum.cc, fmm_sum.cc): sources
// as the columns (x, y, z, ε², g_x, g_y, g_z) of an S × 7 matrix (point_sum_kernels.h) so that
// the loop over sources vectorizes: on AVX-512, else AVX2 with FMA, by intrinsics
// (point_sum_simd.h); elsewhere the portable loops (stokeslet_sum.cc, built with
// -fno-math-errno). Internal to the fluid module.
#pragma once

#include "stokesrods/common/types.h"
#include "stokesrods/fluid/point_sum_kernels.h"

namespace stokesrods {

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
void AddPointSumSingle(const SourceColumnsF& c, Eigen::Index begin, Eigen::Index end,
                       const float* x, double* w);

/// AddPointSumSingle over several ranges of sources at once, each a whole number of blocks of
/// kPointSumBlock: no remainder loop, and one reduction of the lanes per target instead of one per
/// range (the near field of the FMM sums ~27 short ranges per target).
void AddPointSumBlocks(const SourceColumnsF& c, const SourceRange* ranges, int count,
                       const float* x, double* w);

/// The sums at n ≤ kPointSumTargets targets x[k] (adding to w[k]) over the same ranges of sources
/// (any length: each masked at its end on AVX-512 and AVX2; in the portable loops range by range):
/// each block of sources is read once for all n (one target alone reads 7 vectors per block, and
/// its loop ran at less than half the rate of the multiply–add pipes on an Intel Xeon), and the
/// lanes are reduced once per target for all ranges. Each target's sum is bit for bit the
/// one-target sum. In single precision, flush_ranges sums each range in lanes of its own and adds
/// them to the ranges' lanes after it (each term then rounds against its range's partial sum, not
/// the whole sum's; three additions more per range and target): the far rule sum's ranges
/// (far_rule_sum.h).
void AddPointSumRangesTargets(const SourceColumns& c, const SourceRange* ranges, int count, int n,
                              const double* const* x, double* const* w);
void AddPointSumRangesTargets(const SourceColumnsF& c, const SourceRange* ranges, int count, int n,
                              const float* const* x, double* const* w, bool flush_ranges = false);
/// The same over ranges of whole blocks (AddPointSumBlocks' layout: its portable loop without
/// AVX2).
void AddPointSumBlocksTargets(const SourceColumnsF& c, const SourceRange* ranges, int count,
                              int n, const float* const* x, double* const* w);

/// The compiler-vectorized loops behind AddPointSum, AddPointSumSingle and AddPointSumBlocks on
/// CPUs without AVX2 and FMA (elsewhere the sums run on intrinsics; the tests check both paths).
void PointSumPortable(const SourceColumns& c, Eigen::Index begin, Eigen::Index end,
                      const double* x, double* w);
void PointSumSinglePortable(const SourceColumnsF& c, Eigen::Index begin, Eigen::Index end,
                            const float* x, double* w);
void PointSumBlocksPortable(const SourceColumnsF& c, const SourceRange* ranges, int count,
                            const float* x, double* w);

/// The columns of an S × 7 single-precision source matrix.
SourceColumnsF ColumnsF(const Eigen::MatrixXf& src);

}  // namespace stokesrods
