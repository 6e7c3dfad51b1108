// BendTwistStencils: the widest instruction set the CPU has (stencil_batch_avx512.cc,
// stencil_batch_avx2.cc), else one stencil at a time (stencil_lanes.h with T = double).
//
// MEASURED (Intel Xeon with AVX-512, one thread, BM_ElasticForcesAndJacobian/by_edges/64, the
// rod of 65 nodes): see docs/performance.md, session 28.
#include "stokesrods/elastic/stencil_batch.h"

#include "stokesrods/elastic/stencil_batch_lanes.h"

namespace stokesrods {

#if defined(__x86_64__)
void BendTwistStencilsAvx512(const StencilColumns& in, int count, bool with_jacobian,
                             StencilResults* out);
void BendTwistStencilsAvx2(const StencilColumns& in, int count, bool with_jacobian,
                           StencilResults* out);
#endif

void BendTwistStencils(const StencilColumns& in, int count, bool with_jacobian,
                       StencilResults* out, StencilPath path) {
#if defined(__x86_64__)
  static const bool has_avx512 = __builtin_cpu_supports("avx512f");
  static const bool has_avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  if (path == StencilPath::kWidest && has_avx512)
    return BendTwistStencilsAvx512(in, count, with_jacobian, out);
  if (path != StencilPath::kPortable && has_avx2)
    return BendTwistStencilsAvx2(in, count, with_jacobian, out);
#endif
  StencilBatches<double, 1>(in, count, with_jacobian, out);
}

}  // namespace stokesrods
