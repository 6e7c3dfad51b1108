#include "stokesrods/rod/geometry.h"

#include <gtest/gtest.h>

#include <cmath>

namespace stokesrods {
namespace {

// Torsion of the discrete curve through four consecutive points: sign of (e0 × e1) · e2.
double TorsionSign(const Matrix3X& x, int i) {
  const Vec3 e0 = x.col(i + 1) - x.col(i);
  const Vec3 e1 = x.col(i + 2) - x.col(i + 1);
  const Vec3 e2 = x.col(i + 3) - x.col(i + 2);
  return e0.cross(e1).dot(e2);
}

TEST(HelixNodes, MatchesTheSpecGeometry) {
  HelixGeometry g;  // the paper's: N = 65, l0 = 0.2, λ = 0.05, R = 0.01
  g.base = Vec3(0.03, 0.0, 0.0);
  const Matrix3X x = HelixNodes(g);
  ASSERT_EQ(x.cols(), 65);
  EXPECT_TRUE(x.col(0).isApprox(g.base));
  const Vec3 e0 = x.col(1) - x.col(0);
  EXPECT_NEAR(e0.normalized().dot(-Vec3::UnitZ()), 1.0, 1e-14);
  EXPECT_TRUE((x.col(2) - x.col(1)).isApprox(Vec3(0.01, 0.0, -0.01), 1e-14));
  EXPECT_NEAR(x(2, 64), -0.2, 1e-14);
  // every helix node at distance R from the axis through the base
  for (int i = 2; i < 65; ++i) {
    EXPECT_NEAR((x.col(i) - g.base).head<2>().norm(), 0.01, 1e-14);
  }
  // first edge equals the helical arc spacing; total arc length near the paper's L = 0.32 m
  const double c = std::sqrt(1.0 + std::pow(2.0 * kPi * 0.01 / 0.05, 2));
  const double ds = (x(2, 2) - x(2, 3)) * c;
  EXPECT_NEAR(e0.norm(), ds, 1e-12);
  double arc = e0.norm() + (x.col(2) - x.col(1)).norm() + 62 * ds;
  EXPECT_NEAR(arc, 0.3165, 5e-4);
}

TEST(HelixNodes, LeadInAboveMakesTheHelicalPartSpanL0) {
  HelixGeometry g;
  g.lead_in_above = true;
  const Matrix3X x = HelixNodes(g);
  const double c = std::sqrt(1.0 + std::pow(2.0 * kPi * 0.01 / 0.05, 2));
  const double ds = 0.2 * c / 62;  // 62 helical edges over l0 = 0.2 m of axial drop
  EXPECT_NEAR((x.col(1) - x.col(0)).norm(), ds, 1e-14);
  EXPECT_TRUE((x.col(2) - x.col(1)).isApprox(Vec3(0.01, 0.0, -0.01), 1e-14));
  EXPECT_NEAR(x(2, 2) - x(2, 64), 0.2, 1e-14);  // the helical part spans l0
  EXPECT_NEAR(x(2, 64), -(ds + 0.01 + 0.2), 1e-14);
  for (int i = 2; i < 64; ++i) EXPECT_NEAR((x.col(i + 1) - x.col(i)).norm(), (x.col(3) - x.col(2)).norm(), 1e-12);
  // The deformable part is longer than with the lead-in within l0 (issue 8: about 8 %).
  const Matrix3X within = HelixNodes(HelixGeometry{});
  auto arc = [](const Matrix3X& y) {
    double s = 0.0;
    for (int i = 1; i + 1 < y.cols(); ++i) s += (y.col(i + 1) - y.col(i)).norm();
    return s;
  };
  EXPECT_GT(arc(x) / arc(within), 1.05);
  EXPECT_LT(arc(x) / arc(within), 1.10);
}

TEST(HelixNodes, HandednessIsGeometric) {
  HelixGeometry g;
  for (int i = 2; i + 3 < 65; ++i) EXPECT_GT(TorsionSign(HelixNodes(g), i), 0.0) << i;
  g.right_handed = false;
  for (int i = 2; i + 3 < 65; ++i) EXPECT_LT(TorsionSign(HelixNodes(g), i), 0.0) << i;
}

TEST(StraightNodes, HangDownEvenly) {
  const Matrix3X x = StraightNodes(5, 1.0, Vec3(1, 2, 3));
  EXPECT_TRUE(x.col(4).isApprox(Vec3(1, 2, 2)));
  EXPECT_NEAR((x.col(1) - x.col(0)).norm(), 0.25, 1e-15);
}

}  // namespace
}  // namespace stokesrods
