#include "stokesrods/fluid/fmm_tree.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

#include "stokesrods/fluid/fmm_operators.h"

namespace stokesrods {
namespace {

constexpr int kMaxLevel = 20;  // Morton codes of 3 × 20 bits

std::uint64_t Spread(std::uint64_t v) {  // bits b → 3b
  v &= 0x1fffff;
  v = (v | v << 32) & 0x1f00000000ffffULL;
  v = (v | v << 16) & 0x1f0000ff0000ffULL;
  v = (v | v << 8) & 0x100f00f00f00f00fULL;
  v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
  v = (v | v << 2) & 0x1249249249249249ULL;
  return v;
}

std::uint64_t Compact(std::uint64_t v) {  // bits 3b → b
  v &= 0x1249249249249249ULL;
  v = (v ^ (v >> 2)) & 0x10c30c30c30c30c3ULL;
  v = (v ^ (v >> 4)) & 0x100f00f00f00f00fULL;
  v = (v ^ (v >> 8)) & 0x1f0000ff0000ffULL;
  v = (v ^ (v >> 16)) & 0x1f00000000ffffULL;
  v = (v ^ (v >> 32)) & 0x1fffff;
  return v;
}

std::uint64_t Encode(const std::array<std::int64_t, 3>& i) {
  return Spread(static_cast<std::uint64_t>(i[0])) << 2 | Spread(static_cast<std::uint64_t>(i[1])) << 1 |
         Spread(static_cast<std::uint64_t>(i[2]));
}

std::array<std::int64_t, 3> Decode(std::uint64_t code) {
  return {static_cast<std::int64_t>(Compact(code >> 2)), static_cast<std::int64_t>(Compact(code >> 1)),
          static_cast<std::int64_t>(Compact(code))};
}

/// Per point, its cell at kMaxLevel in the cube of side `width` from `corner`.
std::vector<std::array<std::int64_t, 3>> FinestCells(const Matrix3X& p, const Vec3& corner,
                                                     double width) {
  const double cells = static_cast<double>(1 << kMaxLevel);
  std::vector<std::array<std::int64_t, 3>> out(static_cast<size_t>(p.cols()));
  for (Eigen::Index k = 0; k < p.cols(); ++k)
    for (int d = 0; d < 3; ++d)
      out[static_cast<size_t>(k)][static_cast<size_t>(d)] =
          std::clamp<std::int64_t>(static_cast<std::int64_t>((p(d, k) - corner[d]) / width * cells),
                                   0, (1 << kMaxLevel) - 1);
  return out;
}

/// Sorts the points by Morton code at kMaxLevel (ties in input order): the order and the sorted
/// codes. First by their box at the deepest level of at most about as many boxes as points (a
/// stable counting sort), then each box's few points by their whole code: the order of one
/// std::sort of (code, index) pairs, which took a quarter of the Build on a hundred helices.
/// `cells`: the points' FinestCells in the tree's root cube.
std::vector<std::uint64_t> SortByCode(const std::vector<std::array<std::int64_t, 3>>& cells,
                                      std::vector<int>* order) {
  std::vector<std::pair<std::uint64_t, int>> keyed(cells.size());
  for (std::size_t k = 0; k < cells.size(); ++k) keyed[k] = {Encode(cells[k]), static_cast<int>(k)};
  int bucket_level = 1;
  while (bucket_level < kMaxLevel && (std::size_t{1} << (3 * bucket_level + 3)) <= keyed.size())
    ++bucket_level;
  if (keyed.size() > 64) {
    const int shift = 3 * (kMaxLevel - bucket_level);
    std::vector<int> start((std::size_t{1} << (3 * bucket_level)) + 1, 0);
    for (const auto& entry : keyed) ++start[(entry.first >> shift) + 1];
    for (std::size_t b = 1; b < start.size(); ++b) start[b] += start[b - 1];
    std::vector<std::pair<std::uint64_t, int>> bucketed(keyed.size());
    std::vector<int> next(start.begin(), start.end() - 1);
    for (const auto& entry : keyed)
      bucketed[static_cast<size_t>(next[entry.first >> shift]++)] = entry;
    for (std::size_t b = 0; b + 1 < start.size(); ++b)
      if (start[b + 1] - start[b] > 1)
        std::sort(bucketed.begin() + start[b], bucketed.begin() + start[b + 1]);
    keyed.swap(bucketed);
  } else {
    std::sort(keyed.begin(), keyed.end());
  }
  std::vector<std::uint64_t> codes;
  codes.reserve(keyed.size());
  order->clear();
  order->reserve(keyed.size());
  for (const auto& [code, k] : keyed) {
    codes.push_back(code);
    order->push_back(k);
  }
  return codes;
}

/// The boxes of `level`: the distinct prefixes of the sorted codes of sources and targets.
std::vector<FmmBox> MakeLevel(int level, const std::vector<std::uint64_t>& src,
                              const std::vector<std::uint64_t>& tgt) {
  const int shift = 3 * (kMaxLevel - level);
  std::vector<FmmBox> boxes;
  std::size_t s = 0, t = 0;
  while (s < src.size() || t < tgt.size()) {
    const std::uint64_t code = std::min(s < src.size() ? src[s] >> shift : ~0ULL,
                                        t < tgt.size() ? tgt[t] >> shift : ~0ULL);
    FmmBox box;
    box.code = code;
    box.src_begin = static_cast<int>(s);
    while (s < src.size() && src[s] >> shift == code) ++s;
    box.src_end = static_cast<int>(s);
    box.tgt_begin = static_cast<int>(t);
    while (t < tgt.size() && tgt[t] >> shift == code) ++t;
    box.tgt_end = static_cast<int>(t);
    boxes.push_back(box);
  }
  return boxes;
}

/// Links the boxes of a level to their parents (both sorted by code).
void LinkParents(std::vector<FmmBox>* parents, std::vector<FmmBox>* children) {
  std::size_t p = 0;
  for (std::size_t c = 0; c < children->size(); ++c) {
    while ((*parents)[p].code != (*children)[c].code >> 3) ++p;
    if ((*parents)[p].child_end == 0) (*parents)[p].child_begin = static_cast<int>(c);
    (*parents)[p].child_end = static_cast<int>(c) + 1;
    (*children)[c].parent = static_cast<int>(p);
  }
}

/// Index of the box with this code at this level, or −1.
int Find(const std::vector<FmmBox>& boxes, int level, const std::array<std::int64_t, 3>& i) {
  const std::int64_t n = std::int64_t{1} << level;
  for (std::int64_t v : i)
    if (v < 0 || v >= n) return -1;
  const std::uint64_t code = Encode(i);
  const auto it = std::lower_bound(boxes.begin(), boxes.end(), code,
                                   [](const FmmBox& b, std::uint64_t c) { return b.code < c; });
  return it != boxes.end() && it->code == code ? static_cast<int>(it - boxes.begin()) : -1;
}

/// Calls f(index) for every existing neighbour (incl. the box itself) of box i at a level.
template <typename F>
void ForNeighbours(const std::vector<FmmBox>& boxes, int level, std::uint64_t code, F f) {
  const auto c = Decode(code);
  for (int dx = -1; dx <= 1; ++dx)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dz = -1; dz <= 1; ++dz) {
        const int k = Find(boxes, level, {c[0] + dx, c[1] + dy, c[2] + dz});
        if (k >= 0) f(k);
      }
}

/// The V lists of a level ≥ 2: children of the parent's neighbours that have sources and are not
/// neighbours, for the boxes with targets.
FmmList MakeVList(const std::vector<FmmBox>& parents, const std::vector<FmmBox>& boxes, int level) {
  FmmList list;
  for (const FmmBox& b : boxes) {
    if (b.has_targets()) {
      const auto bc = Decode(b.code);
      ForNeighbours(parents, level - 1, parents[static_cast<size_t>(b.parent)].code, [&](int p) {
        const FmmBox& pn = parents[static_cast<size_t>(p)];
        for (int c = pn.child_begin; c < pn.child_end; ++c) {
          const FmmBox& a = boxes[static_cast<size_t>(c)];
          const auto ac = Decode(a.code);
          const std::int64_t vx = ac[0] - bc[0], vy = ac[1] - bc[1], vz = ac[2] - bc[2];
          if (!a.has_sources() || std::max({std::abs(vx), std::abs(vy), std::abs(vz)}) < 2) continue;
          list.box.push_back(c);
          list.offset.push_back(M2lIndex(static_cast<int>(vx), static_cast<int>(vy), static_cast<int>(vz)));
        }
      });
    }
    list.start.push_back(static_cast<int>(list.box.size()));
  }
  return list;
}

/// The near lists of the leaf level and the number of (target, source) pairs in them.
FmmList MakeNearList(const std::vector<FmmBox>& boxes, int level, std::int64_t* pairs) {
  FmmList list;
  *pairs = 0;
  for (const FmmBox& b : boxes) {
    if (b.has_targets())
      ForNeighbours(boxes, level, b.code, [&](int k) {
        const FmmBox& a = boxes[static_cast<size_t>(k)];
        if (!a.has_sources()) return;
        list.box.push_back(k);
        *pairs += static_cast<std::int64_t>(b.tgt_end - b.tgt_begin) * (a.src_end - a.src_begin);
      });
    list.start.push_back(static_cast<int>(list.box.size()));
  }
  return list;
}

/// Counts on a dense grid of one level's cells, with summed-area tables for box sums.
class LevelGrid {
 public:
  /// `largest`: the largest finest cell of the points along each axis.
  LevelGrid(const std::vector<std::array<std::int64_t, 3>>& src,
            const std::vector<std::array<std::int64_t, 3>>& tgt,
            const std::array<std::int64_t, 3>& largest, int level) {
    const int shift = kMaxLevel - level;
    for (std::size_t d = 0; d < 3; ++d) n_[d] = (largest[d] >> shift) + 1;
    cells_ = n_[0] * n_[1] * n_[2];
    if (cells_ > kMaxCells) return;
    sources_.assign(static_cast<size_t>(cells_), 0);
    targets_.assign(static_cast<size_t>(cells_), 0);
    CountCells(src, shift, &sources_);
    CountCells(tgt, shift, &targets_);
    // Summed-area tables of the source counts and of the cells with sources, (n + 1)³.
    count_sum_.assign(static_cast<size_t>((n_[0] + 1) * (n_[1] + 1) * (n_[2] + 1)), 0);
    occupied_sum_ = count_sum_;
    for (std::int64_t i = 0; i < n_[0]; ++i)
      for (std::int64_t j = 0; j < n_[1]; ++j)
        for (std::int64_t k = 0; k < n_[2]; ++k) {
          const std::int64_t s = sources_[Index(i, j, k)];
          Accumulate(&count_sum_, i, j, k, s);
          Accumulate(&occupied_sum_, i, j, k, s > 0 ? 1 : 0);
        }
  }
  bool fits() const { return cells_ <= kMaxCells; }

