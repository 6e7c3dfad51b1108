#include "stokesrods/fluid/rss.h"

#include <cmath>
#include <utility>
#include <vector>

#include "stokesrods/common/assert.h"
#include "stokesrods/fluid/stokeslet_segment.h"

namespace stokesrods {

void AssembleRssDensityMobility(const FluidParams& params, const std::vector<HydroRod>& rods,
                                MatX* density_mobility) {
  const Eigen::Index total = TotalNodes(rods);
  density_mobility->setZero(3 * total, 3 * total);
  const double scale = 1.0 / (8.0 * kPi * params.viscosity);
  std::vector<const Matrix3X*> node_rod;  // rod of each global node, and its column
  std::vector<Eigen::Index> node_col;
  for (const HydroRod& rod : rods)
    for (Eigen::Index i = 0; i < rod.x->cols(); ++i) {
      node_rod.push_back(rod.x);
      node_col.push_back(i);
    }
  // Each target writes its own three rows: targets in parallel.
#pragma omp parallel for schedule(dynamic, 8)
  for (Eigen::Index target = 0; target < total; ++target) {
    const Vec3 point = node_rod[static_cast<size_t>(target)]->col(node_col[static_cast<size_t>(target)]);
    Eigen::Index source = 0;  // global index of the source rod's first node
    for (const HydroRod& rod : rods) {
      const double eps = params.regularization * rod.radius;
      for (Eigen::Index j = 0; j + 1 < rod.x->cols(); ++j) {
        const SegmentMobility s = StokesletSegment(rod.x->col(j), rod.x->col(j + 1), eps, point,
                                                   params.far_field_tolerance);
        density_mobility->block<3, 3>(3 * target, 3 * (source + j)) += scale * s.a;
        density_mobility->block<3, 3>(3 * target, 3 * (source + j + 1)) += scale * s.b;
      }
      source += rod.x->cols();
    }
  }
}

namespace {

// The vectorized assembly. Per source rod, a fixed n-point Gauss–Legendre rule is applied to every
// segment at once (point q of segment j at x_a + α_q v, contiguous over j, so the loop over
// segments vectorizes); the segments closer than GaussRuleMinDelta(n) to the target, where n
// points would not meet the tolerance, are then overwritten by StokesletSegment itself (closed
// forms near, its own Gauss rule between). Every entry is thus at least as accurate as the
// per-pair reference AssembleRssDensityMobility at the same tolerance.
constexpr double kDenseRuleDelta = 2.5;  // n: the fewest points that serve from δ = 2.5 on

struct SourceRod {
  const Matrix3X* x = nullptr;
  double eps = 0.0, eps2 = 0.0, min_delta = 0.0;
  int segments = 0, points = 0;
  const double* alpha = nullptr;     // the rule's nodes on [0, 1]
  std::vector<double> gx, gy, gz, wl;  // point q of segment j at q × segments + j; w_q L_j
  std::vector<double> mx, my, mz, reach2;  // segment midpoints, ((min_delta + ½) L_j)²
};

SourceRod MakeSourceRod(const HydroRod& rod, const FluidParams& params) {
  SourceRod s;
  s.x = rod.x;
  s.eps = params.regularization * rod.radius;
  s.eps2 = s.eps * s.eps;
  s.segments = static_cast<int>(rod.x->cols()) - 1;
  s.points = 2;
  while (s.points < 20 && GaussRuleMinDelta(s.points, params.far_field_tolerance) > kDenseRuleDelta)
    ++s.points;
  s.min_delta = GaussRuleMinDelta(s.points, params.far_field_tolerance);
  const double* weight = nullptr;
  GaussLegendreRule01(s.points, &s.alpha, &weight);
  const auto total = static_cast<size_t>(s.points * s.segments);
  s.gx.resize(total), s.gy.resize(total), s.gz.resize(total), s.wl.resize(total);
  const auto segments = static_cast<size_t>(s.segments);
  s.mx.resize(segments), s.my.resize(segments), s.mz.resize(segments), s.reach2.resize(segments);
  for (int j = 0; j < s.segments; ++j) {
    const Vec3 xa = rod.x->col(j), v = rod.x->col(j + 1) - xa;
    const double length = v.norm();
    for (int q = 0; q < s.points; ++q) {
      const auto k = static_cast<size_t>(q * s.segments + j);
      const Vec3 g = xa + s.alpha[q] * v;
      s.gx[k] = g.x(), s.gy[k] = g.y(), s.gz[k] = g.z();
      s.wl[k] = weight[q] * length;
    }
    const Vec3 mid = xa + 0.5 * v;
    const auto js = static_cast<size_t>(j);
    s.mx[js] = mid.x(), s.my[js] = mid.y(), s.mz[js] = mid.z();
    s.reach2[js] = std::pow((s.min_delta + 0.5) * length, 2);
  }
  return s;
}

// out[c × stride + j] += (1 − α) T_c (c = 0…5) and out[(6 + c) × stride + j] += α T_c for one
// rule point on every segment j: T = the six entries xx, xy, xz, yy, yz, zz of w L S_ε(p − x_q).
__attribute__((target_clones("avx512f", "avx2", "default")))
void AddRulePoint(const double* gx, const double* gy, const double* gz, const double* wl,
                  double alpha, double eps2, int count, const double* p, double* out,
                  int stride) {
  const double beta = 1.0 - alpha, px = p[0], py = p[1], pz = p[2];
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
    bxx[j] += alpha * xx, bxy[j] += alpha * xy, bxz[j] += alpha * xz;
    byy[j] += alpha * yy, byz[j] += alpha * yz, bzz[j] += alpha * zz;
  }
}

// |p − midpoint_j|² of every segment.
__attribute__((target_clones("avx512f", "avx2", "default")))
void MidpointDistances(const SourceRod& s, const double* p, double* d2) {
  const double *mx = s.mx.data(), *my = s.my.data(), *mz = s.mz.data();
  const double px = p[0], py = p[1], pz = p[2];
#pragma omp simd
  for (int j = 0; j < s.segments; ++j) {
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

void AssembleRssMobility(const FluidParams& params, const std::vector<HydroRod>& rods,
                         MatX* mobility) {
  const Eigen::Index total = TotalNodes(rods);
  mobility->resize(3 * total, 3 * total);
  const double scale = 1.0 / (8.0 * kPi * params.viscosity);
  std::vector<SourceRod> sources;
  std::vector<VecX> node_scale;  // 1/(8πμ Δl_k): 𝕄 = A Λ⁻¹
  std::vector<Eigen::Index> first_node;
  std::vector<std::pair<int, Eigen::Index>> target_node;  // (rod, column) of each global node
  Eigen::Index offset = 0;
  for (std::size_t r = 0; r < rods.size(); ++r) {
    sources.push_back(MakeSourceRod(rods[r], params));
    node_scale.push_back(scale * VoronoiLengths(*rods[r].x).cwiseInverse());
    first_node.push_back(offset);
    for (Eigen::Index i = 0; i < rods[r].x->cols(); ++i)
      target_node.emplace_back(static_cast<int>(r), i);
    offset += rods[r].x->cols();
  }
#pragma omp parallel
  {
    std::vector<double> table, d2;  // per thread: 12 rows × segments, midpoint distances
#pragma omp for schedule(dynamic, 8)
    for (Eigen::Index target = 0; target < total; ++target) {
      const auto [rod, column] = target_node[static_cast<size_t>(target)];
      const Vec3 point = rods[static_cast<size_t>(rod)].x->col(column);
      for (std::size_t r = 0; r < sources.size(); ++r) {
        const SourceRod& s = sources[r];
        const int n = s.segments;
        table.assign(static_cast<size_t>(12 * n), 0.0);
        d2.resize(static_cast<size_t>(n));
        for (int q = 0; q < s.points; ++q)
          AddRulePoint(s.gx.data() + q * n, s.gy.data() + q * n, s.gz.data() + q * n,
                       s.wl.data() + q * n, s.alpha[q], s.eps2, n, point.data(), table.data(), n);
        MidpointDistances(s, point.data(), d2.data());
        for (int j = 0; j < n; ++j) {
          if (d2[static_cast<size_t>(j)] >= s.reach2[static_cast<size_t>(j)]) continue;
          const SegmentMobility exact = StokesletSegment(s.x->col(j), s.x->col(j + 1), s.eps,
                                                         point, params.far_field_tolerance);
          StoreSymmetric(exact.a, j, n, 0, table.data());
          StoreSymmetric(exact.b, j, n, 6, table.data());
        }
        // Node k collects A_a of segment k and A_b of segment k − 1.
        for (int k = 0; k <= n; ++k) {
          double e[6];
          for (int c = 0; c < 6; ++c)
            e[c] = (k < n ? table[static_cast<size_t>(c * n + k)] : 0.0) +
                   (k > 0 ? table[static_cast<size_t>((6 + c) * n + k - 1)] : 0.0);
          const double w = node_scale[r](k);
          auto block = mobility->block<3, 3>(3 * target, 3 * (first_node[r] + k));
          block << w * e[0], w * e[1], w * e[2], w * e[1], w * e[3], w * e[4], w * e[2],
              w * e[4], w * e[5];
        }
      }
    }
  }
}

Vec3 RssVelocityAt(const FluidParams& params, const std::vector<HydroRod>& rods,
                   const VecX& nodal_forces, const Vec3& point) {
  SR_ASSERT(nodal_forces.size() == 3 * TotalNodes(rods), "RSS: force vector of the wrong size");
  Vec3 u = Vec3::Zero();
  Eigen::Index offset = 0;
  for (const HydroRod& rod : rods) {
    const double eps = params.regularization * rod.radius;
    const VecX lengths = VoronoiLengths(*rod.x);
    for (Eigen::Index j = 0; j + 1 < rod.x->cols(); ++j) {
      const SegmentMobility s = StokesletSegment(rod.x->col(j), rod.x->col(j + 1), eps, point);
      const Vec3 fa = nodal_forces.segment<3>(3 * (offset + j)) / lengths(j);
      const Vec3 fb = nodal_forces.segment<3>(3 * (offset + j + 1)) / lengths(j + 1);
      u += s.a * fa + s.b * fb;
    }
    offset += rod.x->cols();
  }
  return u / (8.0 * kPi * params.viscosity);
}

}  // namespace stokesrods
