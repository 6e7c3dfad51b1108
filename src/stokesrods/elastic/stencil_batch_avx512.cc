// BendTwistStencils on AVX-512 F: eight stencils per vector. Compiled with -mavx512f and called
// only where the CPU has it (stencil_batch.cc).
#include <immintrin.h>

#include "stokesrods/elastic/stencil_batch_lanes.h"

extern "C" __m512d _ZGVeN8v_sin(__m512d x);  // glibc's libmvec
extern "C" __m512d _ZGVeN8v_cos(__m512d x);

namespace stokesrods {

using Lanes8 = double __attribute__((vector_size(64)));

void BendTwistStencilsAvx512(const StencilColumns& in, int count, bool with_jacobian,
                             double* energy, double* gradient, double* jacobian) {
  StencilBatches<Lanes8, 8>(in, count, with_jacobian, energy, gradient, jacobian);
}

namespace {
struct Avx512Math {
  static Lanes8 Sin(Lanes8 v) { return Lanes8(_ZGVeN8v_sin(__m512d(v))); }
  static Lanes8 Cos(Lanes8 v) { return Lanes8(_ZGVeN8v_cos(__m512d(v))); }
};
}  // namespace

void MaterialFramesAvx512(const MaterialFrameColumns& frames, int count) {
  MaterialFrameBatches<Lanes8, 8, Avx512Math>(frames, count);
}

}  // namespace stokesrods
