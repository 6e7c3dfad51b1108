#include "stokesrods/fluid/wall_sources.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "stokesrods/common/assert.h"
#include "stokesrods/fluid/rss_wall.h"
#include "stokesrods/fluid/stokeslet_segment.h"
#include "stokesrods/fluid/wall.h"

namespace stokesrods {

namespace {

// Structure of arrays of the image sources: blob at y (height above the wall h), ε², strength f.
struct ImageSources {
  std::vector<double> x, y, z, h, e2, fx, fy, fz;
  void Resize(std::size_t n) {
    for (std::vector<double>* v : {&x, &y, &z, &h, &e2, &fx, &fy, &fz}) v->resize(n);
  }
};

// 8πμ × the images' velocity at p of every source: Σ (W − S_ε)(p, y_k) f_k (wall.h), the terms
// of W − S_ε collected on f, R = p − y* and n.
__attribute__((target_clones("avx2", "default")))
Vec3 SumImages(const Vec3& p, const Vec3& n, const ImageSources& s) {
  double ux = 0.0, uy = 0.0, uz = 0.0;
  const double nx = n.x(), ny = n.y(), nz = n.z();
  const double px = p.x(), py = p.y(), pz = p.z();
  const auto count = static_cast<int>(s.x.size());
#pragma omp simd reduction(+ : ux, uy, uz)
  for (int k = 0; k < count; ++k) {
    const double h = s.h[k], e2 = s.e2[k];
    const double rx = px - s.x[k] + 2.0 * h * nx, ry = py - s.y[k] + 2.0 * h * ny,
                 rz = pz - s.z[k] + 2.0 * h * nz;  // R = x − x0*
    const double fx = s.fx[k], fy = s.fy[k], fz = s.fz[k];
    const double r2 = rx * rx + ry * ry + rz * rz, rn = rx * nx + ry * ny + rz * nz;
    const double rf = rx * fx + ry * fy + rz * fz, nf = nx * fx + ny * fy + nz * fz;
    const double drf = rf - 2.0 * rn * nf;  // (ΔR)·f
    const double inv = 1.0 / std::sqrt(r2 + e2);
    const double inv3 = inv * inv * inv, inv5 = inv3 * inv * inv;
    const double cd = 2.0 * h * h * inv3 - 6.0 * h * h * e2 * inv5 - 2.0 * h * rn * inv3;  // on Δf
    const double cf = -(r2 + 2.0 * e2) * inv3 + 6.0 * h * e2 * inv5 * rn + cd;
    const double cr = -inv3 * rf - 6.0 * h * h * inv5 * drf + 2.0 * h * inv3 * nf +
                      6.0 * h * rn * inv5 * drf;
    const double cn = 2.0 * h * (r2 + 4.0 * e2) * inv5 * drf - 6.0 * h * e2 * inv5 * rf -
                      2.0 * nf * cd;
    ux += cf * fx + cr * rx + cn * nx;
    uy += cf * fy + cr * ry + cn * ny;
    uz += cf * fz + cr * rz + cn * nz;
  }
  return {ux, uy, uz};
}

class MobilityWithWallImages final : public MobilityOperator {
 public:
  MobilityWithWallImages(const FluidParams& params, const MobilityOptions& options,
                         std::unique_ptr<MobilityOperator> free_space)
      : params_(params),
        split_(ChooseWallImageSplit(std::max(options.tolerance, options.fast_sum_tolerance),
                                    options.fast_sum_near_delta)),
        free_space_(std::move(free_space)) {
    SR_ASSERT(params.wall.has_value(), "wall images need a wall");
  }

  void Update(const std::vector<HydroRod>& rods) override { UpdateWithBodies(rods, {}); }
  void UpdateWithBodies(const std::vector<HydroRod>& rods,
                        const std::vector<BodySurface>& bodies) override;
  void Apply(const VecX& force, VecX* velocity) const override;
  MatX SelfBlock(int rod) const override {
    MatX block = free_space_->SelfBlock(rod);
    AddRssWallImages(params_, {rods_[static_cast<size_t>(rod)]}, &block);
    return block;
  }
  void ForgetHistory() override { free_space_->ForgetHistory(); }
  MobilityReuseStats reuse_stats() const override { return free_space_->reuse_stats(); }

