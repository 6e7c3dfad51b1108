// The dense mobility reuse's passes with its differences D₁, D₂ kept in IEEE half precision
// (fluid/mobility_reuse.h, PRECISION), on AVX-512 F, BW and VL, or on AVX2 with FMA and F16C
// (mobility_reuse_half.cc): both give the same bits.
#pragma once

#include <cstdint>

#include "stokesrods/common/parallel.h"
#include "stokesrods/common/types.h"

namespace stokesrods {

/// Whether this CPU runs the functions below: AVX-512 F, BW and VL, or AVX2, FMA and F16C.
bool HasHalfDifferences();

/// From this many entries on (a matrix of kDenseInParallelFromRows rows, common/parallel.h), the
/// passes over the reuse's matrices run in two parts.
inline constexpr Eigen::Index kTwoPartsFrom =
    Eigen::Index{kDenseInParallelFromRows} * Eigen::Index{kDenseInParallelFromRows};

/// body(part, first, count) over [0, n): in two parts cut at a multiple of 16 (whole vectors) and
/// run over the OpenMP threads from kTwoPartsFrom entries on (a pass over memory: two cores
/// stream it faster), else in one (part 0). Each part's entries are its own: an elementwise pass
/// gives the same bits either way.
template <class Body>
void ForTwoParts(Eigen::Index n, const Body& body) {
  if (n < kTwoPartsFrom) return body(0, Eigen::Index{0}, n);
  const Eigen::Index cut = (n / 2 + 15) / 16 * 16;
  ForEachStatic(2, true, [&](int part) {
    body(part, part == 0 ? Eigen::Index{0} : cut, part == 0 ? cut : n - cut);
  });
}

/// d (n entries) rounded to half precision at the scale σ, a power of two that puts its largest
/// |entry| near 2¹⁴ (half precision's range ends at 65504): half = σ d in half precision, and d ←
/// half / σ (exact in single precision), so that d holds what the half values stand for. Returns
/// σ (1 for d = 0), or 0 when d has an entry that is not finite (then nothing is written).
/// Precondition: HasHalfDifferences(). `f16c` takes the AVX2 kernels even where AVX-512 is
/// present (for tests).
float RoundToHalf(Eigen::Index n, float* d, std::uint16_t* half, bool f16c = false);

/// out = base + a · slope + b · curve over n entries (slope and curve in half precision, their
/// scales folded into a and b; curve may be null). Precondition: HasHalfDifferences().
void ExtrapolateHalf(Eigen::Index n, const float* base, float a, const std::uint16_t* slope,
                     float b, const std::uint16_t* curve, float* out, bool f16c = false);

}  // namespace stokesrods
