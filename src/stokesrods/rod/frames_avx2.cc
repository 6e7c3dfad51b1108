// TransportFrameLanes on AVX2 with FMA: four edges per vector, the arctangent by glibc's libmvec
// (_ZGVdN4vv_atan2, glibc ≥ 2.35). Compiled with -mavx2 -mfma and called only where the CPU has
// them (frames.cc).
#include <immintrin.h>

#include "stokesrods/rod/frame_lanes.h"

extern "C" __m256d _ZGVdN4vv_atan2(__m256d y, __m256d x);

namespace stokesrods {
namespace {

using Lanes4 = double __attribute__((vector_size(32)));

struct Avx2Math {
  static Lanes4 Sqrt(Lanes4 v) { return Lanes4(_mm256_sqrt_pd(__m256d(v))); }
  static Lanes4 Atan2(Lanes4 y, Lanes4 x) {
    return Lanes4(_ZGVdN4vv_atan2(__m256d(y), __m256d(x)));
  }
};

}  // namespace

void TransportFrameLanesAvx2(int edges, FrameColumns* columns) {
  TransportFrameLanes<Lanes4, 4, Avx2Math>(edges, columns);
}

}  // namespace stokesrods
