// Sums of regularized Stokeslets: the direct sum and a hierarchical-matrix (H-matrix) fast sum.
//
// METHOD. Fast sum = H-matrix of the 3T × 3S matrix [S_ε_s(x_t − y_s)]: kd cluster trees of
// targets and sources (bisect the bounding box's longest side, ≤ 32 points per leaf); a block
// (τ, σ) is far when max(diam τ, diam σ) ≤ η dist(τ, σ) (η = 1). Far blocks become U Vᵀ by adaptive
// cross approximation (ACA, partial pivoting) of the *regularized* kernel itself, recompressed by
// QR + SVD. So no Stokeslet expansion is used and there is no ε²/r² term to fold in or control: the
// regularization, different ε per source, points on a line are all just entries of the matrix.
// Near blocks are not stored: Apply sums them directly with the same vectorized loop as the direct
// sum. Apply is deterministic (a fixed split of the blocks between threads).
// ERROR CONTROL. ACA stops when |u_k||v_k| ≤ δ |U Vᵀ|_F and then checks one unused row per vector
// component (without it, collinear points, whose components decouple, gave errors of 1e-2); the
// SVD drops singular values whose tail is below δ; δ = 5 × tolerance. Measured errors in the norm of
// the header (max over targets of |Δw| / Σ_s |S||g_s|), tests/fluid/stokeslet_sum_test.cc:
//   tolerance        1e-4      1e-6      1e-8
//   random cloud     1.1e-5    9.6e-8    5.1e-10
//   10 helices       1.1e-5    1.9e-7    1.5e-9
// MEASURED (AMD EPYC, 2 cores shared with other builds: ±30%; ms, one thread unless said).
// The direct sum, vectorized (AVX-512/AVX2 clones chosen at run time, -fno-math-errno), costs
// 1.7 ns per pair: Apply 1.4 (10 helices), 5.6 (20), 34 (50), 141 (100); Build ≈ 0.
// The H-matrix on the lattice (forced), Build / Apply / factors:
//   20 helices  1e-4: 281 / 6.8 / 34 MB   1e-6: 764 / 9.5 / 65 MB   1e-8: 1265 / 10.7 / 78 MB
//   50 helices  1e-4: 1513 / 33 / 181 MB  1e-6, 1e-8: over the 300 MB budget
//   100 helices 1e-4: 2 GB, 1e-6: 2.8 GB, 1e-8: 3.6 GB of factors (Build 11–40 s)
// It never beats the vectorized direct sum here: on these thin helices 0.04 m apart 17–30 % of the
// pairs are near at η = 1, and the ranks (max 17 / 36 / 57) of small blocks compress little. Hence
// Build first estimates (rank 4 log10(1/tol), before any ACA, ≈ 1 ms) the memory and the Apply cost
// and sums directly when the tree would not fit in `max_megabytes` or not pay off: on the lattice
// MakeFastStokesletSum is then the direct sum (Apply 141 ms for 100 helices), not the goal of 10 ms.
// Two threads: not measurable on the shared machine (load 4 on 2 cores; wall times were worse).
// NEXT. The goal needs O(N) storage with nested bases: an FMM (four Laplace potentials with the
// ε² dipole folded into ψ and the O(ε⁴/r⁴) rest controlled by a minimum far distance) or an H²/
// bbFMM; at N = 12 800 its constants decide, so measure before choosing.
#include "stokesrods/fluid/stokeslet_sum.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "stokesrods/common/assert.h"