  /// The boxes, the V-list pairs (M2Ls) and the near pairs of this level (fmm_tree.h's lists).
  void Count(double* boxes, double* m2l, double* near) const {
    *boxes = *m2l = *near = 0.0;
    for (std::int64_t i = 0; i < n_[0]; ++i)
      for (std::int64_t j = 0; j < n_[1]; ++j)
        for (std::int64_t k = 0; k < n_[2]; ++k) {
          const std::size_t c = Index(i, j, k);
          if (sources_[c] > 0 || targets_[c] > 0) *boxes += 1.0;
          if (targets_[c] == 0) continue;
          const std::array<std::int64_t, 3> lo{i - 1, j - 1, k - 1}, hi{i + 1, j + 1, k + 1};
          // The parent's neighbours' children: parent p = c / 2, children 2(p − 1) … 2(p + 1) + 1.
          const std::array<std::int64_t, 3> plo{2 * (i / 2) - 2, 2 * (j / 2) - 2, 2 * (k / 2) - 2};
          const std::array<std::int64_t, 3> phi{plo[0] + 5, plo[1] + 5, plo[2] + 5};
          *near += static_cast<double>(targets_[c]) * static_cast<double>(BoxSum(count_sum_, lo, hi));
          *m2l += static_cast<double>(BoxSum(occupied_sum_, plo, phi) - BoxSum(occupied_sum_, lo, hi));
        }
  }

