// Closest points of two segments (paper eq. 17, δ_min = md(x_i, x_i+1, x_j, x_j+1)).
//
// D²(s, t) = |a0 + s d1 − b0 − t d2|² is a convex quadratic on the unit square, so its minimum is
// either the stationary point of the two infinite lines (when it lies inside the square) or lies on
// one of the four edges s = 0, s = 1, t = 0, t = 1, where the problem is a point–segment distance
// solved exactly by a clamped projection. We evaluate these (at most) five candidates and keep the
// nearest, so every returned pair lies on the segments and its distance is the true minimum up to
// round-off, whatever the angle between the segments:
//  - the line stationary point is computed from cross products, s = ((b0 − a0) × d2)·n / |n|² and
//    t = ((b0 − a0) × d1)·n / |n|² with n = d1 × d2. The cross product of nearly parallel vectors
//    has a relative error ~ ε_mach / sin θ, against ε_mach / sin² θ for the textbook Gram
//    determinant a e − b², which is pure noise at θ = 1e-9;
//  - for (anti)parallel segments the minimum is attained on an edge, so the edge candidates
//  suffice;
//    among equally near pairs we prefer the middle of the overlap of the two segments, so that a
//    contact between parallel overlapping segments pushes both nodes of each segment.
//
// CalcTimeOfContact (continuous collision detection, the option named at the end of paper
// section 2.3) advances conservatively on δ_min(τ); see the header.
#include "stokesrods/contact/segment_distance.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "stokesrods/common/assert.h"

namespace stokesrods {
namespace {

constexpr double kMachineEps = std::numeric_limits<double>::epsilon();

/// Parameter in [0, 1] of the point of segment (x0, x0 + d) nearest to p; 0 for a zero-length one.
double ClampedProjection(const Vec3& p, const Vec3& x0, const Vec3& d) {
  const double dd = d.squaredNorm();
  if (!(dd > 0.0)) return 0.0;
  const double u = (p - x0).dot(d) / dd;
  return std::isnan(u) ? 0.0 : std::clamp(u, 0.0, 1.0);
}

struct Candidate {
  double s = 0.0;
  double t = 0.0;
  double distance_sq = std::numeric_limits<double>::infinity();
};

Candidate Evaluate(const Vec3& a0, const Vec3& d1, const Vec3& b0, const Vec3& d2, double s,
                   double t) {
  return {s, t, ((a0 + s * d1) - (b0 + t * d2)).squaredNorm()};
}

/// Candidate pair for (anti)parallel segments with overlapping projections: the middle of the
/// overlap on a, and the point of b nearest to it. Returns false when the projections do not
/// overlap.
bool ParallelOverlapMidpoint(const Vec3& a0, const Vec3& d1, const Vec3& b0, const Vec3& d2,
                             Candidate* candidate) {
  const double a = d1.squaredNorm();
  if (!(a > 0.0)) return false;
  const double u0 = (b0 - a0).dot(d1) / a;       // b0 projected on line a
  const double u1 = (b0 + d2 - a0).dot(d1) / a;  // b1 projected on line a
  const double lo = std::max(0.0, std::min(u0, u1));
  const double hi = std::min(1.0, std::max(u0, u1));
  if (!(lo <= hi)) return false;
  const double s = 0.5 * (lo + hi);
  const double t = ClampedProjection(a0 + s * d1, b0, d2);
  *candidate = Evaluate(a0, d1, b0, d2, s, t);
  return true;
}

}  // namespace

SegmentClosestPoints ClosestPointsBetweenSegments(const Vec3& a0, const Vec3& a1, const Vec3& b0,
                                                  const Vec3& b1) {
  const Vec3 d1 = a1 - a0;
  const Vec3 d2 = b1 - b0;
  const Vec3 w = b0 - a0;

  Candidate best;
  const auto consider = [&best](const Candidate& c) {
    if (c.distance_sq < best.distance_sq) best = c;
  };
  // The four edges of the parameter square, each a point–segment problem.
  consider(Evaluate(a0, d1, b0, d2, 0.0, ClampedProjection(a0, b0, d2)));
  consider(Evaluate(a0, d1, b0, d2, 1.0, ClampedProjection(a1, b0, d2)));
  consider(Evaluate(a0, d1, b0, d2, ClampedProjection(b0, a0, d1), 0.0));
  consider(Evaluate(a0, d1, b0, d2, ClampedProjection(b1, a0, d1), 1.0));

  // Stationary point of the two lines, when it exists and lies in the square.
  const Vec3 n = d1.cross(d2);
  const double nn = n.squaredNorm();
  if (nn > 0.0) {
    const double s = w.cross(d2).dot(n) / nn;
    const double t = w.cross(d1).dot(n) / nn;
    if (s >= 0.0 && s <= 1.0 && t >= 0.0 && t <= 1.0) consider(Evaluate(a0, d1, b0, d2, s, t));
  }

  // Nearly parallel: prefer the middle of the overlap when it is as near as the best up to
  // round-off of the coordinates (a tie-break, never a larger distance beyond that round-off).
  const double a = d1.squaredNorm();
  const double e = d2.squaredNorm();
  if (a > 0.0 && e > 0.0 && nn <= 1e-24 * a * e) {
    Candidate mid;
    if (ParallelOverlapMidpoint(a0, d1, b0, d2, &mid)) {
      const double scale = std::sqrt(a) + std::sqrt(e) + w.norm();
      const double best_distance = std::sqrt(best.distance_sq);
      if (std::sqrt(mid.distance_sq) <= best_distance + 16.0 * kMachineEps * scale) best = mid;
    }
  }

  SegmentClosestPoints out;
  out.s = best.s;
  out.t = best.t;
  out.p = a0 + best.s * d1;
  out.q = b0 + best.t * d2;
  out.distance = (out.q - out.p).norm();
  return out;
}

TimeOfContact CalcTimeOfContact(const std::array<Vec3, 4>& start, const std::array<Vec3, 4>& end,
                                double contact_distance, double tolerance, int max_iterations) {
  SR_ASSERT(contact_distance >= 0.0 && tolerance > 0.0, "contact_distance >= 0, tolerance > 0");
  std::array<Vec3, 4> motion;
  for (std::size_t k = 0; k < 4; ++k) motion[k] = end[k] - start[k];
  double speed = 0.0;  // V [m per step]
  for (std::size_t k = 0; k < 2; ++k) {
    for (std::size_t l = 2; l < 4; ++l) speed = std::max(speed, (motion[k] - motion[l]).norm());
  }
  const auto closest_at = [&](double tau) {
    std::array<Vec3, 4> x;
    for (std::size_t k = 0; k < 4; ++k) x[k] = start[k] + tau * motion[k];
    return ClosestPointsBetweenSegments(x[0], x[1], x[2], x[3]);
  };
  TimeOfContact out;
  double tau = 0.0;
  for (out.iterations = 0; out.iterations < max_iterations; ++out.iterations) {
    out.closest = closest_at(tau);
    const double gap = out.closest.distance - contact_distance;  // [m]
    if (gap <= tolerance) {
      out.hit = true;
      out.time = tau;
      return out;
    }
    if (!(speed > 0.0)) break;
    tau += gap / speed;
    if (tau > 1.0) break;
  }
  out.converged = out.iterations < max_iterations;
  out.time = out.converged ? 1.0 : tau;
  if (out.converged) out.closest = closest_at(1.0);
  return out;
}

}  // namespace stokesrods
