#include "stokesrods/fluid/mobility_operator.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>

#include <Eigen/Geometry>

#include "stokesrods/common/assert.h"
#include "stokesrods/common/parallel.h"
#include "stokesrods/fluid/far_rule_sum.h"
#include "stokesrods/fluid/near_search.h"
#include "stokesrods/fluid/rss.h"
#include "stokesrods/fluid/rss_rows.h"
#include "stokesrods/fluid/stokeslet_segment.h"
#include "stokesrods/solver/blas.h"

namespace stokesrods {

void MobilityOperator::SetLayout(const std::vector<HydroRod>& rods) {
  num_body_points_ = num_free_bodies_ = 0;
  node_offset_.assign(1, 0);
  for (const HydroRod& rod : rods)
    node_offset_.push_back(node_offset_.back() + static_cast<int>(rod.x->cols()));
}

namespace {

class DenseMobility final : public MobilityOperator {
 public:
  DenseMobility(const FluidParams& params, const MobilityOptions& options)
      : params_(params),
        reuse_(options.reuse_tolerance, options.reuse_tolerance >= kSinglePrecisionTolerance),
        single_products_(options.reuse_tolerance >= kSinglePrecisionTolerance) {}

  void Update(const std::vector<HydroRod>& rods) override {
    SetLayout(rods);
    VecX x(3 * node_offset(num_rods()));
    for (int r = 0; r < num_rods(); ++r)
      x.segment(3 * node_offset(r), 3 * rods[static_cast<size_t>(r)].x->cols()) =
          rods[static_cast<size_t>(r)].x->reshaped();
    // 𝕄 with the rods' nodes at `at`: their own positions, or a restored history's.
    const auto assemble = [&](const VecX& at, MatX* m) {
      std::vector<Matrix3X> moved(rods.size());
      std::vector<HydroRod> moved_rods = rods;
      for (int r = 0; r < num_rods(); ++r) {
        const auto k = static_cast<size_t>(r);
        moved[k] = Eigen::Map<const Matrix3X>(at.data() + 3 * node_offset(r), 3, rods[k].x->cols());
        moved_rods[k].x = &moved[k];
      }
      AssembleMobility(params_, moved_rods, m);
    };
    single_current_ = !reuse_.Update(x, assemble, &matrix_, &single_);
    double_stale_ = single_current_;
    // At a reuse tolerance of single precision's order or above, the products take an assembled
    // 𝕄 rounded to single precision too (the history holds it already): 6e-8 relative to its
    // entries, far inside what the extrapolated steps are allowed, at half the bytes per product.
    products_ = single_current_ ? &single_
                : single_products_ ? &reuse_.last_assembly_single()
                                   : nullptr;
  }
  void UpdateWithBodies(const std::vector<HydroRod>& rods,
                        const std::vector<BodySurface>& bodies) override {
    if (bodies.empty()) return Update(rods);  // every fluid model
    reuse_.Forget();  // bodies: assembled at every Update
    single_current_ = double_stale_ = false;
    products_ = nullptr;
    SetLayout(rods);
    for (const BodySurface& b : bodies) {
      num_body_points_ += static_cast<int>(b.points.cols());
      num_free_bodies_ += b.free ? 1 : 0;
    }
    matrix_ = AssembleBorderedMobility(params_, rods, bodies);
  }
  void ForgetHistory() override { reuse_.Forget(); }
  void AtRestartPoint() override {}  // the reuse's history goes into the checkpoint
  MobilityReuseHistory reuse_history() const override { return reuse_.history(); }
  void RestoreReuse(const MobilityReuseHistory& history) override { reuse_.Restore(history); }
  MobilityReuseStats reuse_stats() const override { return reuse_.stats(); }
  void Apply(const VecX& force, VecX* velocity) const override {
    // Row blocks in parallel: the product streams the whole matrix (memory bound beyond cache).
    // In single precision by blocks of 64 rows dealt out in turn (each row's sum is the same
    // whatever the blocks: GemvRowsMixed), from kDenseInParallelFromRows rows on
    // (common/parallel.h); in double by LAPACK's dgemv on fixed blocks of 192.
    const Eigen::Index n = products_ ? products_->rows() : matrix_.rows();
    velocity->resize(n);
    if (products_) {
      constexpr Eigen::Index kRows = 64;
      const auto rows = [&](Eigen::Index first) {
        GemvRowsMixed(*products_, first, std::min(kRows, n - first), force.data(),
                      velocity->data() + first);
      };
      if (!Parallel(n >= kDenseInParallelFromRows)) {
        for (Eigen::Index first = 0; first < n; first += kRows) rows(first);
        return;
      }
#pragma omp parallel for schedule(static, 1)
      for (Eigen::Index first = 0; first < n; first += kRows) rows(first);
      return;
    }
    constexpr Eigen::Index kRows = 192;
    const auto blocks = static_cast<int>((n + kRows - 1) / kRows);
    ForEachStatic(blocks, blocks > 2, [&](int b) {
      const Eigen::Index first = b * kRows;
      GemvRows(matrix_, first, std::min(kRows, n - first), force.data(), velocity->data() + first);
    });
  }
  MatX SelfBlock(int rod) const override {
    const int first = 3 * node_offset(rod), n = 3 * (node_offset(rod + 1) - node_offset(rod));
    if (single_current_) return single_.block(first, first, n, n).cast<double>();
    return matrix_.block(first, first, n, n);
  }
  // An extrapolated 𝕄 (single precision) is converted on demand: the capacitance's rebuilds and
  // the explicit coupling's LU, not the products, read it in double.
  const MatX* matrix() const override {
    if (double_stale_) matrix_ = single_.cast<double>(), double_stale_ = false;
    return &matrix_;
  }
  const Eigen::MatrixXf* single_matrix() const override { return products_; }