namespace stokesrods {
namespace {

int NumThreads() {
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}

// ---------------------------------------------------------------------------------------------
// The direct sum. Sources are stored as the columns (x, y, z, ε², g_x, g_y, g_z) of an S × 7 matrix
// so that the loop over sources vectorizes; it is compiled for AVX-512, AVX2 and the baseline,
// chosen at run time (the build adds no -march flag).

struct SourceColumns {
  const double *x, *y, *z, *e2, *gx, *gy, *gz;
};

SourceColumns Columns(const MatX& src) {
  return {src.col(0).data(), src.col(1).data(), src.col(2).data(), src.col(3).data(),
          src.col(4).data(), src.col(5).data(), src.col(6).data()};
}

/// w += Σ_{s ∈ [begin, end)} S_ε_s(x − y_s) g_s, with
/// S_ε(r) g = (1/R + ε²/R³) g + (r·g) r / R³,  R² = |r|² + ε².
__attribute__((target_clones("avx512f", "avx2", "default")))
void AddPointSum(const SourceColumns& c, Eigen::Index begin, Eigen::Index end, const double* x,
                 double* w) {
  double wx = 0.0, wy = 0.0, wz = 0.0;
#pragma omp simd reduction(+ : wx, wy, wz)
  for (Eigen::Index s = begin; s < end; ++s) {
    const double rx = x[0] - c.x[s], ry = x[1] - c.y[s], rz = x[2] - c.z[s];
    const double inv_r = 1.0 / std::sqrt(rx * rx + ry * ry + rz * rz + c.e2[s]);
    const double inv_r3 = inv_r * inv_r * inv_r;
    const double a = inv_r + c.e2[s] * inv_r3;
    const double b = (rx * c.gx[s] + ry * c.gy[s] + rz * c.gz[s]) * inv_r3;
    wx += a * c.gx[s] + b * rx;
    wy += a * c.gy[s] + b * ry;
    wz += a * c.gz[s] + b * rz;
  }
  w[0] += wx;
  w[1] += wy;
  w[2] += wz;
}

/// The S × 7 source matrix without strengths.
MatX SourceMatrix(const Matrix3X& sources, const VecX& regularization) {
  MatX src(sources.cols(), 7);
  src.leftCols<3>() = sources.transpose();
  src.col(3) = regularization.array().square().matrix();
  src.rightCols<3>().setZero();
  return src;
}

class DirectStokesletSum final : public StokesletSum {
 public:
  void Build(const Matrix3X& sources, const VecX& regularization,
             const Matrix3X& targets) override {
    SR_ASSERT(regularization.size() == sources.cols(), "one ε per source");
    src_ = SourceMatrix(sources, regularization);
    targets_ = targets;
  }

  void Apply(const Matrix3X& strengths, Matrix3X* w) const override {
    SR_ASSERT(strengths.cols() == src_.rows(), "one strength per source");
    const Eigen::Index nt = targets_.cols();
    src_.rightCols<3>() = strengths.transpose();
    w->setZero(3, nt);
    const SourceColumns c = Columns(src_);
#pragma omp parallel for schedule(static)
    for (Eigen::Index t = 0; t < nt; ++t)
      AddPointSum(c, 0, src_.rows(), targets_.col(t).data(), w->col(t).data());
  }

  StokesletSumStats Stats() const override {
    StokesletSumStats stats;
    stats.near_pairs = static_cast<std::int64_t>(src_.rows()) * targets_.cols();
    stats.stored_values = src_.size() + targets_.size();
    return stats;
  }

