#include "stokesrods/fluid/mobility_sources.h"

#include <algorithm>
#include <cmath>

#include "stokesrods/common/assert.h"
#include "stokesrods/fluid/stokeslet_segment.h"
#include "stokesrods/fluid/wall.h"

namespace stokesrods {

namespace {

class MobilityWithBodySources final : public MobilityOperator {
 public:
  MobilityWithBodySources(const FluidParams& params, const MobilityOptions& options,
                          std::unique_ptr<MobilityOperator> rods_operator)
      : params_(params),
        accuracy_(std::max(options.tolerance, options.fast_sum_tolerance)),
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

  FluidParams params_;
  double accuracy_;
  std::unique_ptr<MobilityOperator> rods_operator_;
  std::vector<HydroRod> rods_;
  std::vector<BodySurface> bodies_;
  Matrix3X nodes_;               // 3 × M
  VecX inverse_voronoi_;         // 1/Λ_j
  Matrix3X points_;              // 3 × P
  VecX point_eps_;               // the bodies' blobs ε
  MatX body_block_;              // bodies ← bodies (3P × 3P)
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
  const double scale = 1.0 / (8.0 * kPi * params_.viscosity);
  body_block_.resize(3 * num_body_points_, 3 * num_body_points_);
#pragma omp parallel for schedule(static)
  for (int j = 0; j < num_body_points_; ++j)
    for (int i = 0; i < num_body_points_; ++i)
      body_block_.block<3, 3>(3 * i, 3 * j) =
          scale * PointBlobMatrix(nullptr, points_.col(i), points_.col(j), point_eps_(j));
  rods_operator_->FindNearBlocks(points_, &near_);
}

// velocity (at the body points) += the rods' segments: the far rule at every segment, summed
// directly, plus the near blocks.
void MobilityWithBodySources::AddRodsAtPoints(const VecX& force, VecX* velocity) const {
  const int g = rods_operator_->cost_counts().gauss_points;  // the rods' rule, as in their near blocks
  const double* alpha = nullptr;
  const double* weight = nullptr;
  GaussLegendreRule01(g, &alpha, &weight);
  // The rule's points and strengths w_q L ((1 − α_q) f_a + α_q f_b), f = F/Λ, with their ε².
  std::vector<Vec3> where, strength;
  std::vector<double> eps2;
  for (int r = 0; r < num_rods(); ++r) {
    const double eps = params_.regularization * rods_[static_cast<size_t>(r)].radius;
    for (int a = node_offset(r); a + 1 < node_offset(r + 1); ++a) {
      const Vec3 xa = nodes_.col(a), xb = nodes_.col(a + 1);
      const Vec3 fa = force.segment<3>(3 * a) * inverse_voronoi_(a);
      const Vec3 fb = force.segment<3>(3 * (a + 1)) * inverse_voronoi_(a + 1);
      for (int q = 0; q < g; ++q) {
        where.push_back(xa + alpha[q] * (xb - xa));
        strength.push_back((weight[q] * (xb - xa).norm()) * ((1.0 - alpha[q]) * fa + alpha[q] * fb));
        eps2.push_back(eps * eps);
      }
    }
  }
  const double scale = 1.0 / (8.0 * kPi * params_.viscosity);
  const int m = node_offset(num_rods());
#pragma omp parallel for schedule(static)
  for (int t = 0; t < num_body_points_; ++t) {
    const Vec3 p = points_.col(t);
    Vec3 u = Vec3::Zero();
    for (std::size_t k = 0; k < where.size(); ++k) {
      const Vec3 r = p - where[k];
      const double inv = 1.0 / std::sqrt(r.squaredNorm() + eps2[k]);
      const double inv3 = inv * inv * inv;
      u += (inv + eps2[k] * inv3) * strength[k] + (inv3 * r.dot(strength[k])) * r;
    }
    velocity->segment<3>(3 * (m + t)) += scale * u + near_.At(t, force);
  }
}

void MobilityWithBodySources::Apply(const VecX& force, VecX* velocity) const {
  SR_ASSERT(force.size() == size(), "mobility: force vector of the wrong size");
  const int m = node_offset(num_rods()), p = num_body_points_;
  VecX rods_velocity;
  if (m > 0) rods_operator_->Apply(force.head(3 * m), &rods_velocity);
  velocity->setZero(size());
  velocity->head(3 * m) = rods_velocity;
  const double scale = 1.0 / (8.0 * kPi * params_.viscosity);
  // The bodies' blobs at the rod nodes, summed directly.
#pragma omp parallel for schedule(static)
  for (int i = 0; i < m; ++i) {
    Vec3 u = Vec3::Zero();
    for (int j = 0; j < p; ++j)
      u += PointBlobMatrix(nullptr, nodes_.col(i), points_.col(j), point_eps_(j)) *
           force.segment<3>(3 * (m + j));
    velocity->segment<3>(3 * i) += scale * u;
  }
  if (p == 0) return;
  AddRodsAtPoints(force, velocity);
  velocity->segment(3 * m, 3 * p) += body_block_ * force.segment(3 * m, 3 * p);
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