 private:
  FluidParams params_;
  MobilityReuse reuse_;
  mutable MatX matrix_;          // assembled (or converted from single_ on demand)
  Eigen::MatrixXf single_;       // extrapolated by the reuse (fluid/mobility_reuse.h)
  bool single_current_ = false;  // the last Update extrapolated: single_ is 𝕄
  mutable bool double_stale_ = false;  // matrix_ is not single_ yet
  bool single_products_ = false;  // reuse tolerance ≥ kSinglePrecisionTolerance
  const Eigen::MatrixXf* products_ = nullptr;  // 𝕄 the products take in single precision, if so
};

// A symmetric block's six entries in single precision (NearBlocks::SymmetricBlock).
NearBlocks::SymmetricBlock PackSymmetric(const Mat3& b) {
  return {static_cast<float>(b(0, 0)), static_cast<float>(b(1, 0)), static_cast<float>(b(2, 0)),
          static_cast<float>(b(1, 1)), static_cast<float>(b(2, 1)), static_cast<float>(b(2, 2))};
}

// out (compressed rows) from the blocks per target, packed in parallel (in single precision if
// `single`, each symmetric block's six entries).
void PackNearBlocks(const std::vector<std::vector<std::pair<int, Mat3>>>& per_target, bool single,
                    NearBlocks* out) {
  const int m = static_cast<int>(per_target.size());
  out->start.resize(static_cast<size_t>(m) + 1);
  out->start[0] = 0;
  for (int t = 0; t < m; ++t)
    out->start[static_cast<size_t>(t) + 1] =
        out->start[static_cast<size_t>(t)] + static_cast<int>(per_target[static_cast<size_t>(t)].size());
  const auto count = static_cast<size_t>(out->start.back());
  out->source.resize(count);
  out->single = single;
  out->block.resize(single ? 0 : count);
  out->block_single.resize(single ? count : 0);
  bool symmetric = true;
#pragma omp parallel for schedule(static) reduction(&& : symmetric)
  for (int t = 0; t < m; ++t) {
    auto k = static_cast<size_t>(out->start[static_cast<size_t>(t)]);
    for (const auto& [node, block] : per_target[static_cast<size_t>(t)]) {
      out->source[k] = node;
      if (single) {
        symmetric = symmetric && block(0, 1) == block(1, 0) && block(0, 2) == block(2, 0) &&
                    block(1, 2) == block(2, 1);
        out->block_single[k++] = PackSymmetric(block);
      } else {
        out->block[k++] = block;
      }
    }
  }
  SR_ASSERT(symmetric, "a near block in single precision is not symmetric");
}

// Matrix-free RSS (see the header). With f_j = F_j/Λ_j the force densities at the nodes,
//   8πμ U_t = Σ_segments (A_a f_a + A_b f_b)
//           = Σ_far Σ_q w_q L S_ε(x_t − y_q) [(1 − α_q) f_a + α_q f_b]    (point Stokeslets)
//           + Σ_near (A_a − A_a^Gauss) f_a + (A_b − A_b^Gauss) f_b,       (exact minus the rule)
// where the first sum runs over all segments (the fast sum) and the second corrects the near
// pairs to the closed forms. The corrections are stored per target as 3×3 blocks acting on F.
// Where the far rule sum serves (exclude_near_), its first sum leaves the near pairs out and the
// corrections are the closed forms A_a, A_b alone (fluid/far_rule_sum.h).
class MatrixFreeRssMobility final : public MobilityOperator {
 public:
  // One accuracy at every size: the far field is as accurate as the fast sum's tolerance, so the
  // quadrature (and the near pairs' closed forms) need not be better either, and the near zone
  // (exact closed forms, once per step) can shrink. The fast sum adds up directly (in single
  // precision from 1e-4) below direct_sum_below pairs or where its cost model says the tree
  // would not pay.
  MatrixFreeRssMobility(const FluidParams& params, const MobilityOptions& options)
      : params_(params),
        accuracy_(std::max(options.tolerance, options.fast_sum_tolerance)),
        split_(ChooseNearFarSplit(accuracy_, options.fast_sum_near_delta)),
        fewest_points_(split_),
        split_by_cost_(options.split_by_cost),
        far_(MakeFastStokesletSum(
            {.tolerance = options.fast_sum_tolerance,
             .direct_below_pairs = static_cast<std::int64_t>(options.direct_sum_below),
             .choose_by_cost = options.fast_sum_by_cost})),
        far_rule_by_distance_(options.far_rule_by_distance),
        exclude_near_from_far_(options.exclude_near_from_far_sum),
        single_far_(options.fast_sum_tolerance >= kSinglePrecisionTolerance),
        reuse_near_(single_far_ && options.reuse_tolerance > 0.0),
        near_reuse_(reuse_near_ ? options.reuse_tolerance : 0.0,
                    options.reuse_tolerance >= kSinglePrecisionTolerance),
        near_reuse_tolerance_(reuse_near_ ? options.reuse_tolerance : 0.0) {
    // The blocks' six entries stand for the nine of a 3 × 3 block in the reuse's error measure.
    near_reuse_.set_row_weights({1.0, 2.0, 2.0, 1.0, 2.0, 1.0});
    SR_ASSERT(!params.wall, "the matrix-free RSS is the free-space operator: a wall's images wrap "
                            "it (MakeMobilityWithWallImages, fluid/wall_sources.h)");
  }

