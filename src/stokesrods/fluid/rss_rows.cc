#include "stokesrods/fluid/rss_rows.h"

#include <algorithm>
#include <cmath>

#include "stokesrods/common/assert.h"
#include "stokesrods/fluid/stokeslet_segment.h"

namespace stokesrods {
namespace {

constexpr double kDenseRuleDelta = 2.5;  // n: the fewest points that serve from δ = 2.5 on

// out[c × stride + j] += s (1 − α) T_c (c = 0…5) and out[(6 + c) × stride + j] += s α T_c for one
// rule point on every segment j: T = the six entries xx, xy, xz, yy, yz, zz of w L S_ε(p − x_q).
__attribute__((target_clones("avx512f", "avx2", "default")))
void AddRulePoint(const double* gx, const double* gy, const double* gz, const double* wl,
                  double alpha, double sign, double eps2, int count, const double* p, double* out,
                  int stride) {
  const double beta = sign * (1.0 - alpha), gamma = sign * alpha, px = p[0], py = p[1], pz = p[2];
  double *axx = out, *axy = out + stride, *axz = out + 2 * stride, *ayy = out + 3 * stride,
         *ayz = out + 4 * stride, *azz = out + 5 * stride;
  double *bxx = out + 6 * stride, *bxy = out + 7 * stride, *bxz = out + 8 * stride,
         *byy = out + 9 * stride, *byz = out + 10 * stride, *bzz = out + 11 * stride;
#pragma omp simd
  for (int j = 0; j < count; ++j) {
    const double rx = px - gx[j], ry = py - gy[j], rz = pz - gz[j];
    const double inv = 1.0 / std::sqrt(rx * rx + ry * ry + rz * rz + eps2);
    const double w3 = wl[j] * inv * inv * inv;
    const double diag = wl[j] * inv + eps2 * w3;
    const double xx = diag + w3 * rx * rx, xy = w3 * rx * ry, xz = w3 * rx * rz;
    const double yy = diag + w3 * ry * ry, yz = w3 * ry * rz, zz = diag + w3 * rz * rz;
    axx[j] += beta * xx, axy[j] += beta * xy, axz[j] += beta * xz;
    ayy[j] += beta * yy, ayz[j] += beta * yz, azz[j] += beta * zz;
    bxx[j] += gamma * xx, bxy[j] += gamma * xy, bxz[j] += gamma * xz;
    byy[j] += gamma * yy, byz[j] += gamma * yz, bzz[j] += gamma * zz;
  }
}

// d2[j] = |p − midpoint_j|² for j < count.
__attribute__((target_clones("avx512f", "avx2", "default")))
void MidpointDistances(const double* mx, const double* my, const double* mz, int count,
                       const double* p, double* d2) {
  const double px = p[0], py = p[1], pz = p[2];
#pragma omp simd
  for (int j = 0; j < count; ++j) {
    const double rx = px - mx[j], ry = py - my[j], rz = pz - mz[j];
    d2[j] = rx * rx + ry * ry + rz * rz;
  }
}

// The six entries of a symmetric 3×3 block into column j of the 12-row table (offset 0 or 6).
void StoreSymmetric(const Mat3& m, int j, int stride, int offset, double* out) {
  const double e[6] = {m(0, 0), m(0, 1), m(0, 2), m(1, 1), m(1, 2), m(2, 2)};
  for (int c = 0; c < 6; ++c) out[(offset + c) * stride + j] = e[c];
}

}  // namespace

RssRowKernel::RssRowKernel(const Matrix3X& x, double regularization, double tolerance,
                           int subtracted_rule)
    : x_(&x), eps_(regularization), tolerance_(tolerance),
      segments_(static_cast<int>(x.cols()) - 1) {
  SR_ASSERT(segments_ >= 1 && regularization > 0.0, "RSS rows need a segment and ε > 0");
  int n = 2;
  while (n < 20 && GaussRuleMinDelta(n, tolerance) > kDenseRuleDelta) ++n;
  min_delta_ = GaussRuleMinDelta(n, tolerance);
  rule_ = MakeCloud(n);
  if (subtracted_rule > 0) subtracted_ = MakeCloud(subtracted_rule);
  const auto segments = static_cast<size_t>(segments_);
  mx_.resize(segments), my_.resize(segments), mz_.resize(segments), reach2_.resize(segments);
  for (int j = 0; j < segments_; ++j) {
    const Vec3 mid = 0.5 * (x.col(j) + x.col(j + 1));
    const auto js = static_cast<size_t>(j);
    mx_[js] = mid.x(), my_[js] = mid.y(), mz_[js] = mid.z();
    reach2_[js] = std::pow((min_delta_ + 0.5) * (x.col(j + 1) - x.col(j)).norm(), 2);
  }
}

RssRowKernel::Cloud RssRowKernel::MakeCloud(int points) const {
  Cloud c;
  c.points = points;
  const double* weight = nullptr;
  GaussLegendreRule01(points, &c.alpha, &weight);
  const auto total = static_cast<size_t>(points * segments_);
  c.x.resize(total), c.y.resize(total), c.z.resize(total), c.wl.resize(total);
  for (int j = 0; j < segments_; ++j) {
    const Vec3 xa = x_->col(j), v = x_->col(j + 1) - xa;
    const double length = v.norm();
    for (int q = 0; q < points; ++q) {
      const auto k = static_cast<size_t>(q * segments_ + j);
      const Vec3 g = xa + c.alpha[q] * v;
      c.x[k] = g.x(), c.y[k] = g.y(), c.z[k] = g.z();
      c.wl[k] = weight[q] * length;
    }
  }
  return c;
}

void RssRowKernel::AddCloud(const Cloud& cloud, double sign, const Vec3& p, int first, int count,
                            double* table) const {
  for (int q = 0; q < cloud.points; ++q) {
    const int k = q * segments_ + first;
    AddRulePoint(cloud.x.data() + k, cloud.y.data() + k, cloud.z.data() + k, cloud.wl.data() + k,
                 cloud.alpha[q], sign, eps_ * eps_, count, p.data(), table, count);
  }
}

void RssRowKernel::Row(const Vec3& p, int first, int count, double* table) const {
  SR_ASSERT(first >= 0 && count >= 0 && first + count <= segments_, "RSS rows: bad range");
  std::fill(table, table + 12 * count, 0.0);
  AddCloud(rule_, 1.0, p, first, count, table);
  thread_local std::vector<double> d2;
  d2.resize(static_cast<size_t>(count));
  MidpointDistances(mx_.data() + first, my_.data() + first, mz_.data() + first, count, p.data(),
                    d2.data());
  for (int i = 0; i < count; ++i) {
    const int j = first + i;
    if (d2[static_cast<size_t>(i)] >= reach2_[static_cast<size_t>(j)]) continue;
    const SegmentMobility exact = StokesletSegment(x_->col(j), x_->col(j + 1), eps_, p, tolerance_);
    StoreSymmetric(exact.a, i, count, 0, table);
    StoreSymmetric(exact.b, i, count, 6, table);
  }
}

void RssRowKernel::SubtractRule(const Vec3& p, int first, int count, double* table) const {
  SR_ASSERT(subtracted_.points > 0, "RSS rows: no subtracted rule was set");
  SR_ASSERT(first >= 0 && count >= 0 && first + count <= segments_, "RSS rows: bad range");
  AddCloud(subtracted_, -1.0, p, first, count, table);
}

}  // namespace stokesrods
