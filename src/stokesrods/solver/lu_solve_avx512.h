// One right-hand side of a single-precision LU (as sgetrf leaves it) by a blocked substitution on
// AVX-512 (lu_solve_avx512.cc); DenseLu<float>::Solve uses it where the CPU has AVX-512.
#pragma once

namespace stokesrods {

/// x ← A⁻¹ x, A = P L U column-major with leading dimension n, `pivots` 1-based (LAPACK's).
/// Precondition: HasLuSolveAvx512().
void LuSolveAvx512(int n, const float* lu, const int* pivots, float* x);
/// True when the CPU runs LuSolveAvx512.
bool HasLuSolveAvx512();

}  // namespace stokesrods