 private:
  static constexpr std::int64_t kMaxCells = std::int64_t{1} << 18;
  /// counts[cell] += the points in it. Consecutive points (a rod's) mostly share a cell: counted
  /// as runs, not by one increment each through memory (a chain of stores and loads to one
  /// address that took a third of LeastCost on a hundred helices).
  void CountCells(const std::vector<std::array<std::int64_t, 3>>& points, int shift,
                  std::vector<std::int64_t>* counts) const {
    std::size_t cell = 0;
    std::int64_t run = 0;
    for (const auto& c : points) {
      const std::size_t k = Index(c[0] >> shift, c[1] >> shift, c[2] >> shift);
      if (run > 0 && k != cell) (*counts)[cell] += run, run = 0;
      cell = k;
      ++run;
    }
    if (run > 0) (*counts)[cell] += run;
  }
  std::size_t Index(std::int64_t i, std::int64_t j, std::int64_t k) const {
    return static_cast<size_t>((i * n_[1] + j) * n_[2] + k);
  }
  std::size_t SumIndex(std::int64_t i, std::int64_t j, std::int64_t k) const {
    return static_cast<size_t>((i * (n_[1] + 1) + j) * (n_[2] + 1) + k);
  }
  void Accumulate(std::vector<std::int64_t>* t, std::int64_t i, std::int64_t j, std::int64_t k,
                  std::int64_t v) const {
    auto& a = *t;
    a[SumIndex(i + 1, j + 1, k + 1)] = v + a[SumIndex(i, j + 1, k + 1)] + a[SumIndex(i + 1, j, k + 1)] +
                                       a[SumIndex(i + 1, j + 1, k)] - a[SumIndex(i, j, k + 1)] -
                                       a[SumIndex(i, j + 1, k)] - a[SumIndex(i + 1, j, k)] +
                                       a[SumIndex(i, j, k)];
  }
  /// The sum over the cells [lo, hi] (inclusive, clipped to the grid).
  std::int64_t BoxSum(const std::vector<std::int64_t>& a, std::array<std::int64_t, 3> lo,
                      std::array<std::int64_t, 3> hi) const {
    for (std::size_t d = 0; d < 3; ++d) {
      lo[d] = std::max<std::int64_t>(lo[d], 0);
      hi[d] = std::min<std::int64_t>(hi[d], n_[d] - 1) + 1;
      if (hi[d] <= lo[d]) return 0;
    }
    return a[SumIndex(hi[0], hi[1], hi[2])] - a[SumIndex(lo[0], hi[1], hi[2])] -
           a[SumIndex(hi[0], lo[1], hi[2])] - a[SumIndex(hi[0], hi[1], lo[2])] +
           a[SumIndex(lo[0], lo[1], hi[2])] + a[SumIndex(lo[0], hi[1], lo[2])] +
           a[SumIndex(hi[0], lo[1], lo[2])] - a[SumIndex(lo[0], lo[1], lo[2])];
  }
  std::array<std::int64_t, 3> n_{1, 1, 1};
  std::int64_t cells_ = 0;
  std::vector<std::int64_t> sources_, targets_, count_sum_, occupied_sum_;
};

/// The estimated cost of one Apply and its share of the Build, in pairs of the direct sum.
double Total(const FmmCost& cost, double far, double near, double points) {
  return cost.apply_scale * (far + near) + cost.per_point_build * points;
}

/// The least estimated cost over the depths ≥ 2 (as BuildFmmTree's loop counts it) of the tree
/// whose root cube of side `width` starts at `corner`, from LevelGrid's counts, and its depth.
/// Not `complete` when a level's grid was too large to count densely before the search ended
/// (the cost of the levels counted, infinity if none). With the points' cells in that cube, which
/// the tree then sorts by.
struct LeastCostDepth {
  double cost = std::numeric_limits<double>::infinity();
  int depth = 0;
  bool complete = true;
  std::vector<std::array<std::int64_t, 3>> source_cells, target_cells;
};
LeastCostDepth LeastCost(const Matrix3X& sources, const Matrix3X& targets, const Vec3& corner,
                         double width, double min_leaf_width, const FmmCost& cost) {
  LeastCostDepth best;
  best.source_cells = FinestCells(sources, corner, width);
  best.target_cells = FinestCells(targets, corner, width);
  const auto& src = best.source_cells;
  const auto& tgt = best.target_cells;
  std::array<std::int64_t, 3> largest{0, 0, 0};
  for (const auto* points : {&src, &tgt})
    for (const auto& c : *points)
      for (std::size_t d = 0; d < 3; ++d) largest[d] = std::max(largest[d], c[d]);
  const double points = static_cast<double>(sources.cols() + targets.cols());
  double far_cost = cost.per_point * points;
  for (int level = 2; level <= kMaxLevel && width / static_cast<double>(1 << level) >= min_leaf_width;
       ++level) {
    const LevelGrid grid(src, tgt, largest, level);
    if (!grid.fits()) {
      best.complete = false;
      break;
    }
    double boxes = 0.0, m2l = 0.0, near = 0.0;
    grid.Count(&boxes, &m2l, &near);
    far_cost += cost.per_box * boxes + cost.per_m2l * m2l;
    const double total = Total(cost, far_cost, near, points);
    if (total < best.cost) best.cost = total, best.depth = level;
    if (total > 2.0 * best.cost || boxes >= points) break;
  }
  return best;
}

}  // namespace

