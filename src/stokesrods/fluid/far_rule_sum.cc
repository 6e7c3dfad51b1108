#include "stokesrods/fluid/far_rule_sum.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "stokesrods/common/assert.h"
#include "stokesrods/common/parallel.h"
#include "stokesrods/fluid/mobility_operator.h"
#include "stokesrods/fluid/stokeslet_segment.h"

namespace stokesrods {
namespace {

// Appends the n-point rule's points of the sorted segments as ranges, consecutive segments as one.
void AppendRuns(const std::vector<int>& segments, int first_source, int points,
                std::vector<SourceRange>* out) {
  for (std::size_t i = 0; i < segments.size();) {
    std::size_t end = i + 1;
    while (end < segments.size() && segments[end] == segments[end - 1] + 1) ++end;
    SR_ASSERT(end == segments.size() || segments[end] > segments[end - 1],
              "far rule sum: the left-out segments of a node are not ascending");
    out->push_back({first_source + segments[i] * points, first_source + (segments[end - 1] + 1) * points});
    i = end;
  }
}

// Sorts the ranges and joins those that overlap or touch.
void MergeRanges(std::vector<SourceRange>* ranges) {
  std::sort(ranges->begin(), ranges->end(),
            [](const SourceRange& a, const SourceRange& b) { return a.begin < b.begin; });
  std::size_t kept = 0;
  for (const SourceRange& r : *ranges) {
    if (kept > 0 && r.begin <= (*ranges)[kept - 1].end)
      (*ranges)[kept - 1].end = std::max((*ranges)[kept - 1].end, r.end);
    else
      (*ranges)[kept++] = r;
  }
  ranges->resize(kept);
}

// Appends the ranges (in their order) without the sorted, disjoint holes to out; returns how many
// points they hold.
std::int64_t CutOut(const std::vector<SourceRange>& ranges, const std::vector<SourceRange>& holes,
                    std::vector<SourceRange>* out) {
  std::int64_t points = 0;
  const auto add = [&](int begin, int end) {
    out->push_back({begin, end});
    points += end - begin;
  };
  for (const SourceRange& r : ranges) {
    int begin = r.begin;
    auto h = std::lower_bound(holes.begin(), holes.end(), r.begin,
                              [](const SourceRange& hole, int at) { return hole.end <= at; });
    for (; h != holes.end() && h->begin < r.end; ++h) {
      if (h->begin > begin) add(begin, h->begin);
      begin = std::max(begin, h->end);
    }
    if (begin < r.end) add(begin, r.end);
  }
  return points;
}

std::int64_t RangeLength(const std::vector<SourceRange>& ranges) {
  std::int64_t n = 0;
  for (const SourceRange& r : ranges) n += r.end - r.begin;
  return n;
}

}  // namespace

void FarRuleSum::Build(const Matrix3X& nodes, const std::vector<int>& first_node, const VecX& eps,
                       const std::vector<int>& rod_first_segment, int points, double accuracy,
                       bool single, const std::vector<std::vector<int>>* excluded) {
  SR_ASSERT(points >= 2, "the far rule needs at least 2 points");
  const int segments = static_cast<int>(first_node.size());
  const int rods = static_cast<int>(rod_first_segment.size()) - 1;
  single_ = single;
  first_node_ = first_node;
  targets_ = nodes;

  // The rules k = 2 … n, their points on every segment one after the other.
  rules_.clear();
  int sources = 0;
  for (int k = 2; k <= points; ++k) {
    Rule rule{.points = k, .first_source = sources};
    GaussLegendreRule01(k, &rule.alpha, &rule.weight);
    rules_.push_back(rule);
    sources += k * segments;
  }
  src_.resize(sources, 7);
  length_.resize(segments);
  for (int s = 0; s < segments; ++s)
    length_(s) = (nodes.col(first_node[static_cast<size_t>(s)] + 1) - nodes.col(first_node[static_cast<size_t>(s)])).norm();
  for (const Rule& rule : rules_)
    for (int s = 0; s < segments; ++s) {
      const Vec3 xa = nodes.col(first_node[static_cast<size_t>(s)]);
      const Vec3 v = nodes.col(first_node[static_cast<size_t>(s)] + 1) - xa;
      for (int q = 0; q < rule.points; ++q) {
        const int row = rule.first_source + s * rule.points + q;
        src_.row(row).head<3>() = (xa + rule.alpha[q] * v).transpose();
        src_(row, 3) = eps(s) * eps(s);
      }
    }
  const Vec3 origin = nodes.cols() > 0 ? Vec3(nodes.rowwise().mean()) : Vec3::Zero();
  if (single_) {
    src_f_ = src_.cast<float>();
    src_f_.leftCols<3>() = (src_.leftCols<3>().rowwise() - origin.transpose()).cast<float>();
    targets_f_ = (nodes.colwise() - origin).cast<float>();
  }

  // Per chunk of kChunkSegments consecutive segments of a rod: its box and its longest segment
  // (a rod's segments differ: a clamp's lead is longer than the helix's).
  std::vector<int> chunk_first;  // first segment of each chunk
  for (int r = 0; r < rods; ++r)
    for (int s = rod_first_segment[static_cast<size_t>(r)]; s < rod_first_segment[static_cast<size_t>(r) + 1];
         s += kChunkSegments)
      chunk_first.push_back(s);
  const int chunks = static_cast<int>(chunk_first.size());
  std::vector<int> chunk_end(static_cast<size_t>(chunks));
  std::vector<Eigen::AlignedBox3d> chunk_box(static_cast<size_t>(chunks));
  std::vector<double> longest2(static_cast<size_t>(chunks), 0.0);
  for (int r = 0, c = 0; r < rods; ++r)
    for (; c < chunks && chunk_first[static_cast<size_t>(c)] < rod_first_segment[static_cast<size_t>(r) + 1]; ++c) {
      const auto k = static_cast<size_t>(c);
      chunk_end[k] = std::min(chunk_first[k] + kChunkSegments, rod_first_segment[static_cast<size_t>(r) + 1]);
      for (int s = chunk_first[k]; s < chunk_end[k]; ++s) {
        const int a = first_node[static_cast<size_t>(s)];
        chunk_box[k].extend(Vec3(nodes.col(a)));
        chunk_box[k].extend(Vec3(nodes.col(a + 1)));
        longest2[k] = std::max(longest2[k], length_(s) * length_(s));
      }
    }
  std::vector<double> radius2(rules_.size());  // NearRadius(k)², k = 2 … n
  for (std::size_t i = 0; i < rules_.size(); ++i)
    radius2[i] = std::pow(NearRadius(rules_[i].points, accuracy), 2);

  // Per group of targets, per chunk: the fewest points whose reach the group's box clears; then
  // per pass of the group's targets, those ranges without the points the pass leaves out.
  const int m = static_cast<int>(nodes.cols());
  const int groups = (m + kGroupTargets - 1) / kGroupTargets;
  const Rule& n_rule = rules_.back();
  range_start_.assign(1, 0);
  own_start_.assign(1, 0);
  range_.clear();
  own_range_.clear();
  pairs_ = pairs_at_n_ = excluded_pairs_ = 0;
  std::vector<SourceRange> group_ranges, holes, own_holes;
  const std::vector<int> none;
  const auto left_out = [&](int t) -> const std::vector<int>& {
    return excluded ? (*excluded)[static_cast<size_t>(t)] : none;
  };
  SR_ASSERT(!excluded || excluded->size() == static_cast<size_t>(m),
            "far rule sum: one list of left-out segments per node");
  for (int g = 0; g < groups; ++g) {
    const int first = g * kGroupTargets, count = std::min(kGroupTargets, m - first);
    Eigen::AlignedBox3d box;
    for (int t = first; t < first + count; ++t) box.extend(Vec3(nodes.col(t)));
    group_ranges.clear();
    for (int c = 0; c < chunks; ++c) {
      const auto k = static_cast<size_t>(c);
      const double d2 = chunk_box[k].squaredExteriorDistance(box);
      std::size_t i = 0;  // the fewest points that serve; n when none of fewer does
      while (i + 1 < rules_.size() && d2 < radius2[i] * longest2[k]) ++i;
      const Rule& rule = rules_[i];
      const SourceRange range{rule.first_source + chunk_first[k] * rule.points,
                              rule.first_source + chunk_end[k] * rule.points};
      // Consecutive chunks on the same rule are one range.
      if (!group_ranges.empty() && group_ranges.back().end == range.begin)
        group_ranges.back().end = range.end;
      else
        group_ranges.push_back(range);
      pairs_at_n_ += static_cast<std::int64_t>(count) * (chunk_end[k] - chunk_first[k]) * points;
    }
    const std::int64_t group_points = RangeLength(group_ranges);
    for (int t0 = first; t0 < first + count; t0 += kPointSumTargets) {
      const int pass = std::min(kPointSumTargets, first + count - t0);
      // The union of the pass's left-out points (each segment's n points are consecutive).
      holes.clear();
      for (int t = t0; t < t0 + pass; ++t) AppendRuns(left_out(t), n_rule.first_source, points, &holes);
      MergeRanges(&holes);
      const std::int64_t shared = CutOut(group_ranges, holes, &range_);
      SR_ASSERT(group_points - shared == RangeLength(holes),
                "far rule sum: a left-out segment is not on the n-point rule");
      range_start_.push_back(static_cast<int>(range_.size()));
      pairs_ += pass * shared;
      for (int t = t0; t < t0 + pass; ++t) {
        own_holes.clear();
        AppendRuns(left_out(t), n_rule.first_source, points, &own_holes);
        pairs_ += CutOut(holes, own_holes, &own_range_);
        own_start_.push_back(static_cast<int>(own_range_.size()));
        excluded_pairs_ += RangeLength(own_holes);
      }
    }
  }
}

void FarRuleSum::FillStrengths(const Matrix3X& density) const {
  const int segments = static_cast<int>(first_node_.size());
  ForEachStatic(segments, segments > 1, [&](int s) {
    const Vec3 fa = density.col(first_node_[static_cast<size_t>(s)]);
    const Vec3 fb = density.col(first_node_[static_cast<size_t>(s)] + 1);
    for (const Rule& rule : rules_)
      for (int q = 0; q < rule.points; ++q) {
        const Vec3 g = (rule.weight[q] * length_(s)) * ((1.0 - rule.alpha[q]) * fa + rule.alpha[q] * fb);
        const int row = rule.first_source + s * rule.points + q;
        if (single_)
          src_f_.row(row).tail<3>() = g.transpose().cast<float>();
        else
          src_.row(row).tail<3>() = g.transpose();
      }
  });
}

void FarRuleSum::Apply(const Matrix3X& density, Matrix3X* w) const {
  SR_ASSERT(density.cols() == targets_.cols(), "far rule sum: one density per node");
  FillStrengths(density);
  const int m = static_cast<int>(targets_.cols());
  w->setZero(3, m);
  const SourceColumns columns = Columns(src_);
  const SourceColumnsF columns_f = single_ ? ColumnsF(src_f_) : SourceColumnsF{};
  const int groups = (m + kGroupTargets - 1) / kGroupTargets;
  static_assert(kGroupTargets % kPointSumTargets == 0, "whole passes per group");
  constexpr int kPasses = kGroupTargets / kPointSumTargets;
  ForEachStatic(groups, groups > 1, [&](int g) {
    const int end = std::min(m, (g + 1) * kGroupTargets);
    for (int t0 = g * kGroupTargets, p = g * kPasses; t0 < end; t0 += kPointSumTargets, ++p) {
      const int n = std::min(kPointSumTargets, end - t0);
      double* out[kPointSumTargets];
      const double* x[kPointSumTargets];
      const float* xf[kPointSumTargets];
      for (int k = 0; k < n; ++k) {
        out[k] = w->col(t0 + k).data();
        x[k] = targets_.col(t0 + k).data();
        if (single_) xf[k] = targets_f_.col(t0 + k).data();
      }
      // The ranges the pass shares, then each target's share of the pass's left-out points.
      const auto sum = [&](const SourceRange* ranges, int count, int targets, int k) {
        if (count == 0) return;
        if (single_)
          AddPointSumRangesTargets(columns_f, ranges, count, targets, xf + k, out + k, true);
        else
          AddPointSumRangesTargets(columns, ranges, count, targets, x + k, out + k);
      };
      const auto pu = static_cast<size_t>(p);
      sum(range_.data() + range_start_[pu], range_start_[pu + 1] - range_start_[pu], n, 0);
      for (int k = 0; k < n; ++k) {
        const auto t = static_cast<size_t>(t0 + k);
        sum(own_range_.data() + own_start_[t], own_start_[t + 1] - own_start_[t], 1, k);
      }
    }
  });
}

}  // namespace stokesrods