  void Update(const std::vector<HydroRod>& rods) override;
  void ForgetHistory() override {
    choose_split_ = true;
    ForgetNearHistory();
  }
  MobilityReuseStats reuse_stats() const override { return near_reuse_.stats(); }
  void Apply(const VecX& force, VecX* velocity) const override;
  MatX SelfBlock(int rod) const override {
    MatX block;
    AssembleRssMobility(params_, {rods_[static_cast<size_t>(rod)]}, &block);
    return block;
  }
  void FindNearBlocks(const Matrix3X& targets, NearBlocks* blocks) const override;
  MobilityCostCounts cost_counts() const override {
    const double far_cost = use_rule_sum_ ? static_cast<double>(rule_sum_.pairs()) : far_->Stats().cost;
    return {static_cast<std::int64_t>(near_.size()), far_cost, split_.gauss_points};
  }

 private:
  struct Segment {
    int a = 0;  // global node index of x_a (x_b is a + 1)
    double eps = 0.0;
    int rod = 0;
  };

  // The far rule's points, the far sum and the near blocks at the nodes, for split_; `reuse`:
  // the near blocks through near_reuse_ (else computed, for ChooseSplitByCost's trials).
  void BuildSplit(bool reuse = true);
  // near_ at the nodes: computed, or extrapolated by near_reuse_ while the pattern holds.
  void UpdateNearBlocks();
  // Which nodes each node's near blocks take (NearBlocks' start and source, no values), and its
  // near segments into pattern_segments_ (by near_list_: kept across Updates).
  void FindNearPattern(NearBlocks* pattern) const;
  // The near blocks of the targets `which` (nodes) with the near segments `segments` (per
  // node), all at the node positions `at` (3 × M): the blocks near_reuse_'s history holds for
  // a geometry of its own (REMAP in fluid/mobility_reuse.h), or at the nodes.
  // The far rule is subtracted where the far sum adds it (!exclude_near_); where it does not,
  // `difference_norm2` (if given) gets per target Σ ‖A − A^Gauss‖_F² of its blocks.
  void NearBlocksAt(const Matrix3X& at, const std::vector<int>& which,
                    const std::vector<std::vector<int>>& segments,
                    std::vector<std::vector<std::pair<int, Mat3>>>* blocks,
                    std::vector<double>* difference_norm2 = nullptr) const;
  // The near pattern changed to `pattern` (segments in pattern_segments_): near_reuse_ keeps
  // the blocks of the targets whose near segments are those of near_segments_, and assembles
  // the others' at its held geometries.
  void RemapNearHistory(const NearBlocks& pattern);
  void ForgetNearHistory() {
    near_reuse_.Forget();
    near_segments_.clear();
  }
  // The near segments of each target, to `visit(t, near segments, scratch)` (in parallel).
  template <typename Visit>
  void ForEachTargetsNearSegments(const Matrix3X& targets, const Visit& visit) const;
  // Keeps the cheaper of split_ and the rule with one more point (ChooseNearFarSplit).
  void ChooseSplitByCost();
  // The near blocks at p (node, block) of its near segments (NearSegmentSearch::SegmentsNear).
  struct NearRowScratch {
    std::vector<double> table, difference;
    std::vector<char> is_near;
  };
  // Rod r's rows of exact closed forms and of the far rule, at its nodes x (kept by reference).
  RssRowKernel RowKernel(int r, const Matrix3X& x) const {
    return RssRowKernel(x, params_.regularization * rods_[static_cast<size_t>(r)].radius,
                        accuracy_, split_.gauss_points);
  }
  // The near blocks at `targets` (each with its near segments into `segments`, if given).
  void NearBlocksOf(const Matrix3X& targets, bool subtract_rule, NearBlocks* blocks,
                    std::vector<std::vector<int>>* segments) const;
  // The far sum by FarRuleSum, its near pairs left out where exclude_near_ (the near segments of
  // the last near blocks at the nodes).
  void BuildRuleSum();
  // (kernels and inverse_voronoi (1/Λ_j) of one geometry, the one p is taken from): the closed
  // forms A, minus the far rule where `subtract_rule`; else, if `difference_norm2` is given,
  // Σ ‖A − A^Gauss‖_F² of the blocks into it (the same rows: the closed forms once).
  void NearPairBlocks(const Vec3& p, const std::vector<int>& near,
                      const std::vector<RssRowKernel>& kernels, const VecX& inverse_voronoi,
                      bool subtract_rule, NearRowScratch* scratch,
                      std::vector<std::pair<int, Mat3>>* blocks,
                      double* difference_norm2 = nullptr) const;
  // Per segment its first node and ε; per rod its first segment (and the total last).
  void SegmentLists(std::vector<int>* first_node, VecX* eps,
                    std::vector<int>* rod_first_segment) const;

