// BendTwistStencils on AVX2 with FMA: four stencils per vector. Compiled with -mavx2 -mfma and
// called only where the CPU has them (stencil_batch.cc).
#include <immintrin.h>

#include "stokesrods/elastic/stencil_batch_lanes.h"

extern "C" __m256d _ZGVdN4v_sin(__m256d x);  // glibc's libmvec
extern "C" __m256d _ZGVdN4v_cos(__m256d x);

namespace stokesrods {

using Lanes4 = double __attribute__((vector_size(32)));

void BendTwistStencilsAvx2(const StencilColumns& in, int count, bool with_jacobian,
                           double* energy, double* gradient, double* jacobian) {
  StencilBatches<Lanes4, 4>(in, count, with_jacobian, energy, gradient, jacobian);
}

namespace {
struct Avx2Math {
  static Lanes4 Sin(Lanes4 v) { return Lanes4(_ZGVdN4v_sin(__m256d(v))); }
  static Lanes4 Cos(Lanes4 v) { return Lanes4(_ZGVdN4v_cos(__m256d(v))); }
};
}  // namespace

void MaterialFramesAvx2(const MaterialFrameColumns& frames, int count) {
  MaterialFrameBatches<Lanes4, 4, Avx2Math>(frames, count);
}

}  // namespace stokesrods
