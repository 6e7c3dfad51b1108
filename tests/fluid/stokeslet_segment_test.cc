// The Regularized Stokeslet Segment closed forms (paper eqs. 8–11, 14) against adaptive
// Gauss–Kronrod quadrature of eq. 8, everywhere: far, near, on the segment, far along its line.
#include "stokesrods/fluid/stokeslet_segment.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

namespace stokesrods {
namespace {

double RelativeError(const SegmentMobility& s, const SegmentMobility& ref) {
  const double norm = std::sqrt(ref.a.squaredNorm() + ref.b.squaredNorm());
  return std::sqrt((s.a - ref.a).squaredNorm() + (s.b - ref.b).squaredNorm()) / norm;
}

// Eqs. 11a–f and 14 exactly as printed (with v = x0 − x1, r0 = x̂ − x0), for comparison.
SegmentMobility PaperSegment(const Vec3& x0, const Vec3& x1, double eps, const Vec3& point) {
  const Vec3 v = x0 - x1;
  const Vec3 r0 = point - x0;
  const double l = v.norm();
  const double l2 = l * l;
  const double rv = r0.dot(v);
  const double big_r0 = std::sqrt(r0.squaredNorm() + eps * eps);
  const Vec3 r1 = r0 + v;  // r_α = r0 + α v
  const double big_r1 = std::sqrt(r1.squaredNorm() + eps * eps);
  const double t0m1 = std::log((l * big_r1 + r1.dot(v)) / (l * big_r0 + rv)) / l;
  const double t0m3 = -1.0 / (big_r1 * (l * big_r1 + r1.dot(v))) + 1.0 / (big_r0 * (l * big_r0 + rv));
  const double t1m1 = (big_r1 - big_r0) / l2 - rv / l2 * t0m1;
  const double t1m3 = -(1.0 / big_r1 - 1.0 / big_r0) / l2 - rv / l2 * t0m3;
  const double t2m3 = -(1.0 / big_r1) / l2 + t0m1 / l2 - rv / l2 * t1m3;
  const double t3m3 = -(1.0 / big_r1) / l2 + 2.0 * t1m1 / l2 - rv / l2 * t2m3;
  const Mat3 rr = r0 * r0.transpose();
  const Mat3 rvs = r0 * v.transpose() + v * r0.transpose();
  const Mat3 vv = v * v.transpose();
  const Mat3 id = Mat3::Identity();
  SegmentMobility s;
  s.b = l * ((t1m1 + eps * eps * t1m3) * id + t1m3 * rr + t2m3 * rvs + t3m3 * vv);
  s.a = l * ((t0m1 + eps * eps * t0m3) * id + t0m3 * rr + t1m3 * rvs + t2m3 * vv) - s.b;
  return s;
}

struct Probe {
  const char* where;
  Vec3 point;
};

// Points relative to the segment x_a → x_b = x_a + L d.
std::vector<Probe> Probes(const Vec3& xa, const Vec3& d, double length, std::mt19937& rng) {
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  auto random_dir = [&] { return Vec3(normal(rng), normal(rng), normal(rng)).normalized(); };
  std::vector<Probe> probes;
  for (double alpha : {0.0, 1e-9, 0.3, 0.5, 1.0 - 1e-9, 1.0}) {
    probes.push_back({"on the segment", xa + alpha * length * d});
  }
  for (double alpha : {-0.1, 1.1, -2.0, 3.0, 1e2, -1e3, 1e4, 1e6}) {
    probes.push_back({"on the line", xa + alpha * length * d});
  }
  for (double alpha : {1e3, -1e5}) {  // far along the line, slightly off it
    probes.push_back({"near the line, far", xa + alpha * length * d + 1e-2 * length * random_dir()});
  }
  for (int i = 0; i < 20; ++i) {
    const double alpha = -0.2 + 1.4 * unit(rng);
    const double h = length * std::pow(10.0, -4.0 + 4.0 * unit(rng));
    probes.push_back({"near", xa + alpha * length * d + h * random_dir()});
  }
  for (int i = 0; i < 10; ++i) {
    probes.push_back({"far", xa + length * std::pow(10.0, 4.0 * unit(rng)) * random_dir()});
  }
  return probes;
}

TEST(StokesletSegment, ClosedFormMatchesAdaptiveQuadrature) {
  std::mt19937 rng(7);
  const Vec3 xa(0.1, -0.2, 0.3);
  const Vec3 d = Vec3(1.0, 2.0, -0.5).normalized();
  double worst = 0.0;
  double worst_paper = 0.0;
  for (double length : {1.0, 5e-3}) {
    for (double eps_over_l : {1e-4, 1e-2, 0.204, 1.0, 3.0}) {
      const double eps = eps_over_l * length;
      for (const Probe& probe : Probes(xa, d, length, rng)) {
        const Vec3 xb = xa + length * d;
        const SegmentMobility ref = StokesletSegmentByQuadrature(xa, xb, eps, probe.point);
        const double error = RelativeError(StokesletSegment(xa, xb, eps, probe.point), ref);
        const double paper = RelativeError(PaperSegment(xa, xb, eps, probe.point), ref);
        worst = std::max(worst, error);
        worst_paper = std::max(worst_paper, std::isfinite(paper) ? paper : 1.0);
        EXPECT_LT(error, 1e-12) << probe.where << " ε/L = " << eps_over_l << " L = " << length
                                << " at " << probe.point.transpose();
        if (paper > 1e-8) {
          std::printf("  printed eqs. 11/14: rel. error %.1e %s, ε/L = %g, |x̂ − x_a|/L = %.3g\n",
                      paper, probe.where, eps_over_l, (probe.point - xa).norm() / length);
        }
      }
    }
  }
  std::printf("closed forms vs quadrature: worst relative error %.2e (printed forms %.2e)\n",
              worst, worst_paper);
  EXPECT_GT(worst_paper, 1e-3);  // the printed recurrences fail far along the line
}

// The reference is converged: a loose and a tight tolerance agree.
TEST(StokesletSegment, QuadratureReferenceConverges) {
  const Vec3 xa(0, 0, 0), xb(0, 0, 1), p(0.3, 0.1, 0.5);
  const SegmentMobility loose = StokesletSegmentByQuadrature(xa, xb, 1e-3, p, 1e-10);
  const SegmentMobility tight = StokesletSegmentByQuadrature(xa, xb, 1e-3, p, 1e-15);
  EXPECT_LT(RelativeError(loose, tight), 1e-9);
}

// Sum rule: A_a + A_b is the uniform-density segment; the point-blob limit far away is
// L S_ε(x̂ − x_mid) with corrections O((L/r)²).
TEST(StokesletSegment, FarFieldIsAPointBlob) {
  const Vec3 xa(0, 0, 0), xb(1e-2, 0, 0);
  for (double distance : {1.0, 10.0, 100.0}) {
    const Vec3 p = Vec3(0.3, -0.7, 0.2).normalized() * distance;
    const SegmentMobility s = StokesletSegment(xa, xb, 1e-3, p);
    const Mat3 blob = 1e-2 * RegularizedStokesletMatrix(p - 0.5 * (xa + xb), 1e-3);
    EXPECT_LT((s.a + s.b - blob).norm() / blob.norm(), 2.0 * std::pow(1e-2 / distance, 2));
  }
}

// Symmetry: reversing the segment swaps A_a and A_b; scaling lengths by λ scales A by 1
// (A is dimensionless: 8πμ u = A f with f in N/m).
TEST(StokesletSegment, ReversalAndScaling) {
  const Vec3 xa(0.2, 0.1, -0.3), xb(0.5, -0.2, 0.1), p(0.4, 0.05, 0.0);
  const SegmentMobility s = StokesletSegment(xa, xb, 0.05, p);
  const SegmentMobility r = StokesletSegment(xb, xa, 0.05, p);
  EXPECT_LT((s.a - r.b).norm(), 1e-13 * s.a.norm());
  EXPECT_LT((s.b - r.a).norm(), 1e-13 * s.b.norm());
  for (double lambda : {1e-6, 1e2}) {
    const SegmentMobility t = StokesletSegment(lambda * xa, lambda * xb, lambda * 0.05, lambda * p);
    EXPECT_LT((t.a - s.a).norm(), 1e-12 * s.a.norm()) << lambda;
    EXPECT_LT((t.b - s.b).norm(), 1e-12 * s.b.norm()) << lambda;
  }
}

}  // namespace
}  // namespace stokesrods
