#include "stokesrods/fluid/near_search.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "stokesrods/common/assert.h"

namespace stokesrods {

namespace {

// flags[k] = 1 where segment first + k is near p: |p − closest point|² + ε² < δ²|v|².
__attribute__((target_clones("avx512f", "avx2", "default")))
void MarkNearSegments(const Vec3& p, int first, int count, const double* ax, const double* ay,
                      const double* az, const double* vx, const double* vy, const double* vz,
                      const double* inv_v2, const double* e2, const double* reach2,
                      unsigned char* flags) {
  const double px = p.x(), py = p.y(), pz = p.z();
#pragma omp simd
  for (int k = 0; k < count; ++k) {
    const int s = first + k;
    const double dx = px - ax[s], dy = py - ay[s], dz = pz - az[s];
    const double t = std::clamp((dx * vx[s] + dy * vy[s] + dz * vz[s]) * inv_v2[s], 0.0, 1.0);
    const double rx = dx - t * vx[s], ry = dy - t * vy[s], rz = dz - t * vz[s];
    flags[k] = rx * rx + ry * ry + rz * rz + e2[s] < reach2[s];
  }
}

// flags[k] = 1 where segment s = candidates[k] is near p (MarkNearSegments' test, gathered).
__attribute__((target_clones("avx512f", "avx2", "default")))
void MarkNearAmong(const Vec3& p, const int* candidates, int count, const double* ax,
                   const double* ay, const double* az, const double* vx, const double* vy,
                   const double* vz, const double* inv_v2, const double* e2,
                   const double* reach2, unsigned char* flags) {
  const double px = p.x(), py = p.y(), pz = p.z();
#pragma omp simd
  for (int k = 0; k < count; ++k) {
    const int s = candidates[k];
    const double dx = px - ax[s], dy = py - ay[s], dz = pz - az[s];
    const double t = std::clamp((dx * vx[s] + dy * vy[s] + dz * vz[s]) * inv_v2[s], 0.0, 1.0);
    const double rx = dx - t * vx[s], ry = dy - t * vy[s], rz = dz - t * vz[s];
    flags[k] = rx * rx + ry * ry + rz * rz + e2[s] < reach2[s];
  }
}

// The indices index(k) whose flag is set, appended to `near` (branch-free: every index is
// written, the near ones kept).
template <typename Index>
void KeepFlagged(const Index& index, int count, const unsigned char* flags,
                 std::vector<int>* near) {
  std::size_t found = near->size();
  near->resize(found + static_cast<size_t>(count));
  for (int k = 0; k < count; ++k) {
    (*near)[found] = index(k);
    found += flags[k];
  }
  near->resize(found);
}

struct NoScratch {};

}  // namespace

void NearSegmentSearch::Build(const Matrix3X& nodes, const std::vector<int>& first_node,
                              const VecX& eps, const std::vector<int>& rod_first_segment,
                              double delta) {
  const int num_segments = static_cast<int>(first_node.size());
  const int num_rods = static_cast<int>(rod_first_segment.size()) - 1;
  SR_ASSERT(eps.size() == num_segments && num_rods >= 0 &&
                (num_rods == 0 || rod_first_segment.back() == num_segments),
            "near search: one ε per segment, rods covering the segments");
  for (auto* v : {&ax_, &ay_, &az_, &vx_, &vy_, &vz_, &inv_v2_, &e2_, &reach2_})
    v->resize(static_cast<size_t>(num_segments));
  chunk_first_segment_.clear();
  rod_first_chunk_.assign(static_cast<size_t>(num_rods) + 1, 0);
  for (int r = 0; r < num_rods; ++r) {
    rod_first_chunk_[static_cast<size_t>(r)] = static_cast<int>(chunk_first_segment_.size());
    for (int s = rod_first_segment[static_cast<size_t>(r)];
         s < rod_first_segment[static_cast<size_t>(r) + 1]; s += kChunkSegments)
      chunk_first_segment_.push_back(s);
  }
  rod_first_chunk_.back() = static_cast<int>(chunk_first_segment_.size());
  chunk_first_segment_.push_back(num_segments);
  const std::size_t num_boxes = static_cast<size_t>(num_rods) + chunk_first_segment_.size() - 1;
  boxes_.assign(num_boxes, Eigen::AlignedBox3d());
  box_reach_.assign(num_boxes, 0.0);
  for (int r = 0; r < num_rods; ++r)
    for (int c = rod_first_chunk_[static_cast<size_t>(r)]; c < rod_first_chunk_[static_cast<size_t>(r) + 1]; ++c)
      for (int s = chunk_first_segment_[static_cast<size_t>(c)]; s < chunk_first_segment_[static_cast<size_t>(c) + 1]; ++s) {
        const auto k = static_cast<size_t>(s);
        const Vec3 xa = nodes.col(first_node[k]), v = nodes.col(first_node[k] + 1) - xa;
        ax_[k] = xa.x(), ay_[k] = xa.y(), az_[k] = xa.z(), vx_[k] = v.x(), vy_[k] = v.y(), vz_[k] = v.z();
        inv_v2_[k] = 1.0 / v.squaredNorm();
        e2_[k] = eps(s) * eps(s);
        reach2_[k] = delta * delta * v.squaredNorm();
        for (const std::size_t b : {static_cast<size_t>(r), static_cast<size_t>(num_rods + c)}) {
          boxes_[b].extend(xa);
          boxes_[b].extend(Vec3(xa + v));
          box_reach_[b] = std::max(box_reach_[b], std::sqrt(reach2_[k]));
        }
      }
}

void NearSegmentSearch::ChunksNear(const Eigen::AlignedBox3d& box, std::vector<int>* chunks) const {
  chunks->clear();
  const int num_rods = static_cast<int>(rod_first_chunk_.size()) - 1;
  for (int r = 0; r < num_rods; ++r) {
    if (boxes_[static_cast<size_t>(r)].exteriorDistance(box) >= box_reach_[static_cast<size_t>(r)])
      continue;
    for (int c = rod_first_chunk_[static_cast<size_t>(r)]; c < rod_first_chunk_[static_cast<size_t>(r) + 1]; ++c) {
      const auto b = static_cast<size_t>(num_rods + c);
      if (boxes_[b].exteriorDistance(box) < box_reach_[b]) chunks->push_back(c);
    }
  }
}

void NearSegmentSearch::SegmentsNear(const Vec3& p, const std::vector<int>& chunks,
                                     std::vector<unsigned char>* flags,
                                     std::vector<int>* near) const {
  near->clear();
  const int num_rods = static_cast<int>(rod_first_chunk_.size()) - 1;
  for (const int c : chunks) {
    const auto b = static_cast<size_t>(num_rods + c);
    if (boxes_[b].exteriorDistance(p) >= box_reach_[b]) continue;
    const int first = chunk_first_segment_[static_cast<size_t>(c)];
    const int count = chunk_first_segment_[static_cast<size_t>(c) + 1] - first;
    flags->resize(static_cast<size_t>(count));
    MarkNearSegments(p, first, count, ax_.data(), ay_.data(), az_.data(), vx_.data(), vy_.data(),
                     vz_.data(), inv_v2_.data(), e2_.data(), reach2_.data(), flags->data());
    KeepFlagged([first](int k) { return first + k; }, count, flags->data(), near);
  }
}

void NearSegmentSearch::SegmentsNearAmong(const Vec3& p, const std::vector<int>& candidates,
                                          std::vector<unsigned char>* flags,
                                          std::vector<int>* near) const {
  near->clear();
  const int count = static_cast<int>(candidates.size());
  flags->resize(candidates.size());
  MarkNearAmong(p, candidates.data(), count, ax_.data(), ay_.data(), az_.data(), vx_.data(),
                vy_.data(), vz_.data(), inv_v2_.data(), e2_.data(), reach2_.data(), flags->data());
  KeepFlagged([&candidates](int k) { return candidates[static_cast<size_t>(k)]; }, count,
              flags->data(), near);
}

bool NearSegmentList::Holds(const Matrix3X& nodes, const std::vector<int>& first_node,
                            const VecX& eps, const std::vector<int>& rod_first_segment,
                            double delta) const {
  if (candidates_.empty() || searched_at_.cols() != nodes.cols() || delta != delta_ ||
      first_node != first_node_ || rod_first_segment != rod_first_segment_ || eps != eps_)
    return false;
  // 2Δ ≤ δ ((1 + kSkin) |v₀| − |v|) for every segment (header); written so that a NaN
  // coordinate fails it and searches anew.
  const double move =
      std::sqrt((nodes - searched_at_).colwise().squaredNorm().maxCoeff<Eigen::PropagateNaN>());
  double room = std::numeric_limits<double>::infinity();
  for (std::size_t s = 0; s < first_node.size(); ++s) {
    const int a = first_node[s];
    room = std::min(room, (1.0 + kSkin) * searched_length_[s] -
                              (nodes.col(a + 1) - nodes.col(a)).norm());
  }
  return 2.0 * move <= delta * room;
}

void NearSegmentList::Find(const Matrix3X& nodes, const std::vector<int>& first_node,
                           const VecX& eps, const std::vector<int>& rod_first_segment,
                           double delta, std::vector<std::vector<int>>* near) {
  near->resize(static_cast<size_t>(nodes.cols()));
  if (Holds(nodes, first_node, eps, rod_first_segment, delta)) {
    ++kept_;
    return Filter(nodes, first_node, eps, rod_first_segment, delta, near);
  }
  ++searches_;
  // A list that served one Find only: the next searches go without the skin (header).
  if (!candidates_.empty() && calls_ <= 1) plain_searches_left_ = kPlainSearches;
  const bool skin = plain_searches_left_ == 0;
  if (!skin) --plain_searches_left_;
  candidates_.clear();
  search_.Build(nodes, first_node, eps, rod_first_segment, skin ? (1.0 + kSkin) * delta : delta);
  std::vector<std::vector<int>>& found = skin ? candidates_ : *near;
  found.resize(static_cast<size_t>(nodes.cols()));
  search_.ForEachTarget<NoScratch>(nodes, [&](int t, const std::vector<int>& list, NoScratch*) {
    found[static_cast<size_t>(t)] = list;
  });
  if (!skin) return;
  searched_at_ = nodes;
  first_node_ = first_node;
  rod_first_segment_ = rod_first_segment;
  eps_ = eps;
  delta_ = delta;
  searched_length_.resize(first_node.size());
  for (std::size_t s = 0; s < first_node.size(); ++s)
    searched_length_[s] = (nodes.col(first_node[s] + 1) - nodes.col(first_node[s])).norm();
  calls_ = 0;
  Filter(nodes, first_node, eps, rod_first_segment, delta, near);
}

void NearSegmentList::Filter(const Matrix3X& nodes, const std::vector<int>& first_node,
                             const VecX& eps, const std::vector<int>& rod_first_segment,
                             double delta, std::vector<std::vector<int>>* near) {
  ++calls_;
  search_.Build(nodes, first_node, eps, rod_first_segment, delta);
  const int m = static_cast<int>(nodes.cols());
#pragma omp parallel
  {
    std::vector<unsigned char> flags;
#pragma omp for schedule(dynamic, NearSegmentSearch::kTargetBlock)
    for (int t = 0; t < m; ++t)
      search_.SegmentsNearAmong(nodes.col(t), candidates_[static_cast<size_t>(t)], &flags,
                                &(*near)[static_cast<size_t>(t)]);
  }
}

}  // namespace stokesrods