 private:
  mutable MatX src_;  // S × 7, the strengths are those of the current Apply
  Matrix3X targets_;
};

// ---------------------------------------------------------------------------------------------
// Cluster tree: recursive bisection of the bounding box along its longest side.

struct Cluster {
  int begin = 0, end = 0;  // points perm[begin, end)
  Vec3 lo, hi;             // bounding box [m]
  int left = -1, right = -1;
  int size() const { return end - begin; }
  bool leaf() const { return left < 0; }
  double diameter() const { return (hi - lo).norm(); }
};

struct ClusterTree {
  std::vector<Cluster> nodes;  // nodes[0] is the root
  std::vector<int> perm;       // tree order -> original index
};

int AddCluster(const Matrix3X& p, int begin, int end, int leaf_size, ClusterTree* tree) {
  Cluster c;
  c.begin = begin;
  c.end = end;
  c.lo = c.hi = p.col(tree->perm[begin]);
  for (int k = begin; k < end; ++k) {
    c.lo = c.lo.cwiseMin(p.col(tree->perm[k]));
    c.hi = c.hi.cwiseMax(p.col(tree->perm[k]));
  }
  const int id = static_cast<int>(tree->nodes.size());
  tree->nodes.push_back(c);
  int axis = 0;
  const double extent = (c.hi - c.lo).maxCoeff(&axis);
  if (end - begin <= leaf_size || extent <= 0.0) return id;
  auto first = tree->perm.begin() + begin;
  auto last = tree->perm.begin() + end;
  const double mid = 0.5 * (c.lo[axis] + c.hi[axis]);
  int split = static_cast<int>(
      std::partition(first, last, [&](int i) { return p(axis, i) < mid; }) - tree->perm.begin());
  if (split == begin || split == end) {  // rounding at a tiny extent: split at the median
    split = (begin + end) / 2;
    std::nth_element(first, tree->perm.begin() + split, last,
                     [&](int i, int j) { return p(axis, i) < p(axis, j); });
  }
  const int left = AddCluster(p, begin, split, leaf_size, tree);
  const int right = AddCluster(p, split, end, leaf_size, tree);
  tree->nodes[id].left = left;
  tree->nodes[id].right = right;
  return id;
}

ClusterTree MakeClusterTree(const Matrix3X& points, int leaf_size) {
  ClusterTree tree;
  tree.perm.resize(points.cols());
  for (int k = 0; k < static_cast<int>(points.cols()); ++k) tree.perm[k] = k;
  if (points.cols() > 0) AddCluster(points, 0, static_cast<int>(points.cols()), leaf_size, &tree);
  return tree;
}

double BoxDistance(const Cluster& a, const Cluster& b) {
  const Vec3 gap = (a.lo - b.hi).cwiseMax(b.lo - a.hi).cwiseMax(0.0);
  return gap.norm();
}

// ---------------------------------------------------------------------------------------------
// The hierarchical matrix: every (target cluster, source cluster) block of the 3T × 3S matrix
// [S_ε_s(x_t − y_s)] is either a dense near block or, when admissible, a low-rank U Vᵀ found by
// adaptive cross approximation and recompressed by QR + SVD.

/// Entries of the scalarized kernel matrix A(3t + a, 3s + b) = S_ε_s(x_t − y_s)_ab, in tree order.
struct KernelMatrix {
  const Matrix3X& x;  // targets, tree order
  const Matrix3X& y;  // sources, tree order
  const VecX& eps2;   // ε_s², tree order

