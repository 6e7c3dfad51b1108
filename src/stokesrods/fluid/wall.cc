#include "stokesrods/fluid/wall.h"

#include <algorithm>
#include <cmath>

#include "stokesrods/common/assert.h"
#include "stokesrods/fluid/stokeslet_segment.h"

namespace stokesrods {

Mat3 RegularizedBlakeletMatrix(const Wall& wall, const Vec3& x, const Vec3& x0,
                               double regularization) {
  const Vec3& n = wall.normal;
  const double h = (x0 - wall.point).dot(n);
  SR_DASSERT(h > 0.0, "a blob on or behind the wall");
  const double eps2 = regularization * regularization;
  const Vec3 r = x - x0;
  const Vec3 big_r = r + 2.0 * h * n;  // x − x0*
  const Mat3 reflect = Mat3::Identity() - 2.0 * n * n.transpose();
  const Vec3 reflected = reflect * big_r;  // Δ R
  const double r2 = big_r.squaredNorm(), r_n = big_r.dot(n);
  const double inv = 1.0 / std::sqrt(r2 + eps2);
  const double inv3 = inv * inv * inv, inv5 = inv3 * inv * inv;
  Mat3 w = RegularizedStokesletMatrix(r, regularization) -
           RegularizedStokesletMatrix(big_r, regularization);
  w += 2.0 * h * h * (reflect * inv3 - 3.0 * inv5 * big_r * reflected.transpose()) -
       6.0 * h * h * eps2 * inv5 * reflect;
  w += 2.0 * h *
       ((r2 + 4.0 * eps2) * inv5 * n * reflected.transpose() - r_n * inv3 * reflect +
        inv3 * big_r * n.transpose() + 3.0 * r_n * inv5 * big_r * reflected.transpose());
  w += 6.0 * h * eps2 * inv5 * (r_n * Mat3::Identity() - n * big_r.transpose());
  return w;
}

SegmentMobility StokesletSegmentNearWall(const Wall& wall, const Vec3& xa, const Vec3& xb,
                                         double regularization, const Vec3& point) {
  SegmentMobility out = StokesletSegment(xa, xb, regularization, point);
  const SegmentMobility images = StokesletSegmentWallImages(wall, xa, xb, regularization, point);
  out.a += images.a;
  out.b += images.b;
  return out;
}

SegmentMobility StokesletSegmentWallImages(const Wall& wall, const Vec3& xa, const Vec3& xb,
                                           double regularization, const Vec3& point) {
  SegmentMobility out;
  const Vec3 v = xb - xa;
  const double length = v.norm();
  // The mirrored segment and the target's distance to it.
  auto mirror = [&](const Vec3& y) { return Vec3(y - 2.0 * (y - wall.point).dot(wall.normal) * wall.normal); };
  const Vec3 ma = mirror(xa), mv = mirror(xb) - ma;
  const double t = std::clamp((point - ma).dot(mv) / mv.squaredNorm(), 0.0, 1.0);
  const double distance = std::hypot((point - ma - t * mv).norm(), regularization);
  const int panels = std::max(1, static_cast<int>(std::ceil(length / distance)));
  const double* nodes = nullptr;
  const double* weights = nullptr;
  GaussLegendreRule01(20, &nodes, &weights);
  for (int p = 0; p < panels; ++p)
    for (int q = 0; q < 20; ++q) {
      const double alpha = (p + nodes[q]) / panels, w = weights[q] * length / panels;
      const Vec3 y = xa + alpha * v;
      const Mat3 image = RegularizedBlakeletMatrix(wall, point, y, regularization) -
                         RegularizedStokesletMatrix(point - y, regularization);
      out.a += w * (1.0 - alpha) * image;
      out.b += w * alpha * image;
    }
  return out;
}

Mat3 PointBlobMatrix(const Wall* wall, const Vec3& x, const Vec3& x0, double regularization) {
  return wall ? RegularizedBlakeletMatrix(*wall, x, x0, regularization)
              : RegularizedStokesletMatrix(x - x0, regularization);
}

}  // namespace stokesrods
