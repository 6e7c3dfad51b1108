// One right-hand side of a single-precision LU (as sgetrf leaves it) by a blocked substitution on
// AVX-512 (lu_solve_avx512.cc), or on AVX2 with FMA and F16C (lu_solve_avx2.cc, below);
// DenseLu<float>::Solve uses the widest the CPU has.
#pragma once

#include <cstdint>

namespace stokesrods {

/// The blocking of both: the small triangles of kLuBlock columns, then the rows below or above
/// by the block's panel; from n = kParallelLuSolve blocks of kLuWideBlock columns, the rows in
/// chunks of kLuChunkRows over the OpenMP threads (fixed chunks: the same result on any number).
inline constexpr int kLuBlock = 32;
inline constexpr int kLuWideBlock = 128;
/// 256 since 2026-11-28 (was 1024: at n = 2400 the rows below a block past row 1376 were one
/// chunk, on one thread; the half solve of E then took 762 µs on two threads against 590 on one,
/// and 567–658 with 256: bench_step BM_FloatLuSolve/half/2400, memory bound on the host's two
/// threads).
inline constexpr int kLuChunkRows = 256;
inline constexpr int kParallelLuSolve = 1024;

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

/// The same three on AVX2 with FMA and F16C (lu_solve_avx2.cc): the substitutions of
/// LuSolveAvx512 and LuSolveHalfAvx512 on vectors of eight (each row's operations, and so the
/// results, as theirs), and ConvertLuToHalf's rounding entry by entry (the same bits).
/// Precondition: HasLuSolveAvx2().
void LuSolveAvx2(int n, const float* lu, const int* pivots, float* x);
bool ConvertLuToHalfF16c(int n, const float* lu, std::uint16_t* half, float* u_scale);
void LuSolveHalfAvx2(int n, const std::uint16_t* half, const int* pivots, float u_scale, float* x);
/// True when the CPU has AVX2, FMA and F16C.
bool HasLuSolveAvx2();

}  // namespace stokesrods
