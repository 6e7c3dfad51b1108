#include "stokesrods/fluid/rss.h"

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
#pragma omp parallel
  {
    std::vector<double> table;  // per thread: 12 rows × segments
#pragma omp for schedule(dynamic, 8)
    for (Eigen::Index target = 0; target < total; ++target) {
      const auto [rod, column] = target_node[static_cast<size_t>(target)];
      const Vec3 point = rods[static_cast<size_t>(rod)].x->col(column);
      for (std::size_t r = 0; r < sources.size(); ++r) {
        const int n = sources[r].segments();
        table.resize(static_cast<size_t>(12 * n));
        sources[r].Row(point, 0, n, table.data());
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