  FluidParams params_;
  double accuracy_;                 // of the far field, its quadrature and the near pairs
  NearFarSplit split_;
  NearFarSplit fewest_points_;      // ChooseNearFarSplit's: within the options' largest radius
  bool split_by_cost_;
  bool choose_split_ = true;        // at the next Update (the first, then after ForgetHistory)
  std::unique_ptr<StokesletSum> far_;
  // Where far_ sums directly and the split has more than 2 points: the far field with fewer
  // points on the rods far from each group of targets (fluid/far_rule_sum.h), used instead.
  bool far_rule_by_distance_;
  bool exclude_near_from_far_;      // MobilityOptions::exclude_near_from_far_sum
  bool single_far_;                 // the far sum in single precision (kSinglePrecisionTolerance)
  bool use_rule_sum_ = false;
  FarRuleSum rule_sum_;
  // Where the rule sum serves: the nodes' near pairs are left out of it, and their near blocks
  // are the closed forms alone (fluid/far_rule_sum.h: the rule's rounding at the nearest pairs).
  bool exclude_near_ = false;
  // The near segments of each node of the last near blocks computed without the reuse (with it,
  // near_segments_), and which of the two holds the current ones.
  std::vector<std::vector<int>> own_near_segments_;
  bool near_lists_in_reuse_ = false;
  std::vector<HydroRod> rods_;
  Matrix3X nodes_;                  // 3 × M
  VecX inverse_voronoi_;            // 1/Λ_j
  std::vector<Segment> segments_;
  Matrix3X gauss_points_;           // 3 × (segments × points)
  VecX gauss_eps_;
  NearBlocks near_;                 // the near corrections at the nodes
  // Their values (6 × blocks: NearBlocks::SymmetricBlock) reused across Updates while the
  // pattern holds (fluid/mobility_reuse.h, at the dense 𝕄's reuse tolerance, where the far sum
  // is in single precision); forgotten at restart points and when the split changes, so a resumed run
  // extrapolates as the uninterrupted one.
  bool reuse_near_;
  MobilityReuse near_reuse_;
  double near_reuse_tolerance_;     // its tolerance for blocks A − A^Gauss (see UpdateNearBlocks)
  // The near segments of each target of near_ while near_reuse_ holds a history (else empty).
  std::vector<std::vector<int>> near_segments_;
  // FindNearBlocks' blocks per target before they are packed (kept: their capacity is reused).
  mutable std::vector<std::vector<std::pair<int, Mat3>>> per_target_;
  mutable std::vector<std::vector<int>> pattern_nodes_;  // FindNearPattern's, likewise
  mutable std::vector<std::vector<int>> pattern_segments_;
  mutable NearSegmentList near_list_;  // the near segments of the nodes, kept across Updates
  mutable Matrix3X strengths_, far_velocity_, density_;
};

void MatrixFreeRssMobility::Update(const std::vector<HydroRod>& rods) {
  SetLayout(rods);
  rods_ = rods;
  const int m = node_offset(num_rods());
  nodes_.resize(3, m);
  inverse_voronoi_.resize(m);
  segments_.clear();
  for (int r = 0; r < num_rods(); ++r) {
    const Matrix3X& x = *rods[static_cast<size_t>(r)].x;
    const int first = node_offset(r);
    nodes_.middleCols(first, x.cols()) = x;
    inverse_voronoi_.segment(first, x.cols()) = VoronoiLengths(x).cwiseInverse();
    const double eps = params_.regularization * rods[static_cast<size_t>(r)].radius;
    for (int j = 0; j + 1 < x.cols(); ++j) segments_.push_back({first + j, eps, r});
  }
  if (choose_split_ && split_by_cost_) return ChooseSplitByCost();
  BuildSplit();
}

// The cost of one time step in far-field kernel evaluations (one float pair of the far sum,
// ≈ 0.2 ns), at about kProductsPerUpdate products per Update (a step's GMRES: 5.4–6.5 on the
// bench's flagella cases), from the benchmark BM_MatrixFree{Update,Apply}
// (bench/bench_stokeslet_sum.cc: lattice and ring of 10 helices at 2 and 3 points, one thread):
// a near block costs ≈ 36 ns ≈ 175 evaluations to build (the closed forms minus the rule, once
// per Update) and ≈ 1.8 ns ≈ 9 evaluations per product. Deterministic (no timing), and decided
// on the geometry at the first Update and at every restart point (ForgetHistory), so a run
// resumed from a checkpoint makes the same choice.
void MatrixFreeRssMobility::ChooseSplitByCost() {
  constexpr double kBuildPerBlock = 175.0, kApplyPerBlock = 9.0, kProductsPerUpdate = 6.0;
  choose_split_ = false;
  NearFarSplit best = fewest_points_;
  double best_cost = std::numeric_limits<double>::infinity();
  for (const int extra : {1, 0}) {  // the fewest points last: most often kept, then not rebuilt
    split_ = {fewest_points_.gauss_points + extra,
              NearRadius(fewest_points_.gauss_points + extra, accuracy_)};
    BuildSplit(false);
    const MobilityCostCounts c = cost_counts();
    const auto blocks = static_cast<double>(c.near_blocks);
    const double cost = kBuildPerBlock * blocks +
                        kProductsPerUpdate * (c.far_sum_cost + kApplyPerBlock * blocks);
    if (cost < best_cost) best_cost = cost, best = split_;
  }
  if (best.gauss_points != split_.gauss_points) {
    split_ = best;
    BuildSplit(false);
  }
  ForgetNearHistory();
  if (reuse_near_) {  // the chosen split's blocks start the reuse's history
    UpdateNearBlocks();
    BuildRuleSum();
  }
}

void MatrixFreeRssMobility::BuildSplit(bool reuse) {
  const double* alpha = nullptr;
  const double* weight = nullptr;
  GaussLegendreRule01(split_.gauss_points, &alpha, &weight);
  const int g = split_.gauss_points;
  gauss_points_.resize(3, static_cast<Eigen::Index>(segments_.size()) * g);
  gauss_eps_.resize(gauss_points_.cols());
  for (std::size_t s = 0; s < segments_.size(); ++s) {
    const Vec3 xa = nodes_.col(segments_[s].a), xb = nodes_.col(segments_[s].a + 1);
    for (int q = 0; q < g; ++q) {
      gauss_points_.col(static_cast<Eigen::Index>(s) * g + q) = xa + alpha[q] * (xb - xa);
      gauss_eps_(static_cast<Eigen::Index>(s) * g + q) = segments_[s].eps;
    }
  }
  far_->Build(gauss_points_, gauss_eps_, nodes_);
  use_rule_sum_ = far_rule_by_distance_ && g > 2 && far_->Stats().far_pairs == 0;
  const bool exclude = use_rule_sum_ && exclude_near_from_far_;
  if (exclude != exclude_near_) ForgetNearHistory();  // its blocks were of the other kind
  exclude_near_ = exclude;
  if (reuse) {
    UpdateNearBlocks();
  } else {
    NearBlocksOf(nodes_, !exclude_near_, &near_, &own_near_segments_);
    near_lists_in_reuse_ = false;
  }
  BuildRuleSum();
}

void MatrixFreeRssMobility::BuildRuleSum() {
  if (!use_rule_sum_) return;
  std::vector<int> first_node, rod_first_segment;
  VecX eps;
  SegmentLists(&first_node, &eps, &rod_first_segment);
  const std::vector<std::vector<int>>& near = near_lists_in_reuse_ ? near_segments_ : own_near_segments_;
  rule_sum_.Build(nodes_, first_node, eps, rod_first_segment, split_.gauss_points, accuracy_,
                  single_far_, exclude_near_ ? &near : nullptr);
}

// The near pairs by NearSegmentSearch (fluid/near_search.h: boxes per rod and per run of
// consecutive segments grown by the near reach), their blocks by NearPairBlocks.
void MatrixFreeRssMobility::SegmentLists(std::vector<int>* first_node, VecX* eps,
                                         std::vector<int>* rod_first_segment) const {
  first_node->resize(segments_.size());
  eps->resize(static_cast<Eigen::Index>(segments_.size()));
  for (std::size_t s = 0; s < segments_.size(); ++s)
    (*first_node)[s] = segments_[s].a, (*eps)(static_cast<Eigen::Index>(s)) = segments_[s].eps;
  rod_first_segment->clear();
  for (int r = 0; r <= num_rods(); ++r) rod_first_segment->push_back(node_offset(r) - r);
}

template <typename Visit>
void MatrixFreeRssMobility::ForEachTargetsNearSegments(const Matrix3X& targets,
                                                       const Visit& visit) const {
  std::vector<int> first_node, rod_first_segment;
  VecX eps;
  SegmentLists(&first_node, &eps, &rod_first_segment);
  NearSegmentSearch search;
  search.Build(nodes_, first_node, eps, rod_first_segment, split_.near_delta);
  search.ForEachTarget<NearRowScratch>(targets, visit);
}

void MatrixFreeRssMobility::FindNearBlocks(const Matrix3X& targets, NearBlocks* out) const {
  NearBlocksOf(targets, true, out, nullptr);  // other points: the fast sums add every rule
}

void MatrixFreeRssMobility::NearBlocksOf(const Matrix3X& targets, bool subtract_rule,
                                         NearBlocks* out,
                                         std::vector<std::vector<int>>* segments) const {
  std::vector<RssRowKernel> kernels;
  for (int r = 0; r < num_rods(); ++r)
    kernels.push_back(RowKernel(r, *rods_[static_cast<size_t>(r)].x));
  per_target_.resize(static_cast<size_t>(targets.cols()));
  if (segments) segments->resize(static_cast<size_t>(targets.cols()));
  ForEachTargetsNearSegments(targets, [&](int t, const std::vector<int>& near,
                                          NearRowScratch* scratch) {
    NearPairBlocks(targets.col(t), near, kernels, inverse_voronoi_, subtract_rule, scratch,
                   &per_target_[static_cast<size_t>(t)]);
    if (segments) (*segments)[static_cast<size_t>(t)] = near;
  });
  PackNearBlocks(per_target_, single_far_, out);
}

void MatrixFreeRssMobility::FindNearPattern(NearBlocks* pattern) const {
  const auto m = static_cast<int>(nodes_.cols());
  std::vector<std::vector<int>>& nodes = pattern_nodes_;  // kept: their capacity is reused
  nodes.resize(static_cast<size_t>(m));
  {
    std::vector<int> first_node, rod_first_segment;
    VecX eps;
    SegmentLists(&first_node, &eps, &rod_first_segment);
    near_list_.Find(nodes_, first_node, eps, rod_first_segment, split_.near_delta,
                    &pattern_segments_);
  }
#pragma omp parallel for schedule(static)
  for (int t = 0; t < m; ++t) {
    const std::vector<int>& near = pattern_segments_[static_cast<size_t>(t)];
    // NearPairBlocks' nodes: node k of a rod takes a block when segment k or k − 1 is near.
    std::vector<int>& out = nodes[static_cast<size_t>(t)];
    out.clear();
    for (const int segment : near) {
      const int node = segments_[static_cast<size_t>(segment)].a;
      if (out.empty() || out.back() != node) out.push_back(node);
      out.push_back(node + 1);
    }
  }
  pattern->start.assign(1, 0);
  pattern->source.clear();
  for (const std::vector<int>& list : nodes) {
    pattern->source.insert(pattern->source.end(), list.begin(), list.end());
    pattern->start.push_back(static_cast<int>(pattern->source.size()));
  }
}

void MatrixFreeRssMobility::NearBlocksAt(
    const Matrix3X& at, const std::vector<int>& which,
    const std::vector<std::vector<int>>& segments,
    std::vector<std::vector<std::pair<int, Mat3>>>* blocks,
    std::vector<double>* difference_norm2) const {
  // The rods' nodes, kernels and 1/Λ_j at `at` (the kernels keep their nodes by reference).
  std::vector<Matrix3X> rod_nodes(static_cast<size_t>(num_rods()));
  std::vector<RssRowKernel> kernels;
  VecX inverse_voronoi(at.cols());
  for (int r = 0; r < num_rods(); ++r) {
    const int first = node_offset(r), count = node_offset(r + 1) - first;
    Matrix3X& x = rod_nodes[static_cast<size_t>(r)];
    x = at.middleCols(first, count);
    inverse_voronoi.segment(first, count) = VoronoiLengths(x).cwiseInverse();
    kernels.push_back(RowKernel(r, x));
  }
  blocks->resize(static_cast<size_t>(at.cols()));
  if (difference_norm2) difference_norm2->assign(static_cast<size_t>(at.cols()), 0.0);
  const int n = static_cast<int>(which.size());
#pragma omp parallel
  {
    NearRowScratch scratch;
#pragma omp for schedule(dynamic, 16)
    for (int i = 0; i < n; ++i) {
      const int t = which[static_cast<size_t>(i)];
      NearPairBlocks(at.col(t), segments[static_cast<size_t>(t)], kernels, inverse_voronoi,
                     !exclude_near_, &scratch, &(*blocks)[static_cast<size_t>(t)],
                     difference_norm2 ? &(*difference_norm2)[static_cast<size_t>(t)] : nullptr);
    }
  }
}

void MatrixFreeRssMobility::RemapNearHistory(const NearBlocks& pattern) {
  const int m = static_cast<int>(pattern.start.size()) - 1;
  if (near_segments_.size() != static_cast<size_t>(m)) return ForgetNearHistory();
  std::vector<int> old_column, changed;
  old_column.reserve(pattern.size());
  for (int t = 0; t < m; ++t) {
    const auto tu = static_cast<size_t>(t);
    const int begin = pattern.start[tu], end = pattern.start[tu + 1];
    if (pattern_segments_[tu] == near_segments_[tu]) {  // the same blocks: their history
      SR_ASSERT(near_.start[tu + 1] - near_.start[tu] == end - begin, "near blocks miscounted");
      for (int k = 0; k < end - begin; ++k) old_column.push_back(near_.start[tu] + k);
    } else {
      old_column.insert(old_column.end(), static_cast<size_t>(end - begin), -1);
      if (end > begin) changed.push_back(t);
    }
  }
  std::vector<std::vector<std::pair<int, Mat3>>> blocks;
  const auto assemble = [&](const VecX& at, MatX* columns) {
    NearBlocksAt(at.reshaped(3, m), changed, pattern_segments_, &blocks);
    Eigen::Index count = 0;
    for (const int t : changed)
      count += static_cast<Eigen::Index>(blocks[static_cast<size_t>(t)].size());
    columns->resize(6, count);
    Eigen::Index j = 0;
    for (const int t : changed) {
      const auto& list = blocks[static_cast<size_t>(t)];
      SR_ASSERT(static_cast<int>(list.size()) == pattern.start[static_cast<size_t>(t) + 1] -
                                                     pattern.start[static_cast<size_t>(t)],
                "the near pattern and its blocks disagree");
      for (const auto& [node, block] : list) {  // in single precision, as the assemblies
        const NearBlocks::SymmetricBlock packed = PackSymmetric(block);
        columns->col(j++) =
            Eigen::Map<const Eigen::Matrix<float, 6, 1>>(packed.data()).cast<double>();
      }
    }
  };
  near_reuse_.Remap(old_column, assemble);
}

void MatrixFreeRssMobility::UpdateNearBlocks() {
  near_lists_in_reuse_ = reuse_near_;
  if (!reuse_near_) return NearBlocksOf(nodes_, !exclude_near_, &near_, &own_near_segments_);
  NearBlocks pattern;
  FindNearPattern(&pattern);
  // (the node pattern follows from the segments: comparing those suffices)
  if (pattern_segments_ != near_segments_) RemapNearHistory(pattern);
  near_segments_.swap(pattern_segments_);  // the old lists' capacity serves the next search
  const auto count = static_cast<Eigen::Index>(pattern.size());
  const VecX x = nodes_.reshaped();
  MatX exact;
  Eigen::MatrixXf extrapolated;
  const auto assemble = [&](const VecX& /*at: the current nodes, no history is restored*/,
                            MatX* values) {
    // Of the pattern's near segments (not searched again), in single precision, as the far sum
    // (reuse_near_ only there).
    std::vector<int> all(static_cast<size_t>(nodes_.cols()));
    std::iota(all.begin(), all.end(), 0);
    std::vector<double> difference2;
    NearBlocksAt(nodes_, all, near_segments_, &per_target_, exclude_near_ ? &difference2 : nullptr);
    PackNearBlocks(per_target_, single_far_, &near_);
    SR_ASSERT(near_.source == pattern.source, "the near pattern changed within an Update");
    if (exclude_near_) {
      // The blocks are the closed forms A, no longer A − A^Gauss, whose reuse the tolerance was
      // set for: its bound on the extrapolation's error, relative to the blocks' norm, is
      // scaled by ‖A − A^Gauss‖_F / ‖A‖_F here, so that the error allowed is the same in
      // absolute terms (measured on ten helices over 2 s: without the scaling the clamp forces
      // strayed 14 times farther from the accurate run's than with the rule subtracted).
      double exact2 = 0.0, difference = 0.0;
      for (const auto& list : per_target_)
        for (const auto& [node, block] : list) exact2 += block.squaredNorm();
      for (const double d : difference2) difference += d;
      near_reuse_.set_tolerance(near_reuse_tolerance_ *
                                (exact2 > 0.0 ? std::sqrt(difference / exact2) : 1.0));
    }
    *values = Eigen::Map<const Eigen::MatrixXf>(near_.block_single.front().data(), 6, count)
                  .cast<double>();
  };
  if (count == 0) {  // no near pairs at all: nothing to compute or reuse
    near_ = std::move(pattern);
    near_.single = true;
    return;
  }
  if (near_reuse_.Update(x, assemble, &exact, &extrapolated)) return;  // near_ computed
  near_.start = std::move(pattern.start);
  near_.source = std::move(pattern.source);
  near_.single = true;
  near_.block.clear();
  near_.block_single.resize(static_cast<size_t>(count));
  Eigen::Map<Eigen::MatrixXf>(near_.block_single.front().data(), 6, count) = extrapolated;
}

void MatrixFreeRssMobility::NearPairBlocks(const Vec3& p, const std::vector<int>& near,
                                           const std::vector<RssRowKernel>& kernels,
                                           const VecX& inverse_voronoi, bool subtract_rule,
                                           NearRowScratch* scratch,
                                           std::vector<std::pair<int, Mat3>>* blocks,
                                           double* difference_norm2) const {
  // The exact near pairs (minus the far sum's rule where asked), by rows of RssRowKernel over the
  // range of a rod's segments that are near p (vectorized; columns of segments in the range that
  // are not near are left out), to the far field's accuracy.
  const double scale = 1.0 / (8.0 * kPi * params_.viscosity);
  std::vector<double>& table = scratch->table;
  std::vector<char>& is_near = scratch->is_near;
  blocks->clear();
  for (std::size_t i = 0; i < near.size();) {  // one rod at a time (segments in rod order)
    const int rod = segments_[static_cast<size_t>(near[i])].rod;
    const int rod_first_segment = node_offset(rod) - rod;  // N_k − 1 segments per rod
    std::size_t end = i;
    while (end < near.size() && segments_[static_cast<size_t>(near[end])].rod == rod) ++end;
    const int lo = near[i] - rod_first_segment, hi = near[end - 1] - rod_first_segment;
    const int count = hi - lo + 1;
    table.resize(static_cast<size_t>(12 * count));
    is_near.assign(static_cast<size_t>(count), 0);
    for (std::size_t k = i; k < end; ++k)
      is_near[static_cast<size_t>(near[k] - rod_first_segment - lo)] = 1;
    const RssRowKernel& kernel = kernels[static_cast<size_t>(rod)];
    kernel.Row(p, lo, count, table.data());
    const bool difference = !subtract_rule && difference_norm2;
    if (subtract_rule) kernel.SubtractRule(p, lo, count, table.data());
    if (difference) {
      scratch->difference = table;
      kernel.SubtractRule(p, lo, count, scratch->difference.data());
    }
    // Node k (local) collects A_a of segment k and A_b of segment k − 1, near ones only.
    const auto block_at = [&](const std::vector<double>& rows, int k, bool a_near, bool b_near) {
      double e[6];
      for (int c = 0; c < 6; ++c)
        e[c] = (a_near ? rows[static_cast<size_t>(c * count + k - lo)] : 0.0) +
               (b_near ? rows[static_cast<size_t>((6 + c) * count + k - 1 - lo)] : 0.0);
      const int node = node_offset(rod) + k;
      Mat3 block;
      block << e[0], e[1], e[2], e[1], e[3], e[4], e[2], e[4], e[5];
      return Mat3((scale * inverse_voronoi(node)) * block);
    };
    for (int k = lo; k <= hi + 1; ++k) {
      const bool a_near = k <= hi && is_near[static_cast<size_t>(k - lo)];
      const bool b_near = k > lo && is_near[static_cast<size_t>(k - 1 - lo)];
      if (!a_near && !b_near) continue;
      blocks->emplace_back(node_offset(rod) + k, block_at(table, k, a_near, b_near));
      if (difference)
        *difference_norm2 += block_at(scratch->difference, k, a_near, b_near).squaredNorm();
    }
    i = end;
  }
}

void MatrixFreeRssMobility::Apply(const VecX& force, VecX* velocity) const {
  const auto m = static_cast<int>(nodes_.cols());
  SR_ASSERT(force.size() == 3 * m, "mobility: force vector of the wrong size");
  if (use_rule_sum_) {
    density_ = force.reshaped(3, m).array().rowwise() * inverse_voronoi_.transpose().array();
    rule_sum_.Apply(density_, &far_velocity_);
  } else {
    const int g = split_.gauss_points;
    const double* alpha = nullptr;
    const double* weight = nullptr;
    GaussLegendreRule01(g, &alpha, &weight);
    strengths_.resize(3, gauss_points_.cols());
    const auto num_segments = static_cast<std::ptrdiff_t>(segments_.size());
#pragma omp parallel for schedule(static) if (num_segments > 4096)
    for (std::ptrdiff_t si = 0; si < num_segments; ++si) {
      const auto s = static_cast<std::size_t>(si);
      const int a = segments_[s].a;
      const double length = (nodes_.col(a + 1) - nodes_.col(a)).norm();
      const Vec3 fa = force.segment<3>(3 * a) * inverse_voronoi_(a);
      const Vec3 fb = force.segment<3>(3 * (a + 1)) * inverse_voronoi_(a + 1);
      for (int q = 0; q < g; ++q)
        strengths_.col(static_cast<Eigen::Index>(s) * g + q) =
            (weight[q] * length) * ((1.0 - alpha[q]) * fa + alpha[q] * fb);
    }
    far_->Apply(strengths_, &far_velocity_);
  }
  velocity->resize(3 * m);
  const double scale = 1.0 / (8.0 * kPi * params_.viscosity);
  ForEachStatic(m, m > 1, [&](int t) {
    velocity->segment<3>(3 * t) = scale * far_velocity_.col(t) + near_.At(t, force);
  });
}

}  // namespace

NearFarSplit ChooseNearFarSplit(double tolerance, double max_near_delta) {
  // The n-point Gauss–Legendre rule on one segment–node pair, relative to the pair's |A|, at
  // δ = √(d² + ε²)/L: measured worst over random points and ε ∈ {0.05, 0.3} L (the table in
  // docs/performance.md; tests/fluid/mobility_operator_test.cc checks it), it falls like
  //     e_n(δ) ≈ c_n δ^−(2n−1),   c_n ≈ 9.6e-3 · 13.5^−(n−2)
  // (c_2..c_6 = 9.6e-3, 7.6e-4, 5.6e-5, 3.9e-6, 2.7e-7). With a factor 2 of margin on c_n
  // (GaussRuleError), the near radius for n points is δ_n = (2 c_n / tolerance)^(1/(2n−1)); we take the fewest points
  // whose near radius is at most 12 segment lengths: every point costs every product (S × T
  // kernel evaluations), while a larger near zone costs exact integrals once per step and 3×3
  // blocks per near pair (tolerances 1e-9 … 1e-5 give 3 points; 1e-8: δ_3 = 10.8).
  NearFarSplit split;
  for (int n = 2; n <= 12; ++n) {
    split = {n, NearRadius(n, tolerance)};
    if (split.near_delta <= max_near_delta) break;
  }
  return split;
}

double NearRadius(int gauss_points, double tolerance) {
  // GaussRuleError(n, δ_n) = tolerance, at least one segment length.
  const double tol = std::max(tolerance, 1e-15);
  return std::max(1.0, std::pow(GaussRuleError(gauss_points, 1.0) / tol,
                                1.0 / (2.0 * gauss_points - 1.0)));
}

SelfMobilityPreconditioner::SelfMobilityPreconditioner(const MobilityOperator& mobility) {
  for (int r = 0; r <= mobility.num_rods(); ++r) first_.push_back(3 * mobility.node_offset(r));
  for (int r = 0; r < mobility.num_rods(); ++r) blocks_.emplace_back(mobility.SelfBlock(r));
}

void SelfMobilityPreconditioner::Apply(const VecX& in, VecX* out) const {
  out->resize(in.size());
  for (std::size_t r = 0; r < blocks_.size(); ++r) {
    const int n = first_[r + 1] - first_[r];
    out->segment(first_[r], n) = blocks_[r].solve(in.segment(first_[r], n));
  }
}

std::unique_ptr<MobilityOperator> MakeMobilityOperator(const FluidParams& params,
                                                       const MobilityOptions& options) {
  if (options.kind == MobilityKind::kMatrixFree && params.model == FluidModel::kRss)
    return std::make_unique<MatrixFreeRssMobility>(params, options);
  return std::make_unique<DenseMobility>(params, options);
}

}  // namespace stokesrods
