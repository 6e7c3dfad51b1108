// The fast Stokeslet sum: a kernel-independent FMM (Ying, Biros & Zorin 2004) on a uniform-depth
// octree (fmm_tree.h) with precomputed, width-independent translation operators (fmm_operators.h).
//
// Apply: S2M (the leaf's sources, with their own regularized kernel, evaluated on the upward check
// surface and fitted by upward equivalent densities), M2M up to level 2, M2L over the V lists of
// every level (by Fourier transforms, fmm_m2l_fft.h: one transform per box, a product per V-list
// entry; or, the reference, each entry summed as the source box's equivalent Stokeslets at the
// check points: AddM2l, fmm_operators.h), L2L down, L2T (the
// downward equivalent densities evaluated at the targets), and the near field (the 27 neighbouring
// leaves) summed directly with the regularized kernel by the vectorized loop of the direct sum:
// each leaf's sources padded to whole SIMD blocks by sources of zero strength, and a target's
// neighbour leaves summed in one call (AddPointSumBlocks: no remainder loops, one reduction).
// Every box's work is done by one thread, in a fixed order: Apply is deterministic.
//
// DEPTH. The tree is cut at the depth of least estimated cost (FmmCost, fmm_cost.h: kernel
// evaluations of the near field, S2M and L2T, n² per M2L, the dense translations per box, and
// the Apply's share of the Build), and the sum is direct where that cost is not below S·T
// (unless forced, for tests). An M2L by Fourier transforms costs
// about 345 kernel evaluations at p = 4 (the direct one n² = 3136), and the leaf width is chosen
// finer than a factor 2: the root cube's side is extent × 2^(k/4), k = 0 … 3, by the same cost
// (fmm_tree.cc). On the 100-helix lattice: 8.3 M near pairs (10 % of all), where the direct M2L's
// cost chose 18.9 M (the root 1.68 × extent at depth 3, 2914 M2Ls) and the root of side extent
// alone 29.0 M.
//
// PRECISION. From kSinglePrecisionTolerance (1e-4, stokeslet_sum.h) on, the near field, S2M and
// M2L run in single precision (float SIMD lanes; the fits, M2M, L2L and L2T stay double): the
// measured errors at p = 4 are unchanged (tests/fluid/stokeslet_sum_test.cc).
//
// REGULARIZATION. Far (V-list) pairs are approximated by Stokes flows, while S_ε is one only up
// to O((ε/r)⁴): S_ε = S + (ε²/2)(I − 3 r̂r̂ᵀ)/r³ + ε⁴(−9/8 I + 15/8 r̂r̂ᵀ)/r⁵ + …, whose ε² term
// (a potential dipole) is a Stokes flow the equivalent densities reproduce (S2M uses S_ε itself)
// and whose ε⁴ term is not. Far pairs are at least a leaf width w apart, so leaves are kept no
// narrower than w_min = ε_max (c_ε / tolerance)^(1/4), which bounds that part of the error by
// the tolerance: c_ε = 2 bounds the coefficients of the ε⁴ term (15/8); the test
// MixedRegularizationAndTargetsOnSources runs at that bound.
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <utility>
#include <vector>

#include "stokesrods/common/assert.h"
#include "stokesrods/fluid/fmm_cost.h"
#include "stokesrods/fluid/fmm_m2l_fft.h"
#include "stokesrods/fluid/fmm_operators.h"
#include "stokesrods/fluid/fmm_tree.h"
#include "stokesrods/fluid/point_stokeslet.h"
#include "stokesrods/fluid/stokeslet_sum.h"
#include "stokesrods/solver/blas.h"

