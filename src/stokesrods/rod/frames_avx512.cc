// TransportFrameLanes on AVX-512 F: eight edges per vector, the arctangent by glibc's libmvec
// (_ZGVeN8vv_atan2, glibc ≥ 2.35). Compiled with -mavx512f and called only where the CPU has
// it (frames.cc).
#include <immintrin.h>

#include "stokesrods/rod/frame_lanes.h"

extern "C" __m512d _ZGVeN8vv_atan2(__m512d y, __m512d x);

namespace stokesrods {
namespace {

using Lanes8 = double __attribute__((vector_size(64)));

// (GCC 12's avx512fintrin.h warns on its own _mm512_undefined_pd in vsqrtpd, GCC bug 105593.)
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
struct Avx512Math {
  static Lanes8 Sqrt(Lanes8 v) { return Lanes8(_mm512_sqrt_pd(__m512d(v))); }
  static Lanes8 Atan2(Lanes8 y, Lanes8 x) {
    return Lanes8(_ZGVeN8vv_atan2(__m512d(y), __m512d(x)));
  }
};

}  // namespace

void TransportFrameLanesAvx512(int edges, FrameColumns* columns) {
  TransportFrameLanes<Lanes8, 8, Avx512Math>(edges, columns);
}

}  // namespace stokesrods
