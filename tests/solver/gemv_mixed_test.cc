// The mixed-precision product (solver/gemv_mixed.cc) against the same product summed in long
// double: every path (AVX-512 and AVX2 where the CPU has them, and the portable loop) gives the
// product of the stored single-precision matrix to double rounding, on sizes that are not whole
// blocks of four, eight, 48 or 64 rows, and any block of rows alone equals those rows of the
// whole. The two vector paths give the same bits (fused multiply–adds in the same order).
#include <gtest/gtest.h>

#include <random>

#include "stokesrods/common/types.h"
#include "stokesrods/solver/blas.h"

namespace stokesrods {
namespace {

TEST(GemvRowsMixed, IsTheProductOfTheStoredMatrixToDoubleRounding) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (const int rows : {1, 7, 8, 9, 23, 48, 50, 64, 71, 390}) {
    for (const int cols : {1, 7, 8, 9, 17, 390}) {
      Eigen::MatrixXf a(rows, cols);
      VecX x(cols);
      for (int i = 0; i < rows; ++i)
        for (int j = 0; j < cols; ++j) a(i, j) = static_cast<float>(u(rng));
      for (int j = 0; j < cols; ++j) x[j] = u(rng) * 1e3;
      VecX widest(rows), avx2(rows);
      GemvRowsMixed(a, 0, rows, x.data(), widest.data(), MixedGemvPath::kWidest);
      GemvRowsMixed(a, 0, rows, x.data(), avx2.data(), MixedGemvPath::kAvx2);
#if defined(__x86_64__)
      if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) {
        EXPECT_EQ(widest, avx2) << rows << " x " << cols;
      }
#endif
      for (const MixedGemvPath path :
           {MixedGemvPath::kWidest, MixedGemvPath::kAvx2, MixedGemvPath::kPortable}) {
        const bool portable = path == MixedGemvPath::kPortable;
        VecX padded = VecX::Constant(rows + 8, -7.0);  // nothing past the rows is written
        GemvRowsMixed(a, 0, rows, x.data(), padded.data(), path);
        EXPECT_TRUE((padded.tail(8).array() == -7.0).all()) << rows << " x " << cols;
        const VecX y = padded.head(rows);
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
              << rows << " x " << cols << ", row " << i << (portable ? " portable" : "")
              << (path == MixedGemvPath::kAvx2 ? " AVX2" : "");
        }
        if (rows > 9) {  // rows 5 … 13 alone (a block not starting or ending at a multiple of 8)
          VecX part = VecX::Constant(9 + 8, -7.0);
          GemvRowsMixed(a, 5, 9, x.data(), part.data(), path);
          EXPECT_EQ(part.head(9), y.segment(5, 9));
          EXPECT_TRUE((part.tail(8).array() == -7.0).all()) << rows << " x " << cols;
        }
      }
    }
  }
}

}  // namespace
}  // namespace stokesrods