namespace stokesrods {
namespace {

constexpr double kEpsilonConstant = 2.0;  // c_ε

constexpr Eigen::Index kGemmColumns = 64;

/// One operator of the dense translations, in double and rounded to single precision.
struct Translation {
  const MatX* a = nullptr;
  const Eigen::MatrixXf* a_single = nullptr;
};

/// c_p = alpha a_p b_p for each p by the BLAS (OpenBLAS: its kernels for the CPU at hand, on one
/// thread so that the result does not depend on the thread count (solver/blas.h); the build
/// itself targets baseline x86-64, where Eigen's products are 5–10× slower), over fixed blocks of
/// kGemmColumns columns, those of all the products at once, spread over the OpenMP threads: each
/// column is that of its block's product, whatever the number of threads. (One product on one
/// thread, the fits and translations were the largest serial part of a two-thread step on a
/// hundred helices: docs/performance.md, session 19; the M2M and L2L's eight products of a few
/// blocks each, one after the other, left the second thread waiting: session 27.)
/// With `single`, each block's columns are rounded to single precision and multiplied by a_p's
/// single-precision copy (sgemm: twice the rate of dgemm, and half the operator to pack), the
/// result returned in double. The sums in single precision (tolerance ≥ 1e-4, p = 4) take this
/// for M2M and L2L: the FMM's error stays as it was (tests/fluid/stokeslet_sum_test.cc;
/// bench_stokeslet_sum: 100 helices 4.2726e-5 → 4.2723e-5, 50: 5.7910e-5 → 5.7908e-5) and
/// GMRES's products per step too (lattice50 3.025). Not for the fits check_to_up and check_to_down,
/// pseudo-inverses cut at 1e-6 of their largest singular value, which amplify the rounding:
/// their single precision took lattice50 from 3.025 to 4.0 (check_to_up) and 4.225
/// (check_to_down) products per step (docs/performance.md, session 37).
void GemmByColumns(const std::vector<Translation>& a, const std::vector<const MatX*>& b,
                   double alpha, bool single, std::vector<MatX*>* c) {
  SR_ASSERT(BlasIsSingleThreaded(), "the BLAS must run on one thread");
  struct Block {
    std::size_t product;
    Eigen::Index first;
  };
  std::vector<Block> blocks;
  for (std::size_t p = 0; p < a.size(); ++p) {
    SR_ASSERT(b[p]->rows() == a[p].a->cols(), "GemmByColumns: sizes");
    SR_ASSERT(!single || (a[p].a_single != nullptr && a[p].a_single->rows() == a[p].a->rows()),
              "GemmByColumns: no single-precision operator");
    (*c)[p]->resize(a[p].a->rows(), b[p]->cols());
    if (a[p].a->rows() == 0) continue;
    for (Eigen::Index first = 0; first < b[p]->cols(); first += kGemmColumns) blocks.push_back({p, first});
  }
  const int num_blocks = static_cast<int>(blocks.size());
#pragma omp parallel if (num_blocks > 1)
  {
    Eigen::MatrixXf b_single, c_single;  // a block's columns, per thread
#pragma omp for schedule(dynamic)
    for (int i = 0; i < num_blocks; ++i) {
      const Translation& ap = a[blocks[static_cast<size_t>(i)].product];
      const MatX& bp = *b[blocks[static_cast<size_t>(i)].product];
      MatX& cp = *(*c)[blocks[static_cast<size_t>(i)].product];
      const Eigen::Index first = blocks[static_cast<size_t>(i)].first;
      const int m = static_cast<int>(ap.a->rows()), k = static_cast<int>(ap.a->cols());
      const int n = static_cast<int>(std::min(kGemmColumns, bp.cols() - first));
      if (single) {
        b_single = bp.middleCols(first, n).cast<float>();
        c_single.resize(m, n);
        Gemm(m, n, k, static_cast<float>(alpha), ap.a_single->data(), m, b_single.data(), k, 0.0f,
             c_single.data(), m);
        cp.middleCols(first, n) = c_single.cast<double>();
      } else {
        Gemm(m, n, k, alpha, ap.a->data(), m, bp.data() + first * k, k, 0.0, cp.data() + first * m,
             m);
      }
    }
  }
}

void GemmByColumns(const MatX& a, const MatX& b, double alpha, MatX* c) {
  std::vector<MatX*> out = {c};
  GemmByColumns({{&a, nullptr}}, {&b}, alpha, /*single=*/false, &out);
}

/// The translations between levels (M2M, L2L) of many boxes: out_j = ops[octant_j] in.col(column_j)
/// for every entry j, as one BLAS product per octant (the boxes of one octant share the
/// operator) instead of one matrix–vector product per box. Entry j's result is column slot[j] of
/// (*products)[octant_j].
void TranslateByOctant(const std::array<MatX, 8>& ops,
                       const std::array<Eigen::MatrixXf, 8>& ops_single, bool single,
                       const MatX& in, const std::vector<int>& column,
                       const std::vector<int>& octant, std::array<MatX, 8>* products,
                       std::vector<int>* slot) {
  std::array<int, 8> count{};
  slot->resize(column.size());
  for (std::size_t j = 0; j < column.size(); ++j)
    (*slot)[j] = count[static_cast<size_t>(octant[j])]++;
  std::array<MatX, 8> gathered;
  for (std::size_t o = 0; o < 8; ++o) gathered[o].resize(in.rows(), count[o]);
  for (std::size_t j = 0; j < column.size(); ++j)
    gathered[static_cast<size_t>(octant[j])].col((*slot)[j]) = in.col(column[j]);
  // The eight products' column blocks over the threads at once (one octant holds a few blocks at
  // most: alone, each product ran on one thread).
  std::vector<Translation> a;
  std::vector<const MatX*> b;
  std::vector<MatX*> c;
  for (std::size_t o = 0; o < 8; ++o)
    a.push_back({&ops[o], &ops_single[o]}), b.push_back(&gathered[o]), c.push_back(&(*products)[o]);
  GemmByColumns(a, b, 1.0, single, &c);
}

class FmmStokesletSum final : public StokesletSum {
 public:
  explicit FmmStokesletSum(const StokesletSumOptions& options)
      : options_(options), single_(options.tolerance >= kSinglePrecisionTolerance),
        direct_(MakeDirectStokesletSum(single_)) {
    SR_ASSERT(options.tolerance > 0.0 && options.tolerance < 1.0, "tolerance in (0, 1)");
  }

