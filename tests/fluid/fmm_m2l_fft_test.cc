// The FMM's V-list translations by Fourier transforms (AddM2lByFft, fluid/fmm_m2l_fft.h) against
// the translations they replace, summed directly: check_i = Σ_e Σ_j S(x_i − y_j − v_e) up_e,j
// between the unit box's downward check surface and the equivalent surface of the box at offset
// v_e. Every one of the 316 V-list offsets is used, at the orders the FMM uses.
#include "stokesrods/fluid/fmm_m2l_fft.h"

#include <gtest/gtest.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#include <algorithm>
#include <cstdio>
#include <random>
#include <vector>

#include "stokesrods/fluid/stokeslet_segment.h"

namespace stokesrods {
namespace {

constexpr int kBoxes = 8;

/// A level of kBoxes boxes: box t's V list holds every offset o ≡ t (mod kBoxes) with |v|∞ ≥ 2,
/// each from a random source box; box kBoxes − 1 has an empty list.
FmmList EveryOffset(std::mt19937* rng) {
  FmmList list;
  std::uniform_int_distribution<int> box(0, kBoxes - 1);
  for (int t = 0; t < kBoxes; ++t) {
    for (int o = t; o < 343 && t < kBoxes - 1; o += kBoxes - 1) {
      const int vx = o / 49 - 3, vy = o / 7 % 7 - 3, vz = o % 7 - 3;
      if (std::max({std::abs(vx), std::abs(vy), std::abs(vz)}) < 2) continue;
      list.box.push_back(box(*rng));
      list.offset.push_back(o);
    }
    list.start.push_back(static_cast<int>(list.box.size()));
  }
  return list;
}

/// The worst over check points of |check − ref|_2 / Σ_e Σ_j |S(x_i − y_j)|_2 |up_e,j| (ref the
/// direct sum in double), and whether the box with an empty list kept its values.
template <class T>
double FftM2lError(int order, bool* empty_unchanged) {
  const FmmOperators& op = GetFmmOperators(order, 1e-6);
  const int n = op.points;
  std::mt19937 rng(11 + order);
  std::normal_distribution<double> normal;
  const FmmList list = EveryOffset(&rng);
  MatX up(3 * n, kBoxes);
  for (Eigen::Index k = 0; k < up.size(); ++k) up.data()[k] = normal(rng);
  MatX check = MatX::Constant(3 * n, kBoxes, 0.5);  // AddM2lByFft adds
  M2lFftScratch<T> scratch;
  AddM2lByFft(GetM2lSpectra(op), SortByOffset(list), up, &check, &scratch);
  *empty_unchanged = (check.col(kBoxes - 1).array() == 0.5).all();
  double worst = 0.0;
  for (int t = 0; t + 1 < kBoxes; ++t)
    for (int i = 0; i < n; ++i) {
      const Vec3 x = kFmmInnerRadius * op.surface.col(i);
      Vec3 ref = Vec3::Constant(0.5);
      double magnitude = 0.0;
      for (int e = list.start[static_cast<size_t>(t)]; e < list.start[static_cast<size_t>(t) + 1]; ++e) {
        const int o = list.offset[static_cast<size_t>(e)];
        const Vec3 shift(o / 49 - 3, o / 7 % 7 - 3, o % 7 - 3);
        for (int j = 0; j < n; ++j) {
          const Mat3 s = StokesletMatrix(x - (kFmmInnerRadius * op.surface.col(j) + shift));
          const Vec3 g = up.col(list.box[static_cast<size_t>(e)]).segment<3>(3 * j);
          ref += s * g;
          magnitude += s.norm() * g.norm();
        }
      }
      worst = std::max(worst, (check.block<3, 1>(3 * i, t) - ref).norm() / magnitude);
    }
  return worst;
}

// Double: the transforms' rounding only. Single precision (the FMM from tolerance 1e-4): float's
// ~6e-8 per operation over the N³-point transforms, well below the FMM's 1e-4.
TEST(FmmM2lFftTest, MatchesTheDirectTranslationsAtEveryOffset) {
  for (int order : {4, 5, 6}) {
    bool unchanged_double = false, unchanged_single = false;
    const double error_double = FftM2lError<double>(order, &unchanged_double);
    const double error_single = FftM2lError<float>(order, &unchanged_single);
    std::printf("M2L by FFT, p = %d: error %.2e (double), %.2e (single)\n", order, error_double,
                error_single);
    EXPECT_LT(error_double, 1e-13);
    EXPECT_LT(error_single, 1e-6);
    EXPECT_TRUE(unchanged_double);
    EXPECT_TRUE(unchanged_single);
  }
}

TEST(FmmM2lFftTest, ResultDoesNotDependOnTheThreadCount) {
#ifdef _OPENMP
  const FmmOperators& op = GetFmmOperators(4, 1e-6);
  std::mt19937 rng(5);
  std::normal_distribution<double> normal;
  const FmmList list = EveryOffset(&rng);
  MatX up(3 * op.points, kBoxes);
  for (Eigen::Index k = 0; k < up.size(); ++k) up.data()[k] = normal(rng);
  MatX check[2];
  const int saved = omp_get_max_threads();
  for (int threads = 1; threads <= 2; ++threads) {
    omp_set_num_threads(threads);
    check[threads - 1].setZero(3 * op.points, kBoxes);
    M2lFftScratch<float> scratch;
    AddM2lByFft(GetM2lSpectra(op), SortByOffset(list), up, &check[threads - 1], &scratch);
  }
  omp_set_num_threads(saved);
  EXPECT_TRUE(check[0] == check[1]);
#else
  GTEST_SKIP() << "built without OpenMP";
#endif
}

}  // namespace
}  // namespace stokesrods
