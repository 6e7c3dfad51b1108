#include "stokesrods/fluid/mobility_sources.h"

#include <algorithm>
#include <cmath>

#include "stokesrods/common/assert.h"
#include "stokesrods/fluid/stokeslet_segment.h"
#include "stokesrods/fluid/stokeslet_sum.h"
#include "stokesrods/fluid/wall.h"

namespace stokesrods {

namespace {

class MobilityWithBodySources final : public MobilityOperator {
 public:
  MobilityWithBodySources(const FluidParams& params, const MobilityOptions& options,
                          std::unique_ptr<MobilityOperator> rods_operator)
      : params_(params),
        accuracy_(std::max(options.tolerance, options.fast_sum_tolerance)),
        sum_options_({.tolerance = options.fast_sum_tolerance,
                      .direct_below_pairs = static_cast<std::int64_t>(options.direct_sum_below),
                      .choose_by_cost = options.fast_sum_by_cost}),
        rods_operator_(std::move(rods_operator)) {
    SR_ASSERT(!params.wall, "bodies as sources: no wall images here (dense operator)");
  }

  void Update(const std::vector<HydroRod>& rods) override { UpdateWithBodies(rods, {}); }
  void UpdateWithBodies(const std::vector<HydroRod>& rods,
                        const std::vector<BodySurface>& bodies) override;
  void Apply(const VecX& force, VecX* velocity) const override;
  MatX SelfBlock(int rod) const override { return rods_operator_->SelfBlock(rod); }
  void ForgetHistory() override { rods_operator_->ForgetHistory(); }
  MobilityReuseStats reuse_stats() const override { return rods_operator_->reuse_stats(); }
  MobilityCostCounts cost_counts() const override { return rods_operator_->cost_counts(); }

 private:
  void AddRodsAtPoints(const VecX& force, VecX* velocity) const;
  void BuildSums();