Vec3 FmmTree::BoxCentre(int level, std::uint64_t code) const {
  const auto i = Decode(code);
  const double w = BoxWidth(level);
  return corner + w * Vec3(static_cast<double>(i[0]) + 0.5, static_cast<double>(i[1]) + 0.5,
                           static_cast<double>(i[2]) + 0.5);
}

FmmTree BuildFmmTree(const Matrix3X& sources, const Matrix3X& targets, double min_leaf_width,
                     const FmmCost& cost, bool force_tree) {
  FmmTree tree;
  if (sources.cols() == 0 || targets.cols() == 0) return tree;
  const Vec3 lo = sources.rowwise().minCoeff().cwiseMin(targets.rowwise().minCoeff());
  const Vec3 hi = sources.rowwise().maxCoeff().cwiseMax(targets.rowwise().maxCoeff());
  const double extent = (hi - lo).maxCoeff();
  if (!(extent > 0.0) || !std::isfinite(extent)) return tree;
  // The cube from the lowest corner of the points: along each axis they then span the fewest
  // boxes of every level, ⌈extent_d / w⌉ (centred, a flat cloud such as the 100-helix lattice,
  // 0.38 × 0.38 × 0.2 m, spilt into slivers of boxes above and below: twice the M2Ls).
  tree.corner = lo - Vec3::Constant(0.5e-9 * extent);
  tree.width = extent * (1.0 + 1e-9);
  const double pairs = static_cast<double>(sources.cols()) * static_cast<double>(targets.cols());
  // Whether the tree pays is decided on the root of side `extent` alone, as before the choice of
  // widths below (10 helices, 1280 × 650 points: a wider root estimated at 0.98 of the pairs ran
  // 1.16× slower than the direct sum), against the direct sum's pairs.
  const double direct_cost = pairs;
  LeastCostDepth least = LeastCost(sources, targets, tree.corner, tree.width, min_leaf_width, cost);
  if (!force_tree && least.complete && least.cost >= direct_cost) return FmmTree{};
  // The root's side, extent × 2^(k/4), k = 0 … 3: leaves of any width within a factor 2^(1/8)
  // (a uniform tree offers only extent / 2^depth), chosen by the estimated cost. The levels below
  // the estimate's depth are not built (when it counted every level it needed).
  // The three estimates over the threads, taken in order of k (the same choice on any count).
  std::array<double, 3> widths{};
  std::array<LeastCostDepth, 3> widened;
  for (int k = 1; k < 4; ++k) widths[static_cast<size_t>(k - 1)] = extent * (1.0 + 1e-9) * std::exp2(0.25 * k);
#pragma omp parallel for schedule(dynamic, 1)
  for (std::size_t i = 0; i < widths.size(); ++i)
    widened[i] = LeastCost(sources, targets, tree.corner, widths[i], min_leaf_width, cost);
  for (std::size_t i = 0; i < widths.size(); ++i)
    if (widened[i].complete && widened[i].cost < least.cost)
      least = std::move(widened[i]), tree.width = widths[i];
  const int max_level = least.complete && least.depth >= 2 ? least.depth : kMaxLevel;
  std::vector<std::uint64_t> src, tgt;
#pragma omp parallel sections
  {
#pragma omp section
    src = SortByCode(least.source_cells, &tree.source_order);
#pragma omp section
    tgt = SortByCode(least.target_cells, &tree.target_order);
  }
  const double points = static_cast<double>(sources.cols() + targets.cols());
  tree.levels.push_back(MakeLevel(0, src, tgt));
  tree.levels.push_back(MakeLevel(1, src, tgt));
  LinkParents(&tree.levels[0], &tree.levels[1]);
  tree.v_lists.resize(2);
  double far_cost = cost.per_point * points, best = std::numeric_limits<double>::infinity();
  std::int64_t m2l = 0;
  for (int level = 2; level <= max_level && tree.BoxWidth(level) >= min_leaf_width; ++level) {
    tree.levels.push_back(MakeLevel(level, src, tgt));
    LinkParents(&tree.levels[static_cast<size_t>(level) - 1], &tree.levels.back());
    tree.v_lists.push_back(MakeVList(tree.levels[static_cast<size_t>(level) - 1], tree.levels.back(), level));
    m2l += static_cast<std::int64_t>(tree.v_lists.back().box.size());
    far_cost += cost.per_box * static_cast<double>(tree.levels.back().size()) +
                cost.per_m2l * static_cast<double>(tree.v_lists.back().box.size());
    std::int64_t near = 0;
    MakeNearList(tree.levels.back(), level, &near);
    const double total = Total(cost, far_cost, static_cast<double>(near), points);
    if (total < best) {
      best = total;
      tree.depth = level;
      tree.m2l_count = m2l;
    }
    // The cost is convex in the depth: stop once it has clearly turned.
    if (total > 2.0 * best || tree.levels.back().size() >= static_cast<size_t>(sources.cols() + targets.cols())) break;
  }
  if (tree.depth == 0 || (!force_tree && best >= direct_cost)) return FmmTree{};
  tree.levels.resize(static_cast<size_t>(tree.depth) + 1);
  tree.v_lists.resize(static_cast<size_t>(tree.depth) + 1);
  tree.near = MakeNearList(tree.levels.back(), tree.depth, &tree.near_pairs);
  tree.cost = best;
  return tree;
}

}  // namespace stokesrods
