// BendTwistStencils on AVX2 with FMA: four stencils per vector. Compiled with -mavx2 -mfma and
// called only where the CPU has them (stencil_batch.cc).
#include "stokesrods/elastic/stencil_batch_lanes.h"

namespace stokesrods {

using Lanes4 = double __attribute__((vector_size(32)));

void BendTwistStencilsAvx2(const StencilColumns& in, int count, bool with_jacobian,
                           StencilResults* out) {
  StencilBatches<Lanes4, 4>(in, count, with_jacobian, out);
}

}  // namespace stokesrods