  FluidParams params_;
  double accuracy_;
  StokesletSumOptions sum_options_;
  std::unique_ptr<MobilityOperator> rods_operator_;
  std::vector<HydroRod> rods_;
  std::vector<BodySurface> bodies_;
  Matrix3X nodes_;               // 3 × M
  VecX inverse_voronoi_;         // 1/Λ_j
  Matrix3X points_;              // 3 × P
  VecX point_eps_;               // the bodies' blobs ε
  std::unique_ptr<StokesletSum> at_points_;  // rods' Gauss points and body points → body points
  std::unique_ptr<StokesletSum> at_nodes_;   // body points → rod nodes
  int num_gauss_ = 0;
  NearBlocks near_;              // of the rods at the body points (the rods' operator's)
};

void MobilityWithBodySources::UpdateWithBodies(const std::vector<HydroRod>& rods,
                                               const std::vector<BodySurface>& bodies) {
  rods_operator_->Update(rods);
  SetLayout(rods);
  rods_ = rods;
  bodies_ = bodies;
  const int m = node_offset(num_rods());
  nodes_.resize(3, m);
  inverse_voronoi_.resize(m);
  for (int r = 0; r < num_rods(); ++r) {
    const Matrix3X& x = *rods[static_cast<size_t>(r)].x;
    nodes_.middleCols(node_offset(r), x.cols()) = x;
    inverse_voronoi_.segment(node_offset(r), x.cols()) = VoronoiLengths(x).cwiseInverse();
  }
  for (const BodySurface& b : bodies) {
    num_body_points_ += static_cast<int>(b.points.cols());
    num_free_bodies_ += b.free ? 1 : 0;
  }
  points_.resize(3, num_body_points_);
  point_eps_.resize(num_body_points_);
  int k = 0;
  for (const BodySurface& b : bodies) {
    points_.middleCols(k, b.points.cols()) = b.points;
    point_eps_.segment(k, b.points.cols()).setConstant(b.regularization);
    k += static_cast<int>(b.points.cols());
  }
  BuildSums();
  rods_operator_->FindNearBlocks(points_, &near_);
}

// The far-field sums of the bodies' points (fluid/stokeslet_sum.h, the rods' operator's fast sum
// options): at the body points, every rod segment by the split's Gauss rule (the near blocks
// correct the near ones) and every body point; at the rod nodes, every body point.
void MobilityWithBodySources::BuildSums() {
  const int g = rods_operator_->cost_counts().gauss_points;  // the rods' rule, as in their near blocks
  const double* alpha = nullptr;
  const double* weight = nullptr;
  GaussLegendreRule01(g, &alpha, &weight);
  const int m = node_offset(num_rods());
  num_gauss_ = g * (m - num_rods());
  Matrix3X sources(3, num_gauss_ + num_body_points_);
  VecX eps(num_gauss_ + num_body_points_);
  int k = 0;
  for (int r = 0; r < num_rods(); ++r)
    for (int a = node_offset(r); a + 1 < node_offset(r + 1); ++a)
      for (int q = 0; q < g; ++q, ++k) {
        sources.col(k) = nodes_.col(a) + alpha[q] * (nodes_.col(a + 1) - nodes_.col(a));
        eps(k) = params_.regularization * rods_[static_cast<size_t>(r)].radius;
      }
  sources.rightCols(num_body_points_) = points_;
  eps.tail(num_body_points_) = point_eps_;
  at_points_ = MakeFastStokesletSum(sum_options_);
  at_points_->Build(sources, eps, points_);
  at_nodes_ = MakeFastStokesletSum(sum_options_);
  at_nodes_->Build(points_, point_eps_, nodes_);
}

// velocity (at the body points) += the rods' segments (the far rule at every segment plus the
// near blocks) and the bodies' points.
void MobilityWithBodySources::AddRodsAtPoints(const VecX& force, VecX* velocity) const {
  const int g = rods_operator_->cost_counts().gauss_points;  // the rods' rule, as in their near blocks
  const double* alpha = nullptr;
  const double* weight = nullptr;
  GaussLegendreRule01(g, &alpha, &weight);
  // The rule's strengths w_q L ((1 − α_q) f_a + α_q f_b), f = F/Λ, then the points' forces.
  const int m = node_offset(num_rods());
  Matrix3X strength(3, num_gauss_ + num_body_points_);
  int k = 0;
  for (int r = 0; r < num_rods(); ++r)
    for (int a = node_offset(r); a + 1 < node_offset(r + 1); ++a) {
      const Vec3 fa = force.segment<3>(3 * a) * inverse_voronoi_(a);
      const Vec3 fb = force.segment<3>(3 * (a + 1)) * inverse_voronoi_(a + 1);
      const double length = (nodes_.col(a + 1) - nodes_.col(a)).norm();
      for (int q = 0; q < g; ++q, ++k)
        strength.col(k) = (weight[q] * length) * ((1.0 - alpha[q]) * fa + alpha[q] * fb);
    }
  for (int j = 0; j < num_body_points_; ++j) strength.col(k + j) = force.segment<3>(3 * (m + j));
  Matrix3X w;
  at_points_->Apply(strength, &w);
  const double scale = 1.0 / (8.0 * kPi * params_.viscosity);
#pragma omp parallel for schedule(static)
  for (int t = 0; t < num_body_points_; ++t)
    velocity->segment<3>(3 * (m + t)) += scale * w.col(t) + near_.At(t, force);
}

void MobilityWithBodySources::Apply(const VecX& force, VecX* velocity) const {
  SR_ASSERT(force.size() == size(), "mobility: force vector of the wrong size");
  const int m = node_offset(num_rods()), p = num_body_points_;
  VecX rods_velocity;
  if (m > 0) rods_operator_->Apply(force.head(3 * m), &rods_velocity);
  velocity->setZero(size());
  velocity->head(3 * m) = rods_velocity;
  if (p == 0) return;
  // The bodies' blobs at the rod nodes; the rods and the bodies at the body points.
  if (m > 0) {
    Matrix3X w;
    at_nodes_->Apply(Eigen::Map<const Matrix3X>(force.data() + 3 * m, 3, p), &w);
    velocity->head(3 * m) += Eigen::Map<const VecX>(w.data(), 3 * m) / (8.0 * kPi * params_.viscosity);
  }
  AddRodsAtPoints(force, velocity);
  // The free bodies' border: G V on their points, Gᵀ f in their rows.
  int point = m, mode = 3 * (m + p);
  for (const BodySurface& b : bodies_) {
    if (b.free) {
      const Vec3 u = force.segment<3>(mode), omega = force.segment<3>(mode + 3);
      Vec3 total = Vec3::Zero(), torque = Vec3::Zero();
      for (Eigen::Index j = 0; j < b.points.cols(); ++j) {
        const Vec3 arm = b.points.col(j) - b.center, f = force.segment<3>(3 * (point + j));
        velocity->segment<3>(3 * (point + j)) += u + omega.cross(arm);
        total += f;
        torque += arm.cross(f);
      }
      velocity->segment<3>(mode) = total;
      velocity->segment<3>(mode + 3) = torque;
      mode += 6;
    }
    point += static_cast<int>(b.points.cols());
  }
}

}  // namespace

std::unique_ptr<MobilityOperator> MakeMobilityWithBodySources(
    const FluidParams& params, const MobilityOptions& options,
    std::unique_ptr<MobilityOperator> rods_operator) {
  return std::make_unique<MobilityWithBodySources>(params, options, std::move(rods_operator));
}

}  // namespace stokesrods
