// The dense mobility reuse's passes with its differences D₁, D₂ kept in IEEE half precision
// (fluid/mobility_reuse.h, PRECISION), on AVX-512 F, BW and VL (mobility_reuse_avx512.cc).
#pragma once

#include <cstdint>

#include "stokesrods/common/types.h"
#include "stokesrods/solver/lu_solve_avx512.h"  // HasLuSolveHalfAvx512: the same CPU features

namespace stokesrods {

/// d (n entries) rounded to half precision at the scale σ, a power of two that puts its largest
/// |entry| near 2¹⁴ (half precision's range ends at 65504): half = σ d in half precision, and d ←
/// half / σ (exact in single precision), so that d holds what the half values stand for. Returns
/// σ (1 for d = 0), or 0 when d has an entry that is not finite (then nothing is written).
/// Precondition: HasLuSolveHalfAvx512().
float RoundToHalfAvx512(Eigen::Index n, float* d, std::uint16_t* half);

/// out = base + a · slope + b · curve over n entries (slope and curve in half precision, their
/// scales folded into a and b; curve may be null). Precondition: HasLuSolveHalfAvx512().
void ExtrapolateHalfAvx512(Eigen::Index n, const float* base, float a, const std::uint16_t* slope,
                           float b, const std::uint16_t* curve, float* out);

}  // namespace stokesrods