  Mat3 Block(int t, int s) const {
    const Vec3 r = x.col(t) - y.col(s);
    const double inv_r = 1.0 / std::sqrt(r.squaredNorm() + eps2[s]);
    const double inv_r3 = inv_r * inv_r * inv_r;
    return (inv_r + eps2[s] * inv_r3) * Mat3::Identity() + inv_r3 * (r * r.transpose());
  }
  /// Row 3t + a over the sources [s0, s0 + n).
  void Row(int t, int a, int s0, int n, VecX* row) const {
    for (int j = 0; j < n; ++j) row->segment<3>(3 * j) = Block(t, s0 + j).row(a).transpose();
  }
  /// Column 3s + b over the targets [t0, t0 + m) (S_ε is symmetric).
  void Col(int s, int b, int t0, int m, VecX* col) const {
    for (int i = 0; i < m; ++i) col->segment<3>(3 * i) = Block(t0 + i, s).col(b);
  }
};

/// A row, one per component a (3 rows in all), of the residual A − Σ u vᵀ whose norm exceeds
/// `threshold`, or −1. The rows tried are unused ones at pseudo-random targets.
int UnresolvedRow(const KernelMatrix& kernel, int t0, int m, int s0, int n,
                  const std::vector<VecX>& us, const std::vector<VecX>& vs,
                  const std::vector<char>& used, double threshold, VecX* row) {
  for (int a = 0; a < 3; ++a) {
    int target = static_cast<int>((2654435761u * static_cast<unsigned>(us.size() + a)) % m);
    for (int tries = 0; tries < m && used[3 * target + a]; ++tries) target = (target + 1) % m;
    const int i = 3 * target + a;
    if (used[i]) continue;
    kernel.Row(t0 + target, a, s0, n, row);
    for (size_t l = 0; l < us.size(); ++l) *row -= us[l][i] * vs[l];
    if (row->norm() > threshold) return i;
  }
  return -1;
}

/// Adaptive cross approximation with partial pivoting (Bebendorf 2000) of the block
/// rows [3 t0, 3 t0 + 3m) × columns [3 s0, 3 s0 + 3n): A ≈ Σ_k u_k v_kᵀ, stopped when
/// |u_k| |v_k| ≤ δ |Σ u vᵀ|_F. Returns false when the rank would make U, V larger than the block.
bool CrossApproximation(const KernelMatrix& kernel, int t0, int m, int s0, int n, double delta,
                        MatX* u, MatX* v) {
  const int rows = 3 * m, cols = 3 * n;
  const int max_rank = rows * cols / (rows + cols);
  std::vector<VecX> us, vs;
  std::vector<char> used(rows, 0);
  VecX row(cols), col(rows);
  double norm2 = 0.0;
  int i = 0;
  bool converged = false;
  while (static_cast<int>(us.size()) < max_rank) {
    used[i] = 1;
    kernel.Row(t0 + i / 3, i % 3, s0, n, &row);
    for (size_t l = 0; l < us.size(); ++l) row -= us[l][i] * vs[l];
    Eigen::Index j = 0;
    const double pivot = row.cwiseAbs().maxCoeff(&j);
    if (pivot == 0.0) {  // this row is already exact: try the first unused one
      const auto next = std::find(used.begin(), used.end(), 0);
      if (next == used.end()) { converged = true; break; }
      i = static_cast<int>(next - used.begin());
      continue;
    }
    VecX vk = row / row[j];
    kernel.Col(s0 + static_cast<int>(j) / 3, static_cast<int>(j) % 3, t0, m, &col);
    for (size_t l = 0; l < us.size(); ++l) col -= vs[l][j] * us[l];
    // |S_k|_F² = |S_{k−1}|_F² + 2 Σ_l (u_l·u_k)(v_l·v_k) + |u_k|²|v_k|².
    double cross = 0.0;
    for (size_t l = 0; l < us.size(); ++l) cross += us[l].dot(col) * vs[l].dot(vk);
    const double step2 = col.squaredNorm() * vk.squaredNorm();
    norm2 += 2.0 * cross + step2;
    us.push_back(col);
    vs.push_back(std::move(vk));
    if (step2 <= delta * delta * norm2) {
      // The estimate can stop early when the pivots never visit part of the block (points on a
      // line make each component couple only to itself): check one unused row per component.
      i = UnresolvedRow(kernel, t0, m, s0, n, us, vs, used, delta * std::sqrt(norm2 / rows), &row);
      if (i < 0) { converged = true; break; }
      continue;
    }
    double best = -1.0;
    for (int r = 0; r < rows; ++r)
      if (!used[r] && std::abs(col[r]) > best) { best = std::abs(col[r]); i = r; }
    if (best < 0.0) { converged = true; break; }
  }
  if (!converged) return false;
  const int k = static_cast<int>(us.size());
  u->resize(rows, k);
  v->resize(cols, k);
  for (int l = 0; l < k; ++l) {
    u->col(l) = us[l];
    v->col(l) = vs[l];
  }
  return true;
}

/// U Vᵀ = Q_u (R_u R_vᵀ) Q_vᵀ; truncates the SVD of the small core where the discarded singular
/// values are below δ |U Vᵀ|_F (Frobenius).
void Recompress(double delta, MatX* u, MatX* v) {
  const Eigen::Index k = u->cols();
  if (k == 0) return;
  Eigen::HouseholderQR<MatX> qu(*u), qv(*v);
  const MatX ru = qu.matrixQR().topRows(k).triangularView<Eigen::Upper>();
  const MatX rv = qv.matrixQR().topRows(k).triangularView<Eigen::Upper>();
  Eigen::JacobiSVD<MatX> svd(ru * rv.transpose(), Eigen::ComputeThinU | Eigen::ComputeThinV);
  const VecX& sigma = svd.singularValues();
  const double total2 = sigma.squaredNorm();
  Eigen::Index rank = k;
  double tail2 = 0.0;
  while (rank > 0 && tail2 + sigma[rank - 1] * sigma[rank - 1] <= delta * delta * total2) {
    tail2 += sigma[rank - 1] * sigma[rank - 1];
    --rank;
  }
  const MatX qu_thin = qu.householderQ() * MatX::Identity(u->rows(), k);
  const MatX qv_thin = qv.householderQ() * MatX::Identity(v->rows(), k);
  *u = qu_thin * (svd.matrixU().leftCols(rank) * sigma.head(rank).asDiagonal());
  *v = qv_thin * svd.matrixV().leftCols(rank);
}

struct MatrixBlock {
  int t = 0, s = 0;  // cluster ids
  bool low_rank = false;
  MatX u, v;         // low rank: A ≈ u vᵀ (3m × k, 3n × k); near blocks are summed directly
};

class FastStokesletSum final : public StokesletSum {
 public:
  explicit FastStokesletSum(const StokesletSumOptions& options) : options_(options) {
    SR_ASSERT(options.tolerance > 0.0 && options.tolerance < 1.0, "tolerance in (0, 1)");
    SR_ASSERT(options.leaf_size >= 1 && options.admissibility > 0.0, "bad tree options");
  }

