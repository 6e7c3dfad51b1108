// The mixed-precision product (solver/gemv_mixed.cc) against the same product summed in long
// double: both paths (AVX-512 where the CPU has it, and the portable loop) give the product of
// the stored single-precision matrix to double rounding, on sizes that are not whole blocks of
// eight or 64 rows, and any block of rows alone equals those rows of the whole.
#include <gtest/gtest.h>

#include <random>

#include "stokesrods/common/types.h"
#include "stokesrods/solver/blas.h"

namespace stokesrods {
namespace {

TEST(GemvRowsMixed, IsTheProductOfTheStoredMatrixToDoubleRounding) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (const int rows : {1, 7, 8, 9, 23, 64, 71, 390}) {
    for (const int cols : {1, 7, 8, 9, 17, 390}) {
      Eigen::MatrixXf a(rows, cols);
      VecX x(cols);
      for (int i = 0; i < rows; ++i)
        for (int j = 0; j < cols; ++j) a(i, j) = static_cast<float>(u(rng));
      for (int j = 0; j < cols; ++j) x[j] = u(rng) * 1e3;
      for (const bool portable : {false, true}) {
        VecX y(rows);
        GemvRowsMixed(a, 0, rows, x.data(), y.data(), portable);
        for (int i = 0; i < rows; ++i) {
          long double exact = 0.0L, magnitude = 0.0L;
          for (int j = 0; j < cols; ++j) {
            exact += static_cast<long double>(a(i, j)) * x[j];
            magnitude += std::abs(static_cast<long double>(a(i, j)) * x[j]);
          }
          // Recursive summation: at most cols · ε_double · Σ|a x| (a float rounding of the sums,
          // 6e-8 of the magnitude, would fail this by 1e5).
          EXPECT_LE(std::abs(static_cast<long double>(y[i]) - exact),
                    cols * 1.2e-16L * magnitude)
              << rows << " x " << cols << ", row " << i << (portable ? " portable" : "");
        }
        if (rows > 9) {  // rows 5 … 13 alone (a block not starting or ending at a multiple of 8)
          VecX part(9);
          GemvRowsMixed(a, 5, 9, x.data(), part.data(), portable);
          EXPECT_EQ(part, y.segment(5, 9));
        }
      }
    }
  }
}

}  // namespace
}  // namespace stokesrods
