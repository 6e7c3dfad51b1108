// The Stokeslet sums on AVX-512 F (point_sum_simd.h). Compiled with -mavx512f and called only
// where the CPU has it (HasPointSumAvx512). MEASURED: see stokeslet_sum.cc.
#include "stokesrods/fluid/point_sum_simd.h"

namespace stokesrods {

void PointSumTargetsAvx512(const SourceColumns& c, const SourceRange* ranges, int count, int n,
                           const double* const* x, double* const* w, bool flush_ranges) {
  PointSumTargets<Avx512<double>, kPointSumTargets>(c, ranges, count, n, x, w, flush_ranges);
}

void PointSumTargetsAvx512(const SourceColumnsF& c, const SourceRange* ranges, int count, int n,
                           const float* const* x, double* const* w, bool flush_ranges) {
  PointSumTargets<Avx512<float>, kPointSumTargets>(c, ranges, count, n, x, w, flush_ranges);
}

}  // namespace stokesrods
