// Rows of the RSS force-density mobility A (rss.h) for one source rod, vectorized over its
// segments. Internal to the fluid module: the dense assembly (rss.cc) and the near corrections of
// the matrix-free operator (mobility_operator.cc) share it.
//
// For a target point p and a range of the rod's segments, Row gives A_a and A_b of each segment
// (eq. 8) as a table of 12 rows (xx, xy, xz, yy, yz, zz of A_a, then of A_b; both symmetric) by
// `count` columns. One Gauss rule of n points is applied to every segment at once (point q of
// segment j stored contiguously over j, so the loop over segments vectorizes: AVX-512/AVX2 clones
// chosen at run time); n is the fewest points that meet the tolerance from δ = 2.5 on. Where the
// rule would miss it (δ = √(d² + ε²)/L below GaussRuleMinDelta(n)), StokesletSegment itself
// overwrites the column (closed forms near, its own Gauss rule between). Every entry is thus at
// least as accurate as StokesletSegment(…, tolerance) (tests/fluid/rss_test.cc).
#pragma once

#include <vector>

#include "stokesrods/common/types.h"

namespace stokesrods {

class RssRowKernel {
 public:
  /// The rod's nodes (3 × N, N ≥ 2; kept by reference), its blob size ε [m], the tolerance of
  /// StokesletSegment (0: round-off), and the size g of the rule SubtractRule removes (0: none).
  RssRowKernel(const Matrix3X& x, double regularization, double tolerance,
               int subtracted_rule = 0);

  int segments() const { return segments_; }

  /// table (12 rows, stride `count`) = A_a, A_b of segments [first, first + count) at p.
  void Row(const Vec3& p, int first, int count, double* table) const;

  /// table −= the subtracted rule's A_a, A_b of the same segments: the near corrections of the
  /// matrix-free operator, whose far sum applies that rule to every segment.
  void SubtractRule(const Vec3& p, int first, int count, double* table) const;

 private:
  struct Cloud {  // a rule's points on every segment: point q of segment j at q × segments + j
    int points = 0;
    const double* alpha = nullptr;
    std::vector<double> x, y, z, wl;  // position, w_q L_j
  };
  Cloud MakeCloud(int points) const;
  void AddCloud(const Cloud& cloud, double sign, const Vec3& p, int first, int count,
                double* table) const;

  const Matrix3X* x_;
  double eps_, tolerance_, min_delta_ = 0.0;
  int segments_;
  Cloud rule_, subtracted_;
  std::vector<double> mx_, my_, mz_, reach2_;  // midpoints, ((min_delta + ½) L_j)²
};

}  // namespace stokesrods
