// CalcTimeOfContact: conservative advancement against dense sampling of the step.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "stokesrods/contact/segment_distance.h"

namespace stokesrods {
namespace {

double DistanceAt(const std::array<Vec3, 4>& start, const std::array<Vec3, 4>& end, double tau) {
  std::array<Vec3, 4> x;
  for (std::size_t k = 0; k < 4; ++k) x[k] = start[k] + tau * (end[k] - start[k]);
  return ClosestPointsBetweenSegments(x[0], x[1], x[2], x[3]).distance;
}

TEST(TimeOfContact, HeadOnApproach) {
  // a fixed along x; b along y falls from z = 1 to z = −1: contact at z = 0.2, τ = 0.4.
  const std::array<Vec3, 4> start = {Vec3(-1, 0, 0), Vec3(1, 0, 0), Vec3(0, -1, 1), Vec3(0, 1, 1)};
  const std::array<Vec3, 4> end = {Vec3(-1, 0, 0), Vec3(1, 0, 0), Vec3(0, -1, -1), Vec3(0, 1, -1)};
  const TimeOfContact c = CalcTimeOfContact(start, end, 0.2, 1e-12);
  EXPECT_TRUE(c.hit);
  EXPECT_TRUE(c.converged);
  EXPECT_NEAR(c.time, 0.4, 1e-12);
  EXPECT_LE(c.time, 0.4);
  EXPECT_LT(c.iterations, 5);  // straight approach: one step lands on the contact
}

TEST(TimeOfContact, TunnellingIsCaughtAndMissesAreNot) {
  // Both ends of the step are free of contact, but b passes through a in between.
  const std::array<Vec3, 4> start = {Vec3(-1, 0, 0), Vec3(1, 0, 0), Vec3(0, -1, 3), Vec3(0, 1, 3)};
  std::array<Vec3, 4> end = {Vec3(-1, 0, 0), Vec3(1, 0, 0), Vec3(0, -1, -3), Vec3(0, 1, -3)};
  EXPECT_GT(DistanceAt(start, end, 0.0), 0.2);
  EXPECT_GT(DistanceAt(start, end, 1.0), 0.2);
  const TimeOfContact hit = CalcTimeOfContact(start, end, 0.2, 1e-12);
  EXPECT_TRUE(hit.hit);
  EXPECT_NEAR(hit.time, (3.0 - 0.2) / 6.0, 1e-12);
  // Sliding sideways, 1 above a: never within 0.2.
  end = {Vec3(-1, 0, 0), Vec3(1, 0, 0), Vec3(4, -1, 1), Vec3(4, 1, 1)};
  const std::array<Vec3, 4> above = {start[0], start[1], Vec3(-4, -1, 1), Vec3(-4, 1, 1)};
  const TimeOfContact miss = CalcTimeOfContact(above, end, 0.2, 1e-12);
  EXPECT_FALSE(miss.hit);
  EXPECT_TRUE(miss.converged);
  // No relative motion.
  EXPECT_FALSE(CalcTimeOfContact(above, above, 0.2, 1e-12).hit);
}

TEST(TimeOfContact, RandomMotionsAgainstSampling) {
  // Rotating and translating segments: the sampled distance stays above the contact distance
  // before the returned time (never steps over a contact), and is within tolerance at it.
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto rand3 = [&] { return Vec3(u(rng), u(rng), u(rng)); };
  int hits = 0;
  int max_iterations = 0;
  for (int trial = 0; trial < 200; ++trial) {
    std::array<Vec3, 4> start, end;
    for (std::size_t k = 0; k < 4; ++k) {
      start[k] = rand3() + (k >= 2 ? Vec3(0, 0, 1.5) : Vec3::Zero());
      end[k] = rand3() + (k >= 2 ? Vec3(0, 0, -0.5) : Vec3::Zero());
    }
    const double contact = 0.1;
    const double tol = 1e-10;
    const TimeOfContact c = CalcTimeOfContact(start, end, contact, tol);
    ASSERT_TRUE(c.converged);
    max_iterations = std::max(max_iterations, c.iterations);
    constexpr int kSamples = 4000;
    for (int k = 0; k <= kSamples; ++k) {
      const double tau = k / static_cast<double>(kSamples);
      if (c.hit && tau >= c.time) break;
      EXPECT_GT(DistanceAt(start, end, tau), contact) << trial << " " << tau;
    }
    if (c.hit) {
      ++hits;
      EXPECT_LE(c.closest.distance, contact + tol);
      EXPECT_NEAR(DistanceAt(start, end, c.time), c.closest.distance, 1e-15);
    }
  }
  std::printf("[ info ] %d of 200 random motions hit; at most %d advancement iterations\n", hits,
              max_iterations);
  EXPECT_GT(hits, 50);
  EXPECT_LT(hits, 200);
}

}  // namespace
}  // namespace stokesrods
