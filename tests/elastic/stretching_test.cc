#include "stokesrods/elastic/stretching.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <random>

namespace stokesrods {
namespace {

Vec3 RandomVec(std::mt19937& rng) {
  std::normal_distribution<double> normal;
  return Vec3(normal(rng), normal(rng), normal(rng));
}

// Central differences with step h·L of the energy (gradient) and the gradient (Hessian); errors
// are relative in norm. Returns {gradient error, Hessian error}.
std::pair<double, double> FiniteDifferenceErrors(const StretchingParams& p, const Vec3& x0,
                                                 const Vec3& x1, double length) {
  Vec6 q;
  q << x0, x1;
  Vec6 g;
  Mat6 h;
  StretchingEnergy(p, x0, x1, &g, &h);
  Vec6 g_fd;
  Mat6 h_fd;
  const double step = 1e-5 * length;
  for (int k = 0; k < 6; ++k) {
    Vec6 plus = q;
    Vec6 minus = q;
    plus[k] += step;
    minus[k] -= step;
    Vec6 g_plus;
    Vec6 g_minus;
    const double e_plus = StretchingEnergy(p, plus.head<3>(), plus.tail<3>(), &g_plus);
    const double e_minus = StretchingEnergy(p, minus.head<3>(), minus.tail<3>(), &g_minus);
    g_fd[k] = (e_plus - e_minus) / (2.0 * step);
    h_fd.col(k) = (g_plus - g_minus) / (2.0 * step);
  }
  return {(g_fd - g).norm() / g.norm(), (h_fd - h).norm() / h.norm()};
}

void CheckAtScale(double length) {
  double worst_gradient = 0.0;
  double worst_hessian = 0.0;
  for (unsigned seed = 1; seed <= 20; ++seed) {
    std::mt19937 rng(seed);
    const Vec3 x0 = length * RandomVec(rng);
    const Vec3 x1 = x0 + length * RandomVec(rng);
    std::uniform_real_distribution<double> stretch(0.5, 1.5);  // strains −0.33 … +1
    const StretchingParams p{3.0e3, (x1 - x0).norm() * stretch(rng)};
    const auto [gradient_error, hessian_error] = FiniteDifferenceErrors(p, x0, x1, length);
    EXPECT_LT(gradient_error, 1e-6) << "seed " << seed;
    EXPECT_LT(hessian_error, 1e-6) << "seed " << seed;
    worst_gradient = std::max(worst_gradient, gradient_error);
    worst_hessian = std::max(worst_hessian, hessian_error);
  }
  std::printf("stretching, L = %g m: worst relative FD error gradient %.2e, Hessian %.2e\n",
              length, worst_gradient, worst_hessian);
}

TEST(StretchingEnergy, MatchesFiniteDifferencesAtUnitScale) { CheckAtScale(1.0); }
TEST(StretchingEnergy, MatchesFiniteDifferencesAtMicrometres) { CheckAtScale(1e-6); }
TEST(StretchingEnergy, MatchesFiniteDifferencesAtHundredMetres) { CheckAtScale(1e2); }

TEST(StretchingEnergy, StrainIsCurrentOverRestLengthMinusOne) {
  // |e| = 2, |ē| = 1.6: ε = 0.25, E = ½ EA |ē| ε², force EA ε pulling the nodes together.
  const StretchingParams p{10.0, 1.6};
  const Vec3 x0(1.0, 1.0, 1.0);
  const Vec3 x1 = x0 + Vec3(0.0, 2.0, 0.0);
  Vec6 g;
  EXPECT_NEAR(StretchingEnergy(p, x0, x1, &g), 0.5 * 10.0 * 1.6 * 0.0625, 1e-14);
  EXPECT_LT((g.tail<3>() - Vec3(0.0, 2.5, 0.0)).norm(), 1e-14);
  EXPECT_LT((g.head<3>() + g.tail<3>()).norm(), 0.0 + 1e-15);
}

TEST(StretchingEnergy, ZeroGradientAtRest) {
  std::mt19937 rng(5);
  const Vec3 x0 = RandomVec(rng);
  const Vec3 x1 = x0 + RandomVec(rng);
  const StretchingParams p{7.0, (x1 - x0).norm()};
  Vec6 g;
  Mat6 h;
  EXPECT_EQ(StretchingEnergy(p, x0, x1, &g, &h), 0.0);
  EXPECT_EQ(g.norm(), 0.0);
  // At rest only the axial stiffness EA/|ē| along t remains.
  const Vec3 t = (x1 - x0).normalized();
  EXPECT_LT((h.topLeftCorner<3, 3>() - p.axial_stiffness / p.rest_length * t * t.transpose())
                .norm(), 1e-13);
}

TEST(StretchingEnergy, InvariantUnderRigidMotion) {
  std::mt19937 rng(6);
  const Vec3 x0 = RandomVec(rng);
  const Vec3 x1 = x0 + RandomVec(rng);
  const StretchingParams p{7.0, 0.8 * (x1 - x0).norm()};
  const Mat3 r = Eigen::AngleAxisd(0.9, Vec3(1.0, 1.0, -1.0).normalized()).toRotationMatrix();
  const Vec3 c(10.0, -3.0, 2.0);
  Vec6 g;
  Vec6 g_moved;
  const double e = StretchingEnergy(p, x0, x1, &g);
  EXPECT_NEAR(StretchingEnergy(p, r * x0 + c, r * x1 + c, &g_moved), e, 1e-13 * e);
  EXPECT_LT((g_moved.head<3>() - r * g.head<3>()).norm(), 1e-12 * g.norm());
  EXPECT_LT((g_moved.tail<3>() - r * g.tail<3>()).norm(), 1e-12 * g.norm());
}

}  // namespace
}  // namespace stokesrods
