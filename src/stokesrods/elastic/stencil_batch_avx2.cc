// BendTwistStencils on AVX2 with FMA: four stencils per vector. Compiled with -mavx2 -mfma and
// called only where the CPU has them (stencil_batch.cc).
#include "stokesrods/elastic/stencil_batch_lanes.h"

namespace stokesrods {

using Lanes4 = double __attribute__((vector_size(32)));

void BendTwistStencilsAvx2(const StencilColumns& in, int count, bool with_jacobian,
                           double* energy, double* gradient, double* jacobian) {
  StencilBatches<Lanes4, 4>(in, count, with_jacobian, energy, gradient, jacobian);
}

}  // namespace stokesrods
