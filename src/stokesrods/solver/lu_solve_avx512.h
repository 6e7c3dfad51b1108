// One right-hand side of a single-precision LU (as sgetrf leaves it) by a blocked substitution on
// AVX-512 (lu_solve_avx512.cc); DenseLu<float>::Solve uses it where the CPU has AVX-512.
#pragma once

#include <cstdint>

namespace stokesrods {

/// x ← A⁻¹ x, A = P L U column-major with leading dimension n, `pivots` 1-based (LAPACK's).
/// Precondition: HasLuSolveAvx512().
void LuSolveAvx512(int n, const float* lu, const int* pivots, float* x);
/// True when the CPU runs LuSolveAvx512.
bool HasLuSolveAvx512();

/// The factors of LuSolveAvx512 in IEEE half precision (lu_solve_avx512.cc): L as it is (|L| ≤ 1
/// with partial pivoting), U times `u_scale`, a power of two that puts its largest entry near
/// 2¹⁴ (half precision's range ends at 65504). Returns false (and writes nothing) when U has an
/// entry that is not finite. Precondition: HasLuSolveHalfAvx512().
bool ConvertLuToHalf(int n, const float* lu, std::uint16_t* half, float* u_scale);
/// x ← A⁻¹ x from ConvertLuToHalf's factors: the substitution of LuSolveAvx512, each entry
/// widened to single precision as it is read (the arithmetic stays single): LuSolveAvx512 on the
/// rounded factors, to single-precision rounding. Precondition: HasLuSolveHalfAvx512().
void LuSolveHalfAvx512(int n, const std::uint16_t* half, const int* pivots, float u_scale,
                       float* x);
/// True when the CPU has AVX-512 F, BW and VL (and so F16C): the half precision loads.
bool HasLuSolveHalfAvx512();

}  // namespace stokesrods
