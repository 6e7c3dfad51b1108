// One right-hand side of a single-precision LU (as sgetrf leaves it) by a blocked substitution on
// AVX-512 (lu_solve_avx512.cc), or on AVX2 with FMA and F16C (lu_solve_avx2.cc, below);
// DenseLu<float>::Solve uses the widest the CPU has.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>

namespace stokesrods {

/// Memory a solve brings into the L2 cache a little at a time while it works (the factors of the
/// next solve of a sequence: SolveBlocks' rods), instead of all at once before it: a burst of
/// prefetches fills the CPU's queue of misses and then waits on it. Empty: none.
struct PrefetchSpan {
  const char* first = nullptr;
  std::size_t bytes = 0;
};
/// A PrefetchSpan spread over `steps` calls of Next(), each asking for its next share of the
/// span's cache lines (prefetcht1: into L2).
class SpreadPrefetch {
 public:
  SpreadPrefetch(PrefetchSpan span, int steps)
      : span_(span), share_(steps > 0 ? (span.bytes + static_cast<std::size_t>(steps) - 1) /
                                            static_cast<std::size_t>(steps)
                                      : span.bytes) {}
  void Next() {
    const std::size_t stop = std::min(done_ + share_, span_.bytes);
    for (; done_ < stop; done_ += 64) __builtin_prefetch(span_.first + done_, 0, 2);
  }

 private:
  PrefetchSpan span_;
  std::size_t share_ = 0, done_ = 0;
};

/// The blocking of both: the small triangles of kLuBlock columns, then the rows below or above
/// by the block's panel; from n = kParallelLuSolve blocks of kLuWideBlock columns, the rows in
/// chunks of kLuChunkRows over the OpenMP threads (each row's operations are the same whatever
/// chunk or thread takes it: the same result on any number of threads).
inline constexpr int kLuBlock = 32;
inline constexpr int kLuWideBlock = 128;
/// 128 since 2026-11-29 (256 from 2026-11-28, 1024 before: at n = 2400 the rows below a block
/// past row 1376 were one chunk, on one thread). With the half factors in tiles of this many rows
/// (LuPanels), smaller tiles balance the two threads better at the same streaming.
inline constexpr int kLuChunkRows = 128;
inline constexpr int kParallelLuSolve = 1024;

/// Where the parallel solves (n ≥ kParallelLuSolve) find the factors: column-major with leading
/// dimension n (single precision), or, for the half-precision factors of ConvertLuToHalf, in
/// tiles. L's sweep takes blocks of kLuWideBlock columns [j0, j1) from the top (j0 a multiple of
/// kLuWideBlock), U's from the bottom (j1 = n minus a multiple); each reads its block's diagonal
/// block (L's strictly lower part, U's upper part) and then its rows below (L: [j1, n), in
/// chunks of kLuChunkRows rows from j1) or above (U: [0, j0), in chunks from 0). Tiled, L's blocks
/// come first, in their order, then U's, in theirs; each block is its diagonal block
/// (column-major, leading dimension j1 − j0) followed by its chunks, each chunk column-major with
/// its own row count as leading dimension. A solve then reads each chunk, and each block's chunks
/// in turn, from consecutive memory: read by chunks in place, a column-major 2400 × 2400 jumps n
/// entries at every column of a chunk, which streamed 5 GB/s from memory here against 9 GB/s
/// for consecutive reads (docs/performance.md, session 32). Which chunk, thread or layout holds
/// a row changes none of its arithmetic.
struct LuPanels {
  int n = 0;
  bool tiled = false;

  /// The first entry of the diagonal block of L's block [j0, j1) (U's: UpperDiagonal).
  std::size_t LowerDiagonal(int j0) const {
    return tiled ? Before(j0 / kLuWideBlock) : Square(j0);
  }
  /// The first entry of the chunk of rows from r (r = j1 + a multiple of kLuChunkRows) of L's
  /// block [j0, j1).
  std::size_t LowerChunk(int j0, int j1, int r) const {
    if (!tiled) return Square(j0) + static_cast<std::size_t>(r - j0);
    const auto w = static_cast<std::size_t>(j1 - j0);
    return LowerDiagonal(j0) + w * w + static_cast<std::size_t>(r - j1) * w;
  }
  std::size_t UpperDiagonal(int j0, int j1) const {
    return tiled ? LowerSize() + Before((n - j1) / kLuWideBlock) : Square(j0);
  }
  /// The first entry of the chunk of rows from r (a multiple of kLuChunkRows) of U's [j0, j1).
  std::size_t UpperChunk(int j0, int j1, int r) const {
    if (!tiled) return static_cast<std::size_t>(r) + static_cast<std::size_t>(j0) * n;
    const auto w = static_cast<std::size_t>(j1 - j0);
    return UpperDiagonal(j0, j1) + w * w + static_cast<std::size_t>(r) * w;
  }
  /// Leading dimensions: of a diagonal block of width w, of a chunk of `rows` rows.
  std::ptrdiff_t DiagonalStride(int w) const { return tiled ? w : n; }
  std::ptrdiff_t ChunkStride(int rows) const { return tiled ? rows : n; }
  /// The entries the factors take.
  std::size_t Size() const {
    return tiled ? 2 * LowerSize() : static_cast<std::size_t>(n) * static_cast<std::size_t>(n);
  }

