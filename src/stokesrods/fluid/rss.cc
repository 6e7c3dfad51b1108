#include "stokesrods/fluid/rss.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "stokesrods/common/assert.h"
#include "stokesrods/fluid/rss_rows.h"
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

void AssembleRssMobility(const FluidParams& params, const std::vector<HydroRod>& rods,
                         MatX* mobility) {
  // Rows of A by RssRowKernel (vectorized over each rod's segments), scaled by Λ⁻¹/(8πμ).
  const Eigen::Index total = TotalNodes(rods);
  mobility->resize(3 * total, 3 * total);
  const double scale = 1.0 / (8.0 * kPi * params.viscosity);
  std::vector<RssRowKernel> sources;
  std::vector<VecX> node_scale;  // 1/(8πμ Δl_k): 𝕄 = A Λ⁻¹
  std::vector<Eigen::Index> first_node;
  std::vector<std::pair<int, Eigen::Index>> target_node;  // (rod, column) of each global node
  Eigen::Index offset = 0;
  for (std::size_t r = 0; r < rods.size(); ++r) {
    sources.emplace_back(*rods[r].x, params.regularization * rods[r].radius,
                         params.far_field_tolerance);
    node_scale.push_back(scale * VoronoiLengths(*rods[r].x).cwiseInverse());
    first_node.push_back(offset);
    for (Eigen::Index i = 0; i < rods[r].x->cols(); ++i)
      target_node.emplace_back(static_cast<int>(r), i);
    offset += rods[r].x->cols();
  }
  // Targets in chunks of kChunk consecutive nodes: each chunk's rows are computed first, then
  // written column by column, 3 kChunk consecutive entries of each column of the column-major 𝕄
  // (a target's three rows alone wrote 3 doubles per column, entry by entry; perf put 31 % of
  // the assembly there). MEASURED (AMD EPYC, one thread, bench_step BM_RssMobilityAssembly/2,
  // 390 × 390, medians of 5, two sittings): 0.86–1.05 → 0.66–0.67 ms; the same bits.
  constexpr Eigen::Index kChunk = 8;
  const Eigen::Index chunks = (total + kChunk - 1) / kChunk;
#pragma omp parallel
  {
    std::vector<double> tables;   // per thread: kChunk tables of 12 rows × segments
    std::vector<double> entries;  // and their 6 entries per node
#pragma omp for schedule(dynamic, 1)
    for (Eigen::Index chunk = 0; chunk < chunks; ++chunk) {
      const Eigen::Index first_target = chunk * kChunk;
      const auto count = static_cast<int>(std::min(kChunk, total - first_target));
      for (std::size_t r = 0; r < sources.size(); ++r) {
        const int n = sources[r].segments();
        const auto size = static_cast<size_t>(12 * n);
        tables.resize(size * kChunk);
        for (int t = 0; t < count; ++t) {
          const auto [rod, column] = target_node[static_cast<size_t>(first_target + t)];
          const Vec3 point = rods[static_cast<size_t>(rod)].x->col(column);
          sources[r].Row(point, 0, n, tables.data() + t * size);
        }
        // Node k collects A_a of segment k and A_b of segment k − 1, times 1/(8πμ Δl_k): the
        // six entries per node, by rows over the nodes (vectorized), then written by columns.
        // The end nodes have one segment; their "+ 0.0" (the missing one) keeps the bits of
        // the sum as it was formed before, a zero's sign included.
        const double* w = node_scale[r].data();
        const auto stride = static_cast<size_t>(n) + 1;
        entries.resize(6 * stride * kChunk);
        for (int t = 0; t < count; ++t) {
          const double* table = tables.data() + t * size;
          for (int c = 0; c < 6; ++c) {
            const double* a = table + c * n;
            const double* b = table + (6 + c) * n;
            double* e = entries.data() + (6 * t + c) * stride;
            e[0] = w[0] * (a[0] + 0.0);
#pragma omp simd
            for (int k = 1; k < n; ++k) e[k] = w[k] * (a[k] + b[k - 1]);
            e[n] = w[n] * (0.0 + b[n - 1]);
          }
        }
        const Eigen::Index ld = mobility->rows();
        for (int k = 0; k <= n; ++k) {
          double* col = mobility->data() + (3 * (first_node[r] + k)) * ld + 3 * first_target;
          for (int t = 0; t < count; ++t) {
            const double* e = entries.data() + 6 * t * stride + k;
            const double xx = e[0], xy = e[stride], xz = e[2 * stride], yy = e[3 * stride],
                         yz = e[4 * stride], zz = e[5 * stride];
            // the block's columns: (xx, xy, xz), (xy, yy, yz), (xz, yz, zz)
            double* b = col + 3 * t;
            b[0] = xx, b[1] = xy, b[2] = xz;
            b[ld] = xy, b[ld + 1] = yy, b[ld + 2] = yz;
            b[2 * ld] = xz, b[2 * ld + 1] = yz, b[2 * ld + 2] = zz;
          }
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
