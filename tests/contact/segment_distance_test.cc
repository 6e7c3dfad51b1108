// ClosestPointsBetweenSegments against sampled minima and closed-form degenerate cases.
#include "stokesrods/contact/segment_distance.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

namespace stokesrods {
namespace {

double Clamp01(double u) { return std::isnan(u) ? 0.0 : std::clamp(u, 0.0, 1.0); }

/// min over t of |a(s) − b(t)|, with t from the exact clamped projection.
double DistanceAt(double s, const Vec3& a0, const Vec3& a1, const Vec3& b0, const Vec3& b1) {
  const Vec3 p = a0 + s * (a1 - a0);
  const Vec3 d = b1 - b0;
  const double dd = d.squaredNorm();
  const double t = dd > 0.0 ? Clamp01((p - b0).dot(d) / dd) : 0.0;
  return (p - (b0 + t * d)).norm();
}

/// Reference minimum: f(s) = min_t |a(s) − b(t)| is convex, so sample s on a grid of 20001 points
/// and refine the best bracket by golden-section search. Every value is attained by a pair of
/// points on the segments, so the reference is an upper bound of the true minimum.
double SampledMinimum(const Vec3& a0, const Vec3& a1, const Vec3& b0, const Vec3& b1) {
  constexpr int kSamples = 20000;
  double best = DistanceAt(0.0, a0, a1, b0, b1);
  int best_k = 0;
  for (int k = 1; k <= kSamples; ++k) {
    const double f = DistanceAt(k / static_cast<double>(kSamples), a0, a1, b0, b1);
    if (f < best) {
      best = f;
      best_k = k;
    }
  }
  double lo = std::max(0, best_k - 1) / static_cast<double>(kSamples);
  double hi = std::min(kSamples, best_k + 1) / static_cast<double>(kSamples);
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  for (int it = 0; it < 200 && hi - lo > 1e-17; ++it) {
    const double m1 = hi - g * (hi - lo);
    const double m2 = lo + g * (hi - lo);
    const double f1 = DistanceAt(m1, a0, a1, b0, b1);
    const double f2 = DistanceAt(m2, a0, a1, b0, b1);
    best = std::min({best, f1, f2});
    if (f1 < f2) {
      hi = m2;
    } else {
      lo = m1;
    }
  }
  return best;
}

/// The returned points lie on the segments and realize the returned distance.
void ExpectConsistent(const SegmentClosestPoints& c, const Vec3& a0, const Vec3& a1, const Vec3& b0,
                      const Vec3& b1) {
  const double scale = 1.0 + a0.norm() + a1.norm() + b0.norm() + b1.norm();
  EXPECT_GE(c.s, 0.0);
  EXPECT_LE(c.s, 1.0);
  EXPECT_GE(c.t, 0.0);
  EXPECT_LE(c.t, 1.0);
  EXPECT_LE((c.p - (a0 + c.s * (a1 - a0))).norm(), 1e-15 * scale);
  EXPECT_LE((c.q - (b0 + c.t * (b1 - b0))).norm(), 1e-15 * scale);
  EXPECT_NEAR(c.distance, (c.q - c.p).norm(), 1e-15 * scale);
}

TEST(SegmentDistance, RandomSegmentsMatchSampledMinimum) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto rand3 = [&] { return Vec3(u(rng), u(rng), u(rng)); };
  double max_discrepancy = 0.0;
  for (int trial = 0; trial < 300; ++trial) {
    const Vec3 a0 = rand3(), a1 = rand3(), b0 = rand3();
    // A third of the cases have b near a, so the minimum is often interior or zero.
    const Vec3 b1 = trial % 3 == 0 ? Vec3(b0 + 0.3 * rand3()) : rand3();
    const SegmentClosestPoints c = ClosestPointsBetweenSegments(a0, a1, b0, b1);
    ExpectConsistent(c, a0, a1, b0, b1);
    const double reference = SampledMinimum(a0, a1, b0, b1);
    EXPECT_LE(c.distance, reference + 1e-14) << "trial " << trial;
    EXPECT_NEAR(c.distance, reference, 1e-12) << "trial " << trial;
    max_discrepancy = std::max(max_discrepancy, std::abs(c.distance - reference));
  }
  std::printf("[ info ] max |distance - sampled minimum| over 300 random pairs: %.3g\n",
              max_discrepancy);
}

TEST(SegmentDistance, DenseGridNeverBeatsResult) {
  // A plain 2000 × 2000 grid over (s, t): no grid point is nearer than the result, and the result
  // is within the grid's sampling accuracy (|d_a| + |d_b|)/(2·1999) of the grid minimum.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto rand3 = [&] { return Vec3(u(rng), u(rng), u(rng)); };
  double max_gap = -1.0, min_gap = 1.0;
  for (int trial = 0; trial < 6; ++trial) {
    const Vec3 a0 = rand3(), a1 = rand3(), b0 = rand3(), b1 = rand3();
    const SegmentClosestPoints c = ClosestPointsBetweenSegments(a0, a1, b0, b1);
    constexpr int kGrid = 2000;
    double grid_min = std::numeric_limits<double>::infinity();
    for (int i = 0; i < kGrid; ++i) {
      const Vec3 p = a0 + (i / (kGrid - 1.0)) * (a1 - a0);
      for (int j = 0; j < kGrid; ++j) {
        grid_min = std::min(grid_min, (p - b0 - (j / (kGrid - 1.0)) * (b1 - b0)).norm());
      }
    }
    const double accuracy = ((a1 - a0).norm() + (b1 - b0).norm()) / (2.0 * (kGrid - 1));
    max_gap = std::max(max_gap, c.distance - grid_min);
    min_gap = std::min(min_gap, c.distance - grid_min);
    EXPECT_LE(c.distance, grid_min + 1e-14);
    EXPECT_GE(c.distance, grid_min - accuracy);
  }
  std::printf("[ info ] 2000x2000 grid: distance - grid minimum in [%.3g, %.3g]\n", min_gap,
              max_gap);
}

struct Case {
  const char* name;
  Vec3 a0, a1, b0, b1;
  double distance;
};

TEST(SegmentDistance, DegenerateCasesClosedForm) {
  const double r2 = std::sqrt(2.0);
  const Case cases[] = {
      {"parallel overlapping", {0, 0, 0}, {2, 0, 0}, {1, 1, 0}, {3, 1, 0}, 1.0},
      {"antiparallel overlapping", {0, 0, 0}, {2, 0, 0}, {3, 1, 0}, {1, 1, 0}, 1.0},
      {"parallel, b inside a", {0, 0, 0}, {4, 0, 0}, {1, 0, 2}, {2, 0, 2}, 2.0},
      {"parallel disjoint", {0, 0, 0}, {1, 0, 0}, {2, 1, 0}, {3, 1, 0}, r2},
      {"parallel touching ends", {0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {2, 1, 0}, 1.0},
      {"collinear overlapping", {0, 0, 0}, {2, 0, 0}, {1, 0, 0}, {3, 0, 0}, 0.0},
      {"collinear disjoint", {0, 0, 0}, {1, 0, 0}, {4, 0, 0}, {3, 0, 0}, 2.0},
      {"identical", {0, 1, 2}, {3, 4, 5}, {0, 1, 2}, {3, 4, 5}, 0.0},
      {"reversed identical", {0, 1, 2}, {3, 4, 5}, {3, 4, 5}, {0, 1, 2}, 0.0},
      {"point-segment interior", {0.5, 1, 0}, {0.5, 1, 0}, {0, 0, 0}, {1, 0, 0}, 1.0},
      {"segment-point beyond end", {0, 0, 0}, {1, 0, 0}, {3, 0, 0}, {3, 0, 0}, 2.0},
      {"point-point", {1, 2, 3}, {1, 2, 3}, {1, 2, 6}, {1, 2, 6}, 3.0},
      {"point-point coincident", {1, 2, 3}, {1, 2, 3}, {1, 2, 3}, {1, 2, 3}, 0.0},
      {"intersecting", {-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, 0.0},
      {"skew perpendicular", {-1, 0, 0}, {1, 0, 0}, {0, -1, 0.5}, {0, 1, 0.5}, 0.5},
      {"T end on interior", {0, 0, 0}, {0, 1, 0}, {-1, 2, 0}, {1, 2, 0}, 1.0},
      {"shared endpoint", {0, 0, 0}, {1, 0, 0}, {1, 0, 0}, {1, 1, 0}, 0.0},
  };
  for (const Case& k : cases) {
    SCOPED_TRACE(k.name);
    const SegmentClosestPoints c = ClosestPointsBetweenSegments(k.a0, k.a1, k.b0, k.b1);
    ExpectConsistent(c, k.a0, k.a1, k.b0, k.b1);
    EXPECT_NEAR(c.distance, k.distance, 1e-15);
    EXPECT_NEAR(c.distance, SampledMinimum(k.a0, k.a1, k.b0, k.b1), 1e-15);
    const SegmentClosestPoints swapped = ClosestPointsBetweenSegments(k.b0, k.b1, k.a0, k.a1);
    EXPECT_NEAR(swapped.distance, k.distance, 1e-15);
  }
}

TEST(SegmentDistance, ParallelOverlapPicksMiddleOfOverlap) {
  // Overlap of the projections is x ∈ [1, 2]: the middle x = 1.5 is s = 0.75 on a, t = 0.25 on b,
  // so a response pushes both nodes of each segment.
  const SegmentClosestPoints c =
      ClosestPointsBetweenSegments({0, 0, 0}, {2, 0, 0}, {1, 1, 0}, {3, 1, 0});
  EXPECT_NEAR(c.s, 0.75, 1e-15);
  EXPECT_NEAR(c.t, 0.25, 1e-15);
  const SegmentClosestPoints equal =
      ClosestPointsBetweenSegments({0, 0, 0}, {1, 0, 0}, {1, 0, 0.3}, {0, 0, 0.3});
  EXPECT_NEAR(equal.s, 0.5, 1e-15);
  EXPECT_NEAR(equal.t, 0.5, 1e-15);
}

TEST(SegmentDistance, NearlyParallelAtAngle1e9) {
  // b crosses above a at angle θ = 1e-9 and height h, at the middle of both: distance exactly h.
  const double theta = 1e-9;
  for (double h : {0.0, 1e-12, 1e-3, 1.0}) {
    SCOPED_TRACE(h);
    const Vec3 dir(std::cos(theta), std::sin(theta), 0.0);
    const Vec3 a0(0, 0, 0), a1(1, 0, 0);
    const Vec3 b0 = Vec3(0.5, 0, h) - 0.5 * dir, b1 = Vec3(0.5, 0, h) + 0.5 * dir;
    const SegmentClosestPoints c = ClosestPointsBetweenSegments(a0, a1, b0, b1);
    ExpectConsistent(c, a0, a1, b0, b1);
    EXPECT_NEAR(c.distance, h, 1e-15);
    EXPECT_LE(c.distance, SampledMinimum(a0, a1, b0, b1) + 1e-16);
    if (h == 0.0) {
      EXPECT_NEAR(c.s, 0.5, 1e-6);  // the textbook Gram determinant a e − b² is noise here
    }
  }
  // Nearly parallel, offset so the minimum is at an end.
  const Vec3 a0(0, 0, 0), a1(1, 0, 0);
  const Vec3 b0(0.5, 0.2, 0), b1(1.5, 0.2 + theta, 0);
  const SegmentClosestPoints c = ClosestPointsBetweenSegments(a0, a1, b0, b1);
  EXPECT_NEAR(c.distance, SampledMinimum(a0, a1, b0, b1), 1e-15);
  EXPECT_NEAR(c.distance, 0.2, 1e-15);
}

TEST(SegmentDistance, ScaleAndTranslationInvariant) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto rand3 = [&] { return Vec3(u(rng), u(rng), u(rng)); };
  for (double scale : {1e-6, 1.0, 1e2}) {
    for (int trial = 0; trial < 20; ++trial) {
      const Vec3 a0 = rand3(), a1 = rand3(), b0 = rand3(), b1 = rand3(), shift = rand3();
      const SegmentClosestPoints unit = ClosestPointsBetweenSegments(a0, a1, b0, b1);
      const SegmentClosestPoints c = ClosestPointsBetweenSegments(
          scale * (a0 + shift), scale * (a1 + shift), scale * (b0 + shift), scale * (b1 + shift));
      EXPECT_NEAR(c.distance, scale * unit.distance, 1e-13 * scale);
    }
  }
}

}  // namespace
}  // namespace stokesrods
