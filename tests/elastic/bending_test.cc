#include "stokesrods/elastic/bending.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdio>
#include <random>

#include "elastic/stencil.h"

namespace stokesrods {
namespace {

using testing::CheckByFiniteDifferences;
using testing::Pack;
using testing::RandomStencil;
using testing::Stencil;
using testing::StencilEnergy;

StencilEnergy Bending(const BendingParams& p) {
  return [p](const Stencil& s, Vec11* g, Mat11* h) {
    return BendingEnergy(p, s.x[0], s.x[1], s.x[2], s.f[0], s.f[1], s.theta[0], s.theta[1], g, h);
  };
}

Vec2 Curvatures(const Stencil& s) {
  return MaterialCurvatures(s.x[0], s.x[1], s.x[2], s.f[0], s.f[1], s.theta[0], s.theta[1]);
}

// Gradient and Hessian against central differences of the energy (gradient) and of the analytic
// gradient (Hessian), the frames being re-transported for every perturbed q. A rest curvature
// different from the current one keeps the second-derivative terms of κ in the Hessian.
void CheckAtScale(double length) {
  double worst_gradient = 0.0;
  double worst_hessian = 0.0;
  for (unsigned seed = 1; seed <= 20; ++seed) {
    std::mt19937 rng(seed);
    const Stencil s = RandomStencil(rng, length);
    std::uniform_real_distribution<double> uniform(-1.0, 1.0);
    const BendingParams p{2.5 * length, Vec2(uniform(rng), uniform(rng))};
    const auto r = CheckByFiniteDifferences(Bending(p), s, length);
    EXPECT_LT(r.gradient_error, 1e-6) << "seed " << seed;
    EXPECT_LT(r.hessian_error, 1e-6) << "seed " << seed;
    worst_gradient = std::max(worst_gradient, r.gradient_error);
    worst_hessian = std::max(worst_hessian, r.hessian_error);
  }
  std::printf("bending, L = %g m: worst relative FD error gradient %.2e, Hessian %.2e\n", length,
              worst_gradient, worst_hessian);
}

// The gradient Jacobian is not symmetric away from rest (the re-based frames pick up the holonomy
// of the tangents' motion); its symmetric part is the second derivative of the energy with the
// frames transported from the unperturbed state, checked here by second differences of E alone.
TEST(BendingEnergy, SymmetricPartIsTheEnergyHessian) {
  for (double length : {1e-6, 1.0, 1e2}) {
    double worst = 0.0;
    double asymmetry = 0.0;
    for (unsigned seed = 1; seed <= 10; ++seed) {
      std::mt19937 rng(seed);
      const Stencil s = RandomStencil(rng, length);
      std::uniform_real_distribution<double> uniform(-1.0, 1.0);
      const BendingParams p{2.5 * length, Vec2(uniform(rng), uniform(rng))};
      const double error = testing::CheckSymmetricPartBySecondDifferences(Bending(p), s, length);
      EXPECT_LT(error, 1e-6) << "seed " << seed << ", L = " << length;
      worst = std::max(worst, error);
      Mat11 h;
      Bending(p)(s, nullptr, &h);
      const Vec11 d = testing::DofScale(length);
      const Mat11 scaled = d.asDiagonal() * h * d.asDiagonal();
      asymmetry = std::max(asymmetry, (scaled - scaled.transpose()).norm() / scaled.norm());
    }
    std::printf("bending, L = %g m: energy second differences vs symmetric part %.2e "
                "(largest asymmetry of the Jacobian %.2e)\n", length, worst, asymmetry);
  }
}

TEST(BendingEnergy, MatchesFiniteDifferencesAtUnitScale) { CheckAtScale(1.0); }
TEST(BendingEnergy, MatchesFiniteDifferencesAtMicrometres) { CheckAtScale(1e-6); }
TEST(BendingEnergy, MatchesFiniteDifferencesAtHundredMetres) { CheckAtScale(1e2); }

TEST(BendingEnergy, PlanarBendHasTheClosedFormCurvature) {
  // Edges along x̂ and at angle φ in the xy plane, d1 = ẑ on both: κb = 2 tan(φ/2) ẑ, so
  // κ⁽¹⁾ = ½ (m2⁰ + m2¹)·κb = 0 and κ⁽²⁾ = −½ (m1⁰ + m1¹)·κb = −2 tan(φ/2) at θ = 0; at
  // θ = π/2 on both edges m1 = d2, m2 = −d1, so κ⁽¹⁾ = −2 tan(φ/2) and κ⁽²⁾ = 0.
  const double phi = 0.8;
  const Vec3 x0(-1.0, 0.0, 0.0);
  const Vec3 x1 = Vec3::Zero();
  const Vec3 x2(std::cos(phi), std::sin(phi), 0.0);
  const Vec3 t1 = x2 - x1;
  const RefFrame f0{Vec3::UnitZ(), Vec3::UnitX().cross(Vec3::UnitZ())};
  const RefFrame f1{Vec3::UnitZ(), t1.cross(Vec3::UnitZ())};
  const Vec2 k = MaterialCurvatures(x0, x1, x2, f0, f1, 0.0, 0.0);
  EXPECT_NEAR(k[0], 0.0, 1e-15);
  EXPECT_NEAR(k[1], -2.0 * std::tan(phi / 2), 1e-15);
  const Vec2 k_twisted = MaterialCurvatures(x0, x1, x2, f0, f1, kPi / 2, kPi / 2);
  EXPECT_NEAR(k_twisted[0], -2.0 * std::tan(phi / 2), 1e-15);
  EXPECT_NEAR(k_twisted[1], 0.0, 1e-15);
  const double ei = 3.0;
  EXPECT_NEAR(BendingEnergy({ei, Vec2::Zero()}, x0, x1, x2, f0, f1, 0.0, 0.0),
              0.5 * ei * std::pow(2.0 * std::tan(phi / 2), 2), 1e-14);
}

TEST(BendingEnergy, ZeroGradientAndPositiveHessianAtRest) {
  for (unsigned seed = 1; seed <= 5; ++seed) {
    std::mt19937 rng(seed);
    const Stencil s = RandomStencil(rng, 1e-3);
    const BendingParams p{4.0, Curvatures(s)};
    Vec11 g;
    Mat11 h;
    EXPECT_EQ(Bending(p)(s, &g, &h), 0.0);
    EXPECT_LT(g.norm(), 1e-12 * p.stiffness / 1e-3);
    // At rest the Hessian is k Σ ∇κ ∇κᵀ: symmetric positive semi-definite of rank 2.
    const Eigen::SelfAdjointEigenSolver<Mat11> eig(h);
    EXPECT_GT(eig.eigenvalues().minCoeff(), -1e-10 * eig.eigenvalues().maxCoeff());
    // Moving away from rest costs energy, quadratically in the step.
    const Vec11 dq = 1e-8 * h.col(0).normalized();  // [m] or [rad]
    const double e1 = Bending(p)(testing::Perturb(s, Pack(s) + dq), nullptr, nullptr);
    const double e2 = Bending(p)(testing::Perturb(s, Pack(s) + 2.0 * dq), nullptr, nullptr);
    EXPECT_GT(e1, 0.0);
    EXPECT_NEAR(e2 / e1, 4.0, 1e-3);
  }
}

TEST(BendingEnergy, InvariantUnderRigidMotion) {
  for (unsigned seed = 1; seed <= 5; ++seed) {
    std::mt19937 rng(seed);
    const Stencil s = RandomStencil(rng, 0.01);
    const Mat3 r = Eigen::AngleAxisd(1.3, Vec3(1.0, -2.0, 0.5).normalized()).toRotationMatrix();
    const Stencil moved = testing::RigidlyMoved(s, r, Vec3(0.3, -7.0, 2.0));
    const BendingParams p{1.7, Vec2(0.2, -0.4)};
    Vec11 g;
    Vec11 g_moved;
    Mat11 h;
    Mat11 h_moved;
    const double e = Bending(p)(s, &g, &h);
    EXPECT_NEAR(Bending(p)(moved, &g_moved, &h_moved), e, 1e-12 * e);
    // Forces rotate with the body, moments do not: Q g, Q H Qᵀ with Q = diag(R, 1, R, 1, R).
    Mat11 q = Mat11::Identity();
    for (int b : {0, 4, 8}) q.block<3, 3>(b, b) = r;
    EXPECT_LT((g_moved - q * g).norm(), 1e-10 * g.norm());
    EXPECT_LT((h_moved - q * h * q.transpose()).norm(), 1e-10 * h.norm());
  }
}

TEST(BendingEnergy, CurvaturesDoNotDependOnTheLengthScale) {
  std::mt19937 rng(11);
  const Stencil s = RandomStencil(rng, 1.0);
  for (double scale : {1e-6, 1e2}) {
    Stencil scaled = s;
    for (Vec3& x : scaled.x) x *= scale;
    EXPECT_LT((Curvatures(scaled) - Curvatures(s)).norm(), 1e-13 * Curvatures(s).norm());
  }
}

}  // namespace
}  // namespace stokesrods
