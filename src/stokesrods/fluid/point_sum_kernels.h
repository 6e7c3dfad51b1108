// The layout of the Stokeslet sums' sources (point_stokeslet.h) and the sums written on one
// instruction set each (point_sum_simd.h; point_sum_avx512.cc, point_sum_avx2.cc, each compiled
// for its own set alone). Free of Eigen and the standard library: the instruction-set files
// include nothing else, so that no inline function of a shared header is compiled there with
// instructions that the CPU running the program may lack. Internal to the fluid module.
#pragma once

namespace stokesrods {

/// Sources as the columns (x, y, z, ε², g_x, g_y, g_z) of an S × 7 matrix.
struct SourceColumns {
  const double *x, *y, *z, *e2, *gx, *gy, *gz;
};
struct SourceColumnsF {
  const float *x, *y, *z, *e2, *gx, *gy, *gz;
};

/// A range [begin, end) of sources.
struct SourceRange {
  int begin = 0, end = 0;
};

/// The width of the blocks of AddPointSumBlocks: every range it is given starts at a multiple of
/// it and holds a multiple of it (padded with sources of zero strength, which add exactly zero).
inline constexpr int kPointSumBlock = 16;

/// The most targets the *Targets sums take at once.
inline constexpr int kPointSumTargets = 4;

/// w[k] += Σ over the ranges of S_ε_s(x[k] − y_s) g_s for n ≤ kPointSumTargets targets, each
/// block of sources read once for all n; each target's sum bit for bit its sum alone (n = 1).
/// flush_ranges: each range summed in lanes of its own, then added to the ranges' lanes.
/// Call only where the CPU has the instruction set (HasPointSumAvx512, HasPointSumAvx2).
void PointSumTargetsAvx512(const SourceColumns& c, const SourceRange* ranges, int count, int n,
                           const double* const* x, double* const* w, bool flush_ranges);
void PointSumTargetsAvx512(const SourceColumnsF& c, const SourceRange* ranges, int count, int n,
                           const float* const* x, double* const* w, bool flush_ranges);
void PointSumTargetsAvx2(const SourceColumns& c, const SourceRange* ranges, int count, int n,
                         const double* const* x, double* const* w, bool flush_ranges);
void PointSumTargetsAvx2(const SourceColumnsF& c, const SourceRange* ranges, int count, int n,
                         const float* const* x, double* const* w, bool flush_ranges);

/// Whether the CPU has AVX-512 F; AVX2 and FMA (x86-64 builds; false elsewhere).
bool HasPointSumAvx512();
bool HasPointSumAvx2();

}  // namespace stokesrods
