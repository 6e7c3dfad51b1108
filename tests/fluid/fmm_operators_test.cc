// The FMM's M2L evaluated on the fly (AddM2l, fluid/fmm_operators.h) against the dense translation
// it replaced: K_v = [S(x_i − y_j)] between the unit box's check surface and the equivalent surface
// of the box at offset v, times the source boxes' upward densities.
#include "stokesrods/fluid/fmm_operators.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <random>
#include <vector>

#include "stokesrods/fluid/stokeslet_segment.h"

namespace stokesrods {
namespace {

// Per check point i: |AddM2l − Σ_e K_{v_e} up_e|_2 / Σ_e Σ_j |S(x_i − y_j)|_2 |up_e,j|, the worst.
double M2lError(int order, bool single) {
  const FmmOperators& op = GetFmmOperators(order, 1e-6);
  const int n = op.points;
  // V-list entries: the extreme offsets, one on a face, and a source box used twice.
  const std::vector<std::array<int, 3>> v = {{3, 3, 3}, {-3, -3, -3}, {2, 0, -1}, {-2, 1, 3},
                                             {0, -3, 2}, {3, -2, -2}};
  const std::vector<int> boxes = {0, 1, 2, 3, 4, 2};
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  MatX up(3 * n, 5);
  for (Eigen::Index k = 0; k < up.size(); ++k) up.data()[k] = normal(rng);
  std::vector<int> offsets;
  for (const auto& [x, y, z] : v) offsets.push_back(M2lIndex(x, y, z));
  VecX check = VecX::Zero(3 * n);
  M2lScratch scratch;
  AddM2l(op, boxes.data(), offsets.data(), static_cast<int>(boxes.size()), up, single, &scratch,
         check.data());
  double worst = 0.0;
  for (int i = 0; i < n; ++i) {
    const Vec3 x = kFmmInnerRadius * op.surface.col(i);
    Vec3 ref = Vec3::Zero();
    double magnitude = 0.0;
    for (std::size_t e = 0; e < v.size(); ++e) {
      const Vec3 shift(v[e][0], v[e][1], v[e][2]);
      for (int j = 0; j < n; ++j) {
        const Mat3 s = StokesletMatrix(x - (kFmmInnerRadius * op.surface.col(j) + shift));
        const Vec3 g = up.col(boxes[e]).segment<3>(3 * j);
        ref += s * g;
        magnitude += s.norm() * g.norm();
      }
    }
    worst = std::max(worst, (check.segment<3>(3 * i) - ref).norm() / magnitude);
  }
  return worst;
}

// Double: rounding only. Single precision (the FMM from tolerance 1e-4): float's ~6e-8 of each
// term and of the positions (in box widths, up to 3.5 from the box), well below the 1e-4.
TEST(FmmOperatorsTest, M2lOnTheFlyMatchesTheDenseTranslation) {
  for (int order : {4, 5}) {
    const double error_double = M2lError(order, false), error_single = M2lError(order, true);
    std::printf("M2L on the fly, p = %d: error %.2e (double), %.2e (single)\n", order,
                error_double, error_single);
    EXPECT_LT(error_double, 1e-14);
    EXPECT_LT(error_single, 1e-6);
  }
}

TEST(FmmOperatorsTest, EmptyListAddsNothing) {
  const FmmOperators& op = GetFmmOperators(4, 1e-6);
  VecX check = VecX::Constant(3 * op.points, 2.0);
  M2lScratch scratch;
  AddM2l(op, nullptr, nullptr, 0, MatX(3 * op.points, 1), true, &scratch, check.data());
  EXPECT_TRUE((check.array() == 2.0).all());
}

}  // namespace
}  // namespace stokesrods
