// The Stokeslet sums on AVX2 and FMA (point_sum_simd.h), for CPUs without AVX-512. Compiled
// with -mavx2 -mfma and called only where the CPU has both (HasPointSumAvx2).
//
// MEASURED (AMD EPYC without AVX-512, one thread, BM_StokesletSumApply/20/4/0: 2560 sources ×
// 1300 targets in single precision, medians of 3): the compiler's AVX2 clone of the portable
// loop (IEEE division and square root) 0.88 ns per pair; these sums 0.78 ns with one target per
// pass, 0.64 with two, 0.59 with four (its 16 registers then spill the targets' positions, read
// back as memory operands). In double (20/0/1) 6.0 → 1.5 ns.
#include "stokesrods/fluid/point_sum_simd.h"

namespace stokesrods {

void PointSumTargetsAvx2(const SourceColumns& c, const SourceRange* ranges, int count, int n,
                         const double* const* x, double* const* w, bool flush_ranges) {
  PointSumTargets<Avx2<double>, kPointSumTargets>(c, ranges, count, n, x, w, flush_ranges);
}

void PointSumTargetsAvx2(const SourceColumnsF& c, const SourceRange* ranges, int count, int n,
                         const float* const* x, double* const* w, bool flush_ranges) {
  PointSumTargets<Avx2<float>, kPointSumTargets>(c, ranges, count, n, x, w, flush_ranges);
}

}  // namespace stokesrods
