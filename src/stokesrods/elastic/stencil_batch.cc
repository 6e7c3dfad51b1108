// BendTwistStencils: the widest instruction set the CPU has (stencil_batch_avx512.cc,
// stencil_batch_avx2.cc), else one stencil at a time (stencil_lanes.h with T = double).
//
// MEASURED (Intel Xeon with AVX-512, one thread, BM_ElasticForcesAndJacobian/by_edges/64, the
// rod of 65 nodes): see docs/performance.md, session 28.
#include "stokesrods/elastic/stencil_batch.h"

#include <cstddef>

#include "stokesrods/elastic/stencil_batch_lanes.h"
#include "stokesrods/rod/frames.h"

namespace stokesrods {
#if defined(__x86_64__)
namespace {

enum class Lanes { kAvx512, kAvx2, kOne };

// The lanes `path` asks for that the CPU has.
Lanes LanesFor(StencilPath path) {
  static const bool has_avx512 = __builtin_cpu_supports("avx512f");
  static const bool has_avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  if (path == StencilPath::kWidest && has_avx512) return Lanes::kAvx512;
  if (path != StencilPath::kPortable && has_avx2) return Lanes::kAvx2;
  return Lanes::kOne;
}

}  // namespace
#endif

void BendTwistStencils(const StencilColumns& in, int count, bool with_jacobian,
                       StencilResults* out, StencilPath path) {
  out->energy.resize(static_cast<std::size_t>(count));
  out->gradient.resize(static_cast<std::size_t>(11 * count));
  if (with_jacobian) out->jacobian.resize(static_cast<std::size_t>(121 * count));
  double* const energy = out->energy.data();
  double* const gradient = out->gradient.data();
  double* const jacobian = with_jacobian ? out->jacobian.data() : nullptr;
#if defined(__x86_64__)
  const Lanes lanes = LanesFor(path);
  if (lanes == Lanes::kAvx512)
    return BendTwistStencilsAvx512(in, count, with_jacobian, energy, gradient, jacobian);
  if (lanes == Lanes::kAvx2)
    return BendTwistStencilsAvx2(in, count, with_jacobian, energy, gradient, jacobian);
#endif
  StencilBatches<double, 1>(in, count, with_jacobian, energy, gradient, jacobian);
}

void MaterialFrames(const MaterialFrameColumns& frames, int count, StencilPath path) {
#if defined(__x86_64__)
  const Lanes lanes = LanesFor(path);
  if (lanes == Lanes::kAvx512) return MaterialFramesAvx512(frames, count);
  if (lanes == Lanes::kAvx2) return MaterialFramesAvx2(frames, count);
#endif
  for (int j = 0; j < count; ++j) {
    const RefFrame f{Vec3(frames.d1[0][j], frames.d1[1][j], frames.d1[2][j]),
                     Vec3(frames.d2[0][j], frames.d2[1][j], frames.d2[2][j])};
    Vec3 m1, m2;
    MaterialFrame(f, frames.theta[j], &m1, &m2);
    for (int c = 0; c < 3; ++c) frames.m1[c][j] = m1[c], frames.m2[c][j] = m2[c];
  }
}

}  // namespace stokesrods