  void Build(const Matrix3X& sources, const VecX& regularization,
             const Matrix3X& targets) override;
  void Apply(const Matrix3X& strengths, Matrix3X* w) const override;
  StokesletSumStats Stats() const override { return stats_; }

 private:
  void Upward() const;
  void Downward() const;
  void Leaves(Matrix3X* w) const;
  void M2l(int level) const;
  void PadSources(const Matrix3X& sources, const VecX& regularization);

  StokesletSumOptions options_;
  bool single_ = false;  // near field and S2M in single precision (stokeslet_sum.h)
  std::unique_ptr<StokesletSum> direct_;
  bool use_direct_ = true;
  const FmmOperators* op_ = nullptr;
  const M2lSpectra* spectra_ = nullptr;  // when options_.m2l_by_fft
  std::vector<M2lByOffset> v_by_offset_;  // per level, when spectra_
  mutable M2lFftScratch<float> fft_single_;
  mutable M2lFftScratch<double> fft_double_;
  FmmTree tree_;
  Matrix3X x_;        // targets in tree order
  // S' × 7 sources in tree order (point_stokeslet.h) with the current strengths, each leaf's
  // padded to whole blocks of kPointSumBlock by sources of zero strength: slot s holds source
  // slot_source_[s] (−1: padding); leaf b's slots are leaf_sources_[b]; the near field of leaf
  // b's targets is the slots near_ranges_[near_range_start_[b], near_range_start_[b + 1]).
  mutable MatX src_;
  Eigen::Index num_sources_ = 0;
  std::vector<int> slot_source_;
  std::vector<SourceRange> leaf_sources_, near_ranges_;
  std::vector<int> near_range_start_;
  Vec3 origin_ = Vec3::Zero();     // single precision: positions relative to it
  mutable Eigen::MatrixXf src_f_;  // src_ in single precision
  Eigen::Matrix3Xf x_f_;           // x_ in single precision
  mutable std::vector<MatX> up_, check_, down_;  // per level: 3n × boxes
  StokesletSumStats stats_;
};

void FmmStokesletSum::Build(const Matrix3X& sources, const VecX& regularization,
                            const Matrix3X& targets) {
  SR_ASSERT(regularization.size() == sources.cols(), "one ε per source");
  const double pairs = static_cast<double>(sources.cols()) * static_cast<double>(targets.cols());
  use_direct_ = true;
  tree_ = FmmTree{};
  const int order = OrderFor(options_);
  if (order > 0 && pairs >= static_cast<double>(options_.direct_below_pairs)) {
    const FmmCost cost = EstimatedFmmCost(order, options_);
    const double eps_max = regularization.size() > 0 ? regularization.cwiseAbs().maxCoeff() : 0.0;
    const double min_width = eps_max * std::pow(kEpsilonConstant / options_.tolerance, 0.25);
    tree_ = BuildFmmTree(sources, targets, min_width, cost, !options_.choose_by_cost);
    use_direct_ = tree_.depth == 0;
    if (!use_direct_) {
      op_ = &GetFmmOperators(order, kFmmCutoff);
      spectra_ = options_.m2l_by_fft ? &GetM2lSpectra(*op_) : nullptr;
      v_by_offset_.clear();
      if (spectra_ != nullptr)
        for (const FmmList& v : tree_.v_lists) v_by_offset_.push_back(SortByOffset(v));
    }
  }
  stats_ = StokesletSumStats{};
  if (use_direct_) {
    direct_->Build(sources, regularization, targets);
    stats_ = direct_->Stats();
    return;
  }
  PadSources(sources, regularization);
  const auto ns = static_cast<Eigen::Index>(src_.rows());
  x_.resize(3, targets.cols());
  for (Eigen::Index t = 0; t < targets.cols(); ++t)
    x_.col(t) = targets.col(tree_.target_order[static_cast<size_t>(t)]);
  if (single_) {
    origin_ = ns > 0 ? Vec3(sources.rowwise().mean()) : Vec3::Zero();
    src_f_ = src_.cast<float>();
    src_f_.leftCols<3>() = (src_.leftCols<3>().rowwise() - origin_.transpose()).cast<float>();
    x_f_ = (x_.colwise() - origin_).cast<float>();
  }
  const int levels = tree_.depth + 1;
  up_.assign(static_cast<size_t>(levels), MatX());
  check_.assign(static_cast<size_t>(levels), MatX());
  down_.assign(static_cast<size_t>(levels), MatX());
  stats_.near_pairs = tree_.near_pairs;
  stats_.far_pairs = static_cast<std::int64_t>(pairs) - tree_.near_pairs;
  stats_.max_rank = 3 * op_->points;
  stats_.cost = tree_.cost;
  stats_.stored_values = src_.size() + x_.size();
  for (int l = 2; l < levels; ++l) {
    const auto boxes = static_cast<Eigen::Index>(tree_.levels[static_cast<size_t>(l)].size());
    up_[static_cast<size_t>(l)].resize(3 * op_->points, boxes);
    check_[static_cast<size_t>(l)].resize(3 * op_->points, boxes);
    down_[static_cast<size_t>(l)].resize(3 * op_->points, boxes);
    stats_.stored_values += 9 * op_->points * boxes;
  }
}

// The padded source layout (see the members) and the near field's ranges of slots, contiguous
// neighbours merged.
void FmmStokesletSum::PadSources(const Matrix3X& sources, const VecX& regularization) {
  const auto& leaves = tree_.levels[static_cast<size_t>(tree_.depth)];
  num_sources_ = sources.cols();
  leaf_sources_.assign(leaves.size(), SourceRange{});
  slot_source_.clear();
  for (std::size_t b = 0; b < leaves.size(); ++b) {
    leaf_sources_[b].begin = static_cast<int>(slot_source_.size());
    for (int s = leaves[b].src_begin; s < leaves[b].src_end; ++s)
      slot_source_.push_back(tree_.source_order[static_cast<size_t>(s)]);
    while (slot_source_.size() % kPointSumBlock != 0) slot_source_.push_back(-1);
    leaf_sources_[b].end = static_cast<int>(slot_source_.size());
  }
  const auto slots = static_cast<Eigen::Index>(slot_source_.size());
  src_.setZero(slots, 7);
  for (Eigen::Index s = 0; s < slots; ++s) {
    const int k = slot_source_[static_cast<size_t>(s)];
    if (k < 0) {  // zero strength at the previous slot's place (any finite point), ε² = 1
      if (s > 0) src_.row(s).head<3>() = src_.row(s - 1).head<3>();
      src_(s, 3) = 1.0;
      continue;
    }
    src_.row(s).head<3>() = sources.col(k).transpose();
    src_(s, 3) = regularization[k] * regularization[k];
  }
  near_range_start_.assign(1, 0);
  near_ranges_.clear();
  std::vector<SourceRange> ranges;
  for (std::size_t b = 0; b < leaves.size(); ++b) {
    ranges.clear();
    for (int e = tree_.near.start[b]; e < tree_.near.start[b + 1]; ++e) {
      const SourceRange r = leaf_sources_[static_cast<size_t>(tree_.near.box[static_cast<size_t>(e)])];
      if (r.end > r.begin) ranges.push_back(r);
    }
    std::sort(ranges.begin(), ranges.end(),
              [](const SourceRange& p, const SourceRange& q) { return p.begin < q.begin; });
    for (const SourceRange& r : ranges) {
      if (near_ranges_.size() > static_cast<size_t>(near_range_start_.back()) &&
          near_ranges_.back().end == r.begin)
        near_ranges_.back().end = r.end;
      else
        near_ranges_.push_back(r);
    }
    near_range_start_.push_back(static_cast<int>(near_ranges_.size()));
  }
}

void FmmStokesletSum::Apply(const Matrix3X& strengths, Matrix3X* w) const {
  if (use_direct_) return direct_->Apply(strengths, w);
  SR_ASSERT(strengths.cols() == num_sources_, "one strength per source");
  // (The scatter and gather over the threads: on a hundred helices 13 000 sources and 6 500
  // targets per product, 0.5 % of the samples with the second thread waiting.)
  const Eigen::Index rows = src_.rows();
#pragma omp parallel for schedule(static) if (rows > 4096)
  for (Eigen::Index s = 0; s < rows; ++s) {
    const int k = slot_source_[static_cast<size_t>(s)];
    if (k >= 0) src_.row(s).tail<3>() = strengths.col(k).transpose();  // padding stays zero
    if (single_) src_f_.row(s).tail<3>() = src_.row(s).tail<3>().cast<float>();
  }
  Upward();
  Downward();
  Matrix3X sorted;
  Leaves(&sorted);
  w->resize(3, sorted.cols());
  const Eigen::Index targets = sorted.cols();
#pragma omp parallel for schedule(static) if (targets > 4096)
  for (Eigen::Index t = 0; t < targets; ++t)
    w->col(tree_.target_order[static_cast<size_t>(t)]) = sorted.col(t);
}

// S2M at the leaves, M2M up to level 2, and the projection on the M2L basis.
void FmmStokesletSum::Upward() const {
  const int leaf = tree_.depth;
  const auto& boxes = tree_.levels[static_cast<size_t>(leaf)];
  const SourceColumns columns = Columns(src_);
  const SourceColumnsF columns_f = single_ ? ColumnsF(src_f_) : SourceColumnsF{};
  const double width = tree_.BoxWidth(leaf);
  MatX& check = check_[static_cast<size_t>(leaf)];
  const int n = op_->points;
  check.setZero();
#pragma omp parallel for schedule(dynamic, 4)
  for (std::size_t b = 0; b < boxes.size(); ++b) {
    const FmmBox& box = boxes[b];
    if (!box.has_sources()) continue;
    const Vec3 centre = tree_.BoxCentre(leaf, box.code);
    const SourceRange own = leaf_sources_[b];
    for (int i = 0; i < n; ++i) {
      const Vec3 p = centre + (kFmmOuterRadius * width) * op_->surface.col(i);
      double* out = check.col(static_cast<Eigen::Index>(b)).data() + 3 * i;
      if (single_) {
        const Eigen::Vector3f pf = (p - origin_).cast<float>();
        AddPointSumBlocks(columns_f, &own, 1, pf.data(), out);
      } else {
        AddPointSum(columns, own.begin, own.end, p.data(), out);
      }
    }
  }
  GemmByColumns(op_->check_to_up, check, width, &up_[static_cast<size_t>(leaf)]);
  std::array<MatX, 8> moved;
  std::vector<int> column, octant, slot;
  for (int l = leaf - 1; l >= 2; --l) {
    const auto& parents = tree_.levels[static_cast<size_t>(l)];
    const auto& children = tree_.levels[static_cast<size_t>(l) + 1];
    column.clear();
    octant.clear();
    std::vector<int> entry(children.size(), -1);  // child → its entry in column
    for (std::size_t c = 0; c < children.size(); ++c)
      if (children[c].has_sources()) {
        entry[c] = static_cast<int>(column.size());
        column.push_back(static_cast<int>(c));
        octant.push_back(static_cast<int>(children[c].code & 7));
      }
    TranslateByOctant(op_->m2m, op_->m2m_single, single_, up_[static_cast<size_t>(l) + 1], column,
                      octant, &moved, &slot);
    MatX& parent_up = up_[static_cast<size_t>(l)];
#pragma omp parallel for schedule(static)
    for (std::size_t b = 0; b < parents.size(); ++b) {
      auto out = parent_up.col(static_cast<Eigen::Index>(b));
      out.setZero();
      for (int c = parents[b].child_begin; c < parents[b].child_end; ++c) {
        const int j = entry[static_cast<size_t>(c)];  // children in order: as before, per box
        if (j < 0) continue;
        const auto k = static_cast<size_t>(j);
        out += moved[static_cast<size_t>(octant[k])].col(slot[k]);
      }
    }
  }
}

// M2L over the V lists and L2L, level by level from the top.
void FmmStokesletSum::Downward() const {
  std::array<MatX, 8> moved;
  std::vector<int> column, octant, slot, box;
  for (int l = 2; l <= tree_.depth; ++l) {
    M2l(l);
    const auto& boxes = tree_.levels[static_cast<size_t>(l)];
    MatX& down = down_[static_cast<size_t>(l)];
    GemmByColumns(op_->check_to_down, check_[static_cast<size_t>(l)], 1.0, &down);
    if (l == 2) continue;
    column.clear();
    octant.clear();
    box.clear();
    for (std::size_t b = 0; b < boxes.size(); ++b)
      if (boxes[b].has_targets()) {
        box.push_back(static_cast<int>(b));
        column.push_back(boxes[b].parent);
        octant.push_back(static_cast<int>(boxes[b].code & 7));
      }
    TranslateByOctant(op_->l2l, op_->l2l_single, single_, down_[static_cast<size_t>(l) - 1], column,
                      octant, &moved, &slot);
#pragma omp parallel for schedule(static)
    for (std::size_t j = 0; j < box.size(); ++j)
      down.col(box[j]) += moved[static_cast<size_t>(octant[j])].col(slot[j]);  // one per box
  }
}

// The V-list translations of a level into the downward check potentials (AddM2l), box by box:
// each box's sum by one thread in list order, the same on any number of threads.
void FmmStokesletSum::M2l(int level) const {
  const FmmList& v = tree_.v_lists[static_cast<size_t>(level)];
  const auto& boxes = tree_.levels[static_cast<size_t>(level)];
  const MatX& up = up_[static_cast<size_t>(level)];
  MatX& check = check_[static_cast<size_t>(level)];
  check.setZero();
  if (spectra_ != nullptr) {
    const M2lByOffset& entries = v_by_offset_[static_cast<size_t>(level)];
    if (single_)
      AddM2lByFft(*spectra_, entries, up, &check, &fft_single_);
    else
      AddM2lByFft(*spectra_, entries, up, &check, &fft_double_);
    return;
  }
#pragma omp parallel
  {
    M2lScratch scratch;
#pragma omp for schedule(dynamic, 2)
    for (std::size_t b = 0; b < boxes.size(); ++b) {
      const int first = v.start[b], count = v.start[b + 1] - first;
      AddM2l(*op_, v.box.data() + first, v.offset.data() + first, count, up, single_, &scratch,
             check.col(static_cast<Eigen::Index>(b)).data());
    }
  }
}

// L2T and the near field, leaf by leaf.
void FmmStokesletSum::Leaves(Matrix3X* w) const {
  const int leaf = tree_.depth;
  const auto& boxes = tree_.levels[static_cast<size_t>(leaf)];
  const SourceColumns columns = Columns(src_);
  const SourceColumnsF columns_f = single_ ? ColumnsF(src_f_) : SourceColumnsF{};
  const double width = tree_.BoxWidth(leaf);
  const int n = op_->points;
  w->setZero(3, x_.cols());
#pragma omp parallel
  {
    // The downward equivalent densities as sources, ε = 0 (L2T), in the sum's precision: in
    // single precision relative to the box's centre (rounding 1e-7 of the box, not of the cloud).
    MatX surface(single_ ? 0 : n, 7);
    surface.col(3).setZero();
    Eigen::MatrixXf surface_f(single_ ? n : 0, 7);
    if (single_) {
      surface_f.leftCols<3>() = (kFmmOuterRadius * width * op_->surface).transpose().cast<float>();
      surface_f.col(3).setZero();
    }
#pragma omp for schedule(dynamic, 4)
    for (std::size_t b = 0; b < boxes.size(); ++b) {
      const FmmBox& box = boxes[b];
      if (!box.has_targets()) continue;
      const Vec3 centre = tree_.BoxCentre(leaf, box.code);
      const auto down =
          Eigen::Map<const Matrix3X>(down_[static_cast<size_t>(leaf)].col(static_cast<Eigen::Index>(b)).data(), 3, n);
      if (single_) {
        surface_f.rightCols<3>() = down.transpose().cast<float>();
      } else {
        surface.leftCols<3>() =
            ((kFmmOuterRadius * width * op_->surface).colwise() + centre).transpose();
        surface.rightCols<3>() = down.transpose();
      }
      const SourceColumns far = Columns(surface);
      const SourceColumnsF far_f = single_ ? ColumnsF(surface_f) : SourceColumnsF{};
      const SourceRange surface_range{0, n};
      const SourceRange* near = near_ranges_.data() + near_range_start_[b];
      const int count = near_range_start_[b + 1] - near_range_start_[b];
      // The box's targets by groups of kPointSumTargets, which share its sources.
      for (int t0 = box.tgt_begin; t0 < box.tgt_end; t0 += kPointSumTargets) {
        const int group = std::min(kPointSumTargets, box.tgt_end - t0);
        double* out[kPointSumTargets];
        for (int k = 0; k < group; ++k) out[k] = w->col(t0 + k).data();
        if (single_) {
          Eigen::Matrix<float, 3, kPointSumTargets> local;
          const float* x_local[kPointSumTargets];
          const float* x_near[kPointSumTargets];
          for (int k = 0; k < group; ++k) {
            local.col(k) = (x_.col(t0 + k) - centre).cast<float>();
            x_local[k] = local.col(k).data();
            x_near[k] = x_f_.col(t0 + k).data();
          }
          AddPointSumRangesTargets(far_f, &surface_range, 1, group, x_local, out);
          AddPointSumBlocksTargets(columns_f, near, count, group, x_near, out);
        } else {
          const double* x[kPointSumTargets];
          for (int k = 0; k < group; ++k) x[k] = x_.col(t0 + k).data();
          AddPointSumRangesTargets(far, &surface_range, 1, group, x, out);
          AddPointSumRangesTargets(columns, near, count, group, x, out);
        }
      }
    }
  }
}

}  // namespace

std::unique_ptr<StokesletSum> MakeFastStokesletSum(const StokesletSumOptions& options) {
  return std::make_unique<FmmStokesletSum>(options);
}

}  // namespace stokesrods
