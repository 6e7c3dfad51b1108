// Where the parallel LU solves find the factors, and the half-precision factors' conversion
// (solver/lu_solve_avx512.h, LuPanels). Out of the instruction-set files: it allocates, and those
// define no inline code that others could share (scripts/check_isa_objects.sh).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "stokesrods/solver/lu_solve_avx512.h"

namespace stokesrods {

LuPanels HalfFactorLayout(int n) { return {.n = n, .tiled = n >= kParallelLuSolve}; }

std::size_t HalfFactorIndex(int n, int i, int j) {
  const LuPanels panels = HalfFactorLayout(n);
  if (!panels.tiled) return static_cast<std::size_t>(i) + static_cast<std::size_t>(j) * n;
  const auto chunk_at = [](int row, int first) {  // its chunk's first row, counted from first
    return first + (row - first) / kLuChunkRows * kLuChunkRows;
  };
  if (i > j) {  // L's block from the top
    const int j0 = j / kLuWideBlock * kLuWideBlock, j1 = std::min(j0 + kLuWideBlock, n);
    const auto column = static_cast<std::size_t>(j - j0);
    if (i < j1)
      return panels.LowerDiagonal(j0) + static_cast<std::size_t>(i - j0) + column * (j1 - j0);
    const int r = chunk_at(i, j1), rows = std::min(kLuChunkRows, n - r);
    return panels.LowerChunk(j0, j1, r) + static_cast<std::size_t>(i - r) + column * rows;
  }
  // U's block from the bottom
  const int j1 = n - (n - 1 - j) / kLuWideBlock * kLuWideBlock, j0 = std::max(j1 - kLuWideBlock, 0);
  const auto column = static_cast<std::size_t>(j - j0);
  if (i >= j0)
    return panels.UpperDiagonal(j0, j1) + static_cast<std::size_t>(i - j0) + column * (j1 - j0);
  const int r = chunk_at(i, 0), rows = std::min(kLuChunkRows, j0 - r);
  return panels.UpperChunk(j0, j1, r) + static_cast<std::size_t>(i - r) + column * rows;
}

void ArrangeHalfFactors(int n, const std::uint16_t* column_major, std::uint16_t* out) {
  const LuPanels panels = HalfFactorLayout(n);
  if (!panels.tiled) {
    std::copy_n(column_major, panels.Size(), out);
    return;
  }
  // Every place is written once below but the diagonal blocks' unread halves, zeroed there.
  // Rows [first, end) of column j into the chunks from `first` of a block (its column `column`);
  // `chunk(r)` is where the chunk from row r starts.
  const auto to_chunks = [&](int j, int first, int end, std::size_t column, const auto& chunk) {
    for (int r = first; r < end; r += kLuChunkRows) {
      const int rows = std::min(kLuChunkRows, end - r);
      std::copy_n(column_major + r + static_cast<std::size_t>(j) * n, rows,
                  out + chunk(r) + column * static_cast<std::size_t>(rows));
    }
  };
  for (int j0 = 0; j0 < n; j0 += kLuWideBlock) {  // L: strictly lower parts, then rows below
    const int j1 = std::min(j0 + kLuWideBlock, n);
    const auto w = static_cast<std::size_t>(j1 - j0);
    std::fill_n(out + panels.LowerDiagonal(j0), w * w, std::uint16_t{0});
    for (int j = j0; j < j1; ++j) {
      const auto column = static_cast<std::size_t>(j - j0);
      const std::uint16_t* in = column_major + static_cast<std::size_t>(j) * n;
      std::copy(in + j + 1, in + j1, out + panels.LowerDiagonal(j0) + column * w + column + 1);
      to_chunks(j, j1, n, column, [&](int r) { return panels.LowerChunk(j0, j1, r); });
    }
  }
  for (int j1 = n; j1 > 0; j1 -= kLuWideBlock) {  // U: upper parts with the diagonal, rows above
    const int j0 = std::max(j1 - kLuWideBlock, 0);
    const auto w = static_cast<std::size_t>(j1 - j0);
    std::fill_n(out + panels.UpperDiagonal(j0, j1), w * w, std::uint16_t{0});
    for (int j = j0; j < j1; ++j) {
      const auto column = static_cast<std::size_t>(j - j0);
      const std::uint16_t* in = column_major + static_cast<std::size_t>(j) * n;
      std::copy(in + j0, in + j + 1, out + panels.UpperDiagonal(j0, j1) + column * w);
      to_chunks(j, 0, j0, column, [&](int r) { return panels.UpperChunk(j0, j1, r); });
    }
  }
}

namespace {

// A rounding kernel's column-major output, into HalfFactorLayout(n) where that tiles.
bool ToLayout(int n, const float* lu, std::uint16_t* half, float* u_scale,
              bool (*round)(int, const float*, std::uint16_t*, float*)) {
  if (!HalfFactorLayout(n).tiled) return round(n, lu, half, u_scale);
  // Kept from call to call: at a hundred helices E's 11.5 MB, zeroed and faulted in at every
  // rebuild otherwise.
  thread_local std::vector<std::uint16_t> column_major;
  column_major.resize(static_cast<std::size_t>(n) * static_cast<std::size_t>(n));
  if (!round(n, lu, column_major.data(), u_scale)) return false;
  ArrangeHalfFactors(n, column_major.data(), half);
  return true;
}

}  // namespace

bool ConvertLuToHalf(int n, const float* lu, std::uint16_t* half, float* u_scale) {
  return ToLayout(n, lu, half, u_scale, RoundLuToHalfAvx512);
}

bool ConvertLuToHalfF16c(int n, const float* lu, std::uint16_t* half, float* u_scale) {
  return ToLayout(n, lu, half, u_scale, RoundLuToHalfF16c);
}

}  // namespace stokesrods