  void Build(const Matrix3X& sources, const VecX& regularization,
             const Matrix3X& targets) override {
    SR_ASSERT(regularization.size() == sources.cols(), "one ε per source");
    num_sources_ = static_cast<int>(sources.cols());
    num_targets_ = static_cast<int>(targets.cols());
    blocks_.clear();
    stats_ = StokesletSumStats{};
    use_direct_ = static_cast<std::int64_t>(num_sources_) * num_targets_ < options_.direct_below_pairs;
    if (use_direct_) {
      direct_.Build(sources, regularization, targets);
      stats_ = direct_.Stats();
      return;
    }
    ttree_ = MakeClusterTree(targets, options_.leaf_size);
    stree_ = MakeClusterTree(sources, options_.leaf_size);
    x_.resize(3, num_targets_);
    y_.resize(3, num_sources_);
    eps2_.resize(num_sources_);
    for (int k = 0; k < num_targets_; ++k) x_.col(k) = targets.col(ttree_.perm[k]);
    for (int k = 0; k < num_sources_; ++k) {
      y_.col(k) = sources.col(stree_.perm[k]);
      eps2_[k] = regularization[stree_.perm[k]] * regularization[stree_.perm[k]];
    }
    src_ = MatX(num_sources_, 7);
    src_.leftCols<3>() = y_.transpose();
    src_.col(3) = eps2_;
    src_.rightCols<3>().setZero();
    Partition(0, 0);
    if ((options_.choose_by_cost && !PaysOff()) || !FillBlocks()) {  // the hierarchical matrix does not pay here: sum directly
      use_direct_ = true;
      blocks_.clear();
      direct_.Build(sources, regularization, targets);
      stats_ = direct_.Stats();
      return;
    }
    const int threads = NumThreads();
    SplitBlocks(threads);
    accumulators_.assign(threads, VecX::Zero(3 * num_targets_));
    rank_scratch_.assign(threads, VecX::Zero(std::max(stats_.max_rank, 1)));
    permuted_strengths_.resize(3 * num_sources_);
  }

