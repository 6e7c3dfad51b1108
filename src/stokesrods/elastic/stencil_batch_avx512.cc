// BendTwistStencils on AVX-512 F: eight stencils per vector. Compiled with -mavx512f and called
// only where the CPU has it (stencil_batch.cc).
#include "stokesrods/elastic/stencil_batch_lanes.h"

namespace stokesrods {

using Lanes8 = double __attribute__((vector_size(64)));

void BendTwistStencilsAvx512(const StencilColumns& in, int count, bool with_jacobian,
                             double* energy, double* gradient, double* jacobian) {
  StencilBatches<Lanes8, 8>(in, count, with_jacobian, energy, gradient, jacobian);
}

}  // namespace stokesrods