 private:
  void FindNearImages();

  FluidParams params_;
  NearFarSplit split_;
  std::unique_ptr<MobilityOperator> free_space_;
  std::vector<HydroRod> rods_;
  Matrix3X targets_;        // 3 × (M + P): the rods' nodes, then the bodies' points
  VecX inverse_voronoi_;    // 1/Λ_j
  std::vector<int> segment_first_node_;
  mutable ImageSources sources_;  // the segments' Gauss points, then the bodies' blobs
  NearBlocks near_;
};

void MobilityWithWallImages::UpdateWithBodies(const std::vector<HydroRod>& rods,
                                              const std::vector<BodySurface>& bodies) {
  free_space_->UpdateWithBodies(rods, bodies);
  SetLayout(rods);
  for (const BodySurface& b : bodies) {
    num_body_points_ += static_cast<int>(b.points.cols());
    num_free_bodies_ += b.free ? 1 : 0;
  }
  SR_ASSERT(size() == free_space_->size(), "wall images: layouts differ");
  rods_ = rods;
  const int m = node_offset(num_rods());
  targets_.resize(3, m + num_body_points_);
  inverse_voronoi_.resize(m);
  segment_first_node_.clear();
  for (int r = 0; r < num_rods(); ++r) {
    const Matrix3X& x = *rods[static_cast<size_t>(r)].x;
    targets_.middleCols(node_offset(r), x.cols()) = x;
    inverse_voronoi_.segment(node_offset(r), x.cols()) = VoronoiLengths(x).cwiseInverse();
    for (int j = 0; j + 1 < x.cols(); ++j) segment_first_node_.push_back(node_offset(r) + j);
  }
  const Wall& wall = *params_.wall;
  const int g = split_.gauss_points;
  const double* alpha = nullptr;
  const double* weight = nullptr;
  GaussLegendreRule01(g, &alpha, &weight);
  const std::size_t num_gauss = segment_first_node_.size() * static_cast<size_t>(g);
  sources_.Resize(num_gauss + static_cast<size_t>(num_body_points_));
  auto place = [&](std::size_t k, const Vec3& y, double eps) {
    sources_.x[k] = y.x(), sources_.y[k] = y.y(), sources_.z[k] = y.z();
    sources_.h[k] = (y - wall.point).dot(wall.normal);
    sources_.e2[k] = eps * eps;
  };
  std::size_t k = 0;
  for (int r = 0; r < num_rods(); ++r) {
    const double eps = params_.regularization * rods[static_cast<size_t>(r)].radius;
    for (int a = node_offset(r); a + 1 < node_offset(r + 1); ++a)
      for (int q = 0; q < g; ++q)
        place(k++, targets_.col(a) + alpha[q] * (targets_.col(a + 1) - targets_.col(a)), eps);
  }
  int point = m;
  for (const BodySurface& b : bodies)
    for (Eigen::Index j = 0; j < b.points.cols(); ++j) {
      targets_.col(point++) = b.points.col(j);
      place(k++, b.points.col(j), b.regularization);
    }
  FindNearImages();
}

// Near pairs by a cheap bound first: the mirrored segment lies at least as deep as its lower end,
// so d* ≥ h(target) + min h(ends).
void MobilityWithWallImages::FindNearImages() {
  const Wall& wall = *params_.wall;
  const double scale = 1.0 / (8.0 * kPi * params_.viscosity);
  const int num_targets = static_cast<int>(targets_.cols());
  std::vector<std::vector<std::pair<int, Mat3>>> per_target(static_cast<size_t>(num_targets));
  std::vector<double> eps(segment_first_node_.size());
  for (int r = 0, s = 0; r < num_rods(); ++r)
    for (int a = node_offset(r); a + 1 < node_offset(r + 1); ++a)
      eps[static_cast<size_t>(s++)] = params_.regularization * rods_[static_cast<size_t>(r)].radius;
#pragma omp parallel for schedule(dynamic, 16)
  for (int t = 0; t < num_targets; ++t) {
    const Vec3 p = targets_.col(t);
    const double hp = (p - wall.point).dot(wall.normal);
    for (std::size_t s = 0; s < segment_first_node_.size(); ++s) {
      const int a = segment_first_node_[s];
      const Vec3 xa = targets_.col(a), xb = targets_.col(a + 1);
      const double reach = split_.near_delta * (xb - xa).norm();
      const double low = hp + std::min((xa - wall.point).dot(wall.normal),
                                       (xb - wall.point).dot(wall.normal));
      if (low * low + eps[s] * eps[s] >= reach * reach) continue;
      if (WallImageDelta(wall, xa, xb, eps[s], p) >= split_.near_delta) continue;
      const SegmentMobility exact = StokesletSegmentWallImages(wall, xa, xb, eps[s], p);
      const SegmentMobility rule =
          StokesletSegmentWallImagesGauss(wall, xa, xb, eps[s], p, split_.gauss_points);
      std::vector<std::pair<int, Mat3>>& blocks = per_target[static_cast<size_t>(t)];
      blocks.emplace_back(a, (scale * inverse_voronoi_(a)) * (exact.a - rule.a));
      blocks.emplace_back(a + 1, (scale * inverse_voronoi_(a + 1)) * (exact.b - rule.b));
    }
  }
  near_ = NearBlocks{};
  for (const auto& blocks : per_target) {
    for (const auto& [node, block] : blocks) {
      near_.source.push_back(node);
      near_.block.push_back(block);
    }
    near_.start.push_back(static_cast<int>(near_.source.size()));
  }
}

void MobilityWithWallImages::Apply(const VecX& force, VecX* velocity) const {
  SR_ASSERT(force.size() == size(), "mobility: force vector of the wrong size");
  free_space_->Apply(force, velocity);
  const int g = split_.gauss_points;
  const double* alpha = nullptr;
  const double* weight = nullptr;
  GaussLegendreRule01(g, &alpha, &weight);
  // Strengths: w_q L ((1 − α_q) f_a + α_q f_b) with f = F/Λ at the Gauss points, F at the blobs.
  std::size_t k = 0;
  for (const int a : segment_first_node_) {
    const double length = (targets_.col(a + 1) - targets_.col(a)).norm();
    const Vec3 fa = force.segment<3>(3 * a) * inverse_voronoi_(a);
    const Vec3 fb = force.segment<3>(3 * (a + 1)) * inverse_voronoi_(a + 1);
    for (int q = 0; q < g; ++q, ++k) {
      const Vec3 f = (weight[q] * length) * ((1.0 - alpha[q]) * fa + alpha[q] * fb);
      sources_.fx[k] = f.x(), sources_.fy[k] = f.y(), sources_.fz[k] = f.z();
    }
  }
  const int m = node_offset(num_rods());
  for (int j = 0; j < num_body_points_; ++j, ++k) {
    const Vec3 f = force.segment<3>(3 * (m + j));
    sources_.fx[k] = f.x(), sources_.fy[k] = f.y(), sources_.fz[k] = f.z();
  }
  const double scale = 1.0 / (8.0 * kPi * params_.viscosity);
  const Wall& wall = *params_.wall;
#pragma omp parallel for schedule(static)
  for (int t = 0; t < static_cast<int>(targets_.cols()); ++t)
    velocity->segment<3>(3 * t) +=
        scale * SumImages(targets_.col(t), wall.normal, sources_) + near_.At(t, force);
}

}  // namespace

NearFarSplit ChooseWallImageSplit(double tolerance, double max_near_delta) {
  // WallImageRuleError(n, δ*) = 2 c*_n δ*^−(2n−2) = tolerance at the near radius δ*_n.
  NearFarSplit split;
  const double tol = std::max(tolerance, 1e-15);
  for (int n = 2; n <= 12; ++n) {
    split.gauss_points = n;
    split.near_delta =
        std::max(1.0, std::pow(WallImageRuleError(n, 1.0) / tol, 1.0 / (2.0 * n - 2.0)));
    if (split.near_delta <= max_near_delta) break;
  }
  return split;
}

std::unique_ptr<MobilityOperator> MakeMobilityWithWallImages(
    const FluidParams& params, const MobilityOptions& options,
    std::unique_ptr<MobilityOperator> free_space) {
  return std::make_unique<MobilityWithWallImages>(params, options, std::move(free_space));
}

}  // namespace stokesrods