  void Apply(const Matrix3X& strengths, Matrix3X* w) const override {
    if (use_direct_) return direct_.Apply(strengths, w);
    SR_ASSERT(strengths.cols() == num_sources_, "one strength per source");
    for (int k = 0; k < num_sources_; ++k) {
      permuted_strengths_.segment<3>(3 * k) = strengths.col(stree_.perm[k]);
      src_.row(k).tail<3>() = strengths.col(stree_.perm[k]).transpose();
    }
    const SourceColumns columns = Columns(src_);
    const int threads = static_cast<int>(accumulators_.size());
    // Each thread takes a fixed range of blocks of about equal cost: the sum is deterministic.
#pragma omp parallel for schedule(static, 1) num_threads(threads)
    for (int p = 0; p < threads; ++p) {
      VecX& acc = accumulators_[p];
      VecX& tmp = rank_scratch_[p];
      acc.setZero();
      for (int b = first_block_[p]; b < first_block_[p + 1]; ++b) {
        const MatrixBlock& block = blocks_[b];
        const Cluster& tc = ttree_.nodes[block.t];
        const Cluster& sc = stree_.nodes[block.s];
        if (block.low_rank) {
          const auto g = permuted_strengths_.segment(3 * sc.begin, 3 * sc.size());
          auto t = tmp.head(block.u.cols());
          t.noalias() = block.v.transpose() * g;
          acc.segment(3 * tc.begin, 3 * tc.size()).noalias() += block.u * t;
        } else {
          for (int i = tc.begin; i < tc.end; ++i)
            AddPointSum(columns, sc.begin, sc.end, x_.col(i).data(), acc.data() + 3 * i);
        }
      }
    }
    w->resize(3, num_targets_);
#pragma omp parallel for schedule(static)
    for (int k = 0; k < num_targets_; ++k) {
      Vec3 sum = accumulators_[0].segment<3>(3 * k);
      for (int p = 1; p < threads; ++p) sum += accumulators_[p].segment<3>(3 * k);
      w->col(ttree_.perm[k]) = sum;
    }
  }

  StokesletSumStats Stats() const override { return stats_; }

 private:
  // The block tree: split the larger cluster until a block is admissible or both are leaves.
  void Partition(int t, int s) {
    const Cluster& tc = ttree_.nodes[t];
    const Cluster& sc = stree_.nodes[s];
    const double dist = BoxDistance(tc, sc);
    const double dt = tc.diameter(), ds = sc.diameter();
    if (dist > 0.0 && std::max(dt, ds) <= options_.admissibility * dist) {
      blocks_.push_back({t, s, true, {}, {}});
    } else if (tc.leaf() && sc.leaf()) {
      blocks_.push_back({t, s, false, {}, {}});
    } else if (tc.leaf() || (!sc.leaf() && ds > dt)) {
      Partition(t, sc.left);
      Partition(t, sc.right);
    } else {
      Partition(tc.left, s);
      Partition(tc.right, s);
    }
  }

  /// A priori (before any compression): with a nominal rank k = 4 log10(1/tolerance) per far
  /// block (the measured average is below it), do the factors fit in the memory budget and is an
  /// Apply cheaper than the direct sum? Measured costs: a near pair (summed directly, vectorized)
  /// ≈ 1.7 ns, a stored factor value ≈ 1 ns ≈ 0.6 pair.
  bool PaysOff() const {
    const double rank = 4.0 * std::log10(1.0 / options_.tolerance);
    double factors = 0.0, near = 0.0;
    for (const MatrixBlock& block : blocks_) {
      const double m = ttree_.nodes[block.t].size(), n = stree_.nodes[block.s].size();
      if (block.low_rank) factors += rank * 3.0 * (m + n);
      if (!block.low_rank) near += m * n;
    }
    const double direct = static_cast<double>(num_sources_) * num_targets_;
    return 8e-6 * factors <= options_.max_megabytes && near + 0.6 * factors < 0.7 * direct;
  }

