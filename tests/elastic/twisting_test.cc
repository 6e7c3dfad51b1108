#include "stokesrods/elastic/twisting.h"

#include <gtest/gtest.h>

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

StencilEnergy Twisting(const TwistingParams& p) {
  return [p](const Stencil& s, Vec11* g, Mat11* h) {
    return TwistingEnergy(p, s.x[0], s.x[1], s.x[2], s.theta[0], s.theta[1], s.reference_twist, g,
                          h);
  };
}

double Twist(const Stencil& s) { return s.theta[1] - s.theta[0] + s.reference_twist; }

// As for bending: FD of the energy and of the analytic gradient, with the frames transported and
// the reference twist recomputed (on the branch of the unperturbed one) at every perturbed q.
void CheckAtScale(double length) {
  double worst_gradient = 0.0;
  double worst_hessian = 0.0;
  for (unsigned seed = 1; seed <= 20; ++seed) {
    std::mt19937 rng(seed);
    const Stencil s = RandomStencil(rng, length);
    std::uniform_real_distribution<double> uniform(-1.0, 1.0);
    const TwistingParams p{0.8 * length, Twist(s) + uniform(rng)};  // τ − τ̄ of order 1
    const auto r = CheckByFiniteDifferences(Twisting(p), s, length);
    EXPECT_LT(r.gradient_error, 1e-6) << "seed " << seed;
    EXPECT_LT(r.hessian_error, 1e-6) << "seed " << seed;
    worst_gradient = std::max(worst_gradient, r.gradient_error);
    worst_hessian = std::max(worst_hessian, r.hessian_error);
  }
  std::printf("twisting, L = %g m: worst relative FD error gradient %.2e, Hessian %.2e\n", length,
              worst_gradient, worst_hessian);
}

// The gradient Jacobian is not symmetric away from rest (the re-based frames pick up the holonomy
// of the tangents' motion); its symmetric part is the second derivative of the energy with the
// frames transported from the unperturbed state, checked here by second differences of E alone.
TEST(TwistingEnergy, SymmetricPartIsTheEnergyHessian) {
  for (double length : {1e-6, 1.0, 1e2}) {
    double worst = 0.0;
    double asymmetry = 0.0;
    for (unsigned seed = 1; seed <= 10; ++seed) {
      std::mt19937 rng(seed);
      const Stencil s = RandomStencil(rng, length);
      std::uniform_real_distribution<double> uniform(-1.0, 1.0);
      const TwistingParams p{0.8 * length, Twist(s) + uniform(rng)};
      const double error = testing::CheckSymmetricPartBySecondDifferences(Twisting(p), s, length);
      EXPECT_LT(error, 1e-6) << "seed " << seed << ", L = " << length;
      worst = std::max(worst, error);
      Mat11 h;
      Twisting(p)(s, nullptr, &h);
      const Vec11 d = testing::DofScale(length);
      const Mat11 scaled = d.asDiagonal() * h * d.asDiagonal();
      asymmetry = std::max(asymmetry, (scaled - scaled.transpose()).norm() / scaled.norm());
    }
    std::printf("twisting, L = %g m: energy second differences vs symmetric part %.2e "
                "(largest asymmetry of the Jacobian %.2e)\n", length, worst, asymmetry);
  }
}

TEST(TwistingEnergy, MatchesFiniteDifferencesAtUnitScale) { CheckAtScale(1.0); }
TEST(TwistingEnergy, MatchesFiniteDifferencesAtMicrometres) { CheckAtScale(1e-6); }
TEST(TwistingEnergy, MatchesFiniteDifferencesAtHundredMetres) { CheckAtScale(1e2); }

TEST(TwistingEnergy, ReferenceTwistGradientIsHalfTheCurvatureBinormal) {
  // With θ0 = θ1 and τ − τ̄ = 1, k = 1: ∂E/∂x0 = −κb / (2|e0|), ∂E/∂x2 = κb / (2|e1|).
  std::mt19937 rng(3);
  Stencil s = RandomStencil(rng, 1.0);
  s.theta[1] = s.theta[0];
  const Vec3 e0 = s.x[1] - s.x[0];
  const Vec3 e1 = s.x[2] - s.x[1];
  const Vec3 kb = 2.0 * e0.cross(e1) / (e0.norm() * e1.norm() + e0.dot(e1));
  Vec11 g;
  Twisting({1.0, Twist(s) - 1.0})(s, &g, nullptr);
  EXPECT_LT((g.segment<3>(0) + kb / (2.0 * e0.norm())).norm(), 1e-14);
  EXPECT_LT((g.segment<3>(8) - kb / (2.0 * e1.norm())).norm(), 1e-14);
  EXPECT_NEAR(g[3], -1.0, 1e-15);
  EXPECT_NEAR(g[7], 1.0, 1e-15);
}

TEST(TwistingEnergy, ZeroGradientAtRest) {
  for (unsigned seed = 1; seed <= 5; ++seed) {
    std::mt19937 rng(seed);
    const Stencil s = RandomStencil(rng, 1e-3);
    const TwistingParams p{2.0, Twist(s)};
    Vec11 g;
    Mat11 h;
    EXPECT_EQ(Twisting(p)(s, &g, &h), 0.0);
    EXPECT_EQ(g.norm(), 0.0);
    // At rest the Hessian is k ∇τ ∇τᵀ.
    Vec11 grad_tau = Vec11::Zero();
    Twisting({1.0, Twist(s) - 1.0})(s, &grad_tau, nullptr);
    EXPECT_LT((h - p.stiffness * grad_tau * grad_tau.transpose()).norm(), 1e-12 * h.norm());
    // Winding θ1 by δ costs ½ k δ², whatever the geometry.
    Vec11 dq = Vec11::Zero();
    dq[7] = 0.1;
    EXPECT_NEAR(Twisting(p)(testing::Perturb(s, Pack(s) + dq), nullptr, nullptr),
                0.5 * p.stiffness * 0.01, 1e-14);
  }
}

TEST(TwistingEnergy, InvariantUnderRigidMotion) {
  for (unsigned seed = 1; seed <= 5; ++seed) {
    std::mt19937 rng(seed);
    const Stencil s = RandomStencil(rng, 0.01);
    const Mat3 r = Eigen::AngleAxisd(-2.2, Vec3(0.3, 1.0, 0.5).normalized()).toRotationMatrix();
    const Stencil moved = testing::RigidlyMoved(s, r, Vec3(-1.0, 4.0, 0.2));
    EXPECT_NEAR(moved.reference_twist, s.reference_twist, 1e-13);
    const TwistingParams p{1.3, 0.4};
    Vec11 g;
    Vec11 g_moved;
    Mat11 h;
    Mat11 h_moved;
    const double e = Twisting(p)(s, &g, &h);
    EXPECT_NEAR(Twisting(p)(moved, &g_moved, &h_moved), e, 1e-12 * e);
    Mat11 q = Mat11::Identity();
    for (int b : {0, 4, 8}) q.block<3, 3>(b, b) = r;
    EXPECT_LT((g_moved - q * g).norm(), 1e-10 * g.norm());
    EXPECT_LT((h_moved - q * h * q.transpose()).norm(), 1e-10 * h.norm());
  }
}

}  // namespace
}  // namespace stokesrods
