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

namespace {

// Where the images' part of a segment is singular: the mirrored segment. Returns the distance
// √(d*² + ε²) from `point` to it.
double MirrorDistance(const Wall& wall, const Vec3& xa, const Vec3& xb, double regularization,
                      const Vec3& point) {
  auto mirror = [&](const Vec3& y) { return Vec3(y - 2.0 * (y - wall.point).dot(wall.normal) * wall.normal); };
  const Vec3 ma = mirror(xa), mv = mirror(xb) - ma;
  const double t = std::clamp((point - ma).dot(mv) / mv.squaredNorm(), 0.0, 1.0);
  return std::hypot((point - ma - t * mv).norm(), regularization);
}

// L ∫ φ(α) (W − S_ε)(x̂, x_α) dα by an n-point Gauss–Legendre rule on `panels` equal panels.
SegmentMobility ImagesByGauss(const Wall& wall, const Vec3& xa, const Vec3& xb,
                              double regularization, const Vec3& point, int n, int panels) {
  SegmentMobility out;
  const Vec3 v = xb - xa;
  const double length = v.norm();
  const double* nodes = nullptr;
  const double* weights = nullptr;
  GaussLegendreRule01(n, &nodes, &weights);
  for (int p = 0; p < panels; ++p)
    for (int q = 0; q < n; ++q) {
      const double alpha = (p + nodes[q]) / panels, w = weights[q] * length / panels;
      const Vec3 y = xa + alpha * v;
      const Mat3 image = RegularizedBlakeletMatrix(wall, point, y, regularization) -
                         RegularizedStokesletMatrix(point - y, regularization);
      out.a += w * (1.0 - alpha) * image;
      out.b += w * alpha * image;
    }
  return out;
}

}  // namespace

SegmentMobility StokesletSegmentWallImages(const Wall& wall, const Vec3& xa, const Vec3& xb,
                                           double regularization, const Vec3& point,
                                           double tolerance) {
  const double distance = MirrorDistance(wall, xa, xb, regularization, point);
  // The fewest points of the calibrated range whose error bound meets the tolerance, if any.
  if (tolerance > 0.0)
    for (int n = 2; n <= kWallImageRuleMaxPoints; ++n)
      if (WallImageRuleError(n, distance / (xb - xa).norm()) <= tolerance)
        return ImagesByGauss(wall, xa, xb, regularization, point, n, 1);
  // 20 points on panels no longer than the distance to the mirrored segment.
  const int panels = std::max(1, static_cast<int>(std::ceil((xb - xa).norm() / distance)));
  return ImagesByGauss(wall, xa, xb, regularization, point, 20, panels);
}

SegmentMobility StokesletSegmentWallImagesGauss(const Wall& wall, const Vec3& xa, const Vec3& xb,
                                                double regularization, const Vec3& point, int n) {
  return ImagesByGauss(wall, xa, xb, regularization, point, n, 1);
}

double WallImageDelta(const Wall& wall, const Vec3& xa, const Vec3& xb, double regularization,
                      const Vec3& point) {
  return MirrorDistance(wall, xa, xb, regularization, point) / (xb - xa).norm();
}

double WallImageRuleError(int n, double delta) {
  return 2.0 * 2.2e-2 * std::pow(11.5, -(n - 2.0)) * std::pow(std::max(delta, 1.0), -(2.0 * n - 2.0));
}

Mat3 PointBlobMatrix(const Wall* wall, const Vec3& x, const Vec3& x0, double regularization) {
  return wall ? RegularizedBlakeletMatrix(*wall, x, x0, regularization)
              : RegularizedStokesletMatrix(x - x0, regularization);
}

}  // namespace stokesrods