  /// Compresses the admissible blocks; false when the factors would exceed the memory budget.
  bool FillBlocks() {
    const KernelMatrix kernel{x_, y_, eps2_};
    // ACA and recompression each within δ of the block's Frobenius norm. The per-target error
    // measure (relative to Σ_s |S||g_s|) is far looser than a block's norm: δ = 5 tolerance gives
    // measured errors 5–50 times below the tolerance (tests/fluid/stokeslet_sum_test.cc).
    const double delta = 5.0 * options_.tolerance;
    const int nb = static_cast<int>(blocks_.size());
    const std::int64_t budget = static_cast<std::int64_t>(options_.max_megabytes * 1e6 / 8.0);
    std::int64_t stored = 0;
    bool over_budget = false;
#pragma omp parallel for schedule(dynamic, 4)
    for (int b = 0; b < nb; ++b) {
      if (over_budget) continue;
      MatrixBlock& block = blocks_[b];
      const Cluster& tc = ttree_.nodes[block.t];
      const Cluster& sc = stree_.nodes[block.s];
      if (block.low_rank) {
        block.low_rank = CrossApproximation(kernel, tc.begin, tc.size(), sc.begin, sc.size(),
                                            delta, &block.u, &block.v);
        if (block.low_rank) Recompress(delta, &block.u, &block.v);
      }
      if (!block.low_rank) {
        block.u.resize(0, 0);
        block.v.resize(0, 0);
      }
      if (block.low_rank) {
#pragma omp atomic
        stored += block.u.size() + block.v.size();
      }
      if (stored > budget) over_budget = true;
    }
    if (over_budget) return false;
    for (const MatrixBlock& block : blocks_) {
      const std::int64_t pairs = static_cast<std::int64_t>(ttree_.nodes[block.t].size()) *
                                 stree_.nodes[block.s].size();
      if (block.low_rank) {
        stats_.far_pairs += pairs;
        stats_.stored_values += block.u.size() + block.v.size();
        stats_.max_rank = std::max(stats_.max_rank, static_cast<int>(block.u.cols()));
      } else {
        stats_.near_pairs += pairs;
      }
    }
    stats_.stored_values += src_.size() + x_.size();
    return true;
  }

  // first_block_[p] … first_block_[p + 1]: the blocks of thread p, of about equal storage.
  void SplitBlocks(int threads) {
    std::vector<double> cost(blocks_.size() + 1, 0.0);
    for (size_t b = 0; b < blocks_.size(); ++b) {
      const MatrixBlock& block = blocks_[b];
      const double near = block.low_rank ? 0.0
                                         : 3.0 * ttree_.nodes[block.t].size() *
                                               stree_.nodes[block.s].size();
      cost[b + 1] = cost[b] + static_cast<double>(block.u.size() + block.v.size()) + near;
    }
    first_block_.assign(threads + 1, static_cast<int>(blocks_.size()));
    first_block_[0] = 0;
    for (int p = 1; p < threads; ++p)
      first_block_[p] = static_cast<int>(
          std::lower_bound(cost.begin(), cost.end(), cost.back() * p / threads) - cost.begin());
  }

  StokesletSumOptions options_;
  std::vector<int> first_block_;
  int num_sources_ = 0, num_targets_ = 0;
  bool use_direct_ = false;
  DirectStokesletSum direct_;
  ClusterTree ttree_, stree_;
  Matrix3X x_, y_;  // targets, sources in tree order
  VecX eps2_;
  std::vector<MatrixBlock> blocks_;
  StokesletSumStats stats_;
  mutable std::vector<VecX> accumulators_, rank_scratch_;  // per thread
  mutable VecX permuted_strengths_;
  mutable MatX src_;  // S × 7 in tree order (see SourceMatrix), strengths of the current Apply
};

}  // namespace

std::unique_ptr<StokesletSum> MakeDirectStokesletSum() {
  return std::make_unique<DirectStokesletSum>();
}

std::unique_ptr<StokesletSum> MakeFastStokesletSum(const StokesletSumOptions& options) {
  return std::make_unique<FastStokesletSum>(options);
}

}  // namespace stokesrods