 private:
  std::size_t Square(int j0) const {
    return static_cast<std::size_t>(j0) + static_cast<std::size_t>(j0) * n;
  }
  // The entries of the first b blocks of either sweep (all kLuWideBlock wide), each w² and w by
  // the n − (k + 1) w rows past it: b w² + w (b n − w b (b + 1) / 2).
  std::size_t Before(int b) const {
    const std::size_t w = kLuWideBlock, bs = static_cast<std::size_t>(b);
    return bs * w * w + w * (bs * static_cast<std::size_t>(n) - w * bs * (bs + 1) / 2);
  }
  std::size_t LowerSize() const {
    const int blocks = (n + kLuWideBlock - 1) / kLuWideBlock;
    const auto last = static_cast<std::size_t>(n - (blocks - 1) * kLuWideBlock);
    return Before(blocks - 1) + last * last;
  }
};
/// The layout of ConvertLuToHalf's (and ConvertLuToHalfF16c's) output: column-major below
/// kParallelLuSolve, LuPanels' tiles from there on.
LuPanels HalfFactorLayout(int n);
/// Where entry (i, j) of the factors sits in it (the place the solve reads).
std::size_t HalfFactorIndex(int n, int i, int j);
/// The column-major half factors (n², leading dimension n) into their places in
/// HalfFactorLayout(n) (its Size() entries; the diagonal blocks' unread halves zero).
void ArrangeHalfFactors(int n, const std::uint16_t* column_major, std::uint16_t* out);

/// x ← A⁻¹ x, A = P L U column-major with leading dimension n, `pivots` 1-based (LAPACK's).
/// Precondition: HasLuSolveAvx512().
void LuSolveAvx512(int n, const float* lu, const int* pivots, float* x);
/// True when the CPU runs LuSolveAvx512.
bool HasLuSolveAvx512();

/// The factors of LuSolveAvx512 in IEEE half precision (lu_solve_avx512.cc): L as it is (|L| ≤ 1
/// with partial pivoting), U times `u_scale`, a power of two that puts its largest entry near
/// 2¹⁴ (half precision's range ends at 65504), HalfFactorLayout(n).Size() entries where
/// HalfFactorIndex says. Returns false (and writes nothing) when U has an entry that is not
/// finite. Precondition: HasLuSolveHalfAvx512().
bool ConvertLuToHalf(int n, const float* lu, std::uint16_t* half, float* u_scale);
/// x ← A⁻¹ x from ConvertLuToHalf's factors: the substitution of LuSolveAvx512, each entry
/// widened to single precision as it is read (the arithmetic stays single): LuSolveAvx512 on the
/// rounded factors, to single-precision rounding. Precondition: HasLuSolveHalfAvx512().
/// `then`: prefetched along the way (below kParallelLuSolve).
void LuSolveHalfAvx512(int n, const std::uint16_t* half, const int* pivots, float u_scale,
                       float* x, PrefetchSpan then = {});
/// True when the CPU has AVX-512 F, BW and VL (and so F16C): the half precision loads.
bool HasLuSolveHalfAvx512();

/// The same three on AVX2 with FMA and F16C (lu_solve_avx2.cc): the substitutions of
/// LuSolveAvx512 and LuSolveHalfAvx512 on vectors of eight (each row's operations, and so the
/// results, as theirs), and ConvertLuToHalf's rounding entry by entry (the same bits).
/// Precondition: HasLuSolveAvx2().
void LuSolveAvx2(int n, const float* lu, const int* pivots, float* x);
bool ConvertLuToHalfF16c(int n, const float* lu, std::uint16_t* half, float* u_scale);
/// The two conversions' rounding alone, column-major with leading dimension n (the kernels of
/// the instruction-set files; ConvertLuToHalf and ConvertLuToHalfF16c then place the entries,
/// lu_layout.cc). Preconditions as theirs.
bool RoundLuToHalfAvx512(int n, const float* lu, std::uint16_t* half, float* u_scale);
bool RoundLuToHalfF16c(int n, const float* lu, std::uint16_t* half, float* u_scale);
void LuSolveHalfAvx2(int n, const std::uint16_t* half, const int* pivots, float u_scale, float* x,
                     PrefetchSpan then = {});
/// True when the CPU has AVX2, FMA and F16C.
bool HasLuSolveAvx2();

}  // namespace stokesrods
