#include "stokesrods/sim/coarse_level.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "stokesrods/common/assert.h"
#include "stokesrods/common/parallel.h"
#include "stokesrods/solver/blas.h"

namespace stokesrods {

namespace {

// t[k np + j], k < 7: over the n nodes (xs, ys, zs), Σ_i of (1/R + ε²/R³, then r rᵀ/R³ as xx,
// xy, xz, yy, yz, zz), r = p_j − x_i, R² = |r|² + ε_j², at each of the np points p_j = (px, py,
// pz)_j with its own ε_j² (e2): the point Stokeslets S_ε between a chunk of nodes and each point,
// summed over the chunk, all points at once (vectorized over the points). With a centre c (not
// null), also their first moments about it, t[(7 + 7 a + k) np + j] = Σ_i (x_i − c)_a (the k-th
// term), a < 3, summed over spans of kSpan points whose 28 sums stay in L1 while every node
// passes over them (all 320 points of twenty helices at once, 72 KB swept once per node, took
// E 13–14 ms against 1.5 ms for the 7 sums).
__attribute__((target_clones("avx512f", "avx2", "default")))
void SumChunkAtPoints(const double* xs, const double* ys, const double* zs, int n,
                      const double* px, const double* py, const double* pz, const double* e2,
                      int np, const double* centre, double* t) {
  if (centre == nullptr) {
    std::fill(t, t + 7 * static_cast<std::ptrdiff_t>(np), 0.0);
    for (int i = 0; i < n; ++i) {
      const double x = xs[i], y = ys[i], z = zs[i];
#pragma omp simd
      for (int j = 0; j < np; ++j) {
        const double rx = px[j] - x, ry = py[j] - y, rz = pz[j] - z;
        const double inv = 1.0 / std::sqrt(rx * rx + ry * ry + rz * rz + e2[j]);
        const double inv3 = inv * inv * inv;
        t[j] += inv + e2[j] * inv3;
        t[np + j] += rx * rx * inv3, t[2 * np + j] += rx * ry * inv3, t[3 * np + j] += rx * rz * inv3;
        t[4 * np + j] += ry * ry * inv3, t[5 * np + j] += ry * rz * inv3, t[6 * np + j] += rz * rz * inv3;
      }
    }
    return;
  }
  constexpr int kSpan = 64;  // points per span: 28 sums of 64 points, 14 KB
  double s[28 * kSpan];
  for (int j0 = 0; j0 < np; j0 += kSpan) {
    const int ns = std::min(kSpan, np - j0);
    std::fill(s, s + 28 * kSpan, 0.0);
    for (int i = 0; i < n; ++i) {
      const double x = xs[i], y = ys[i], z = zs[i];
      const double dx = x - centre[0], dy = y - centre[1], dz = z - centre[2];
#pragma omp simd
      for (int j = 0; j < ns; ++j) {
        const double rx = px[j0 + j] - x, ry = py[j0 + j] - y, rz = pz[j0 + j] - z;
        const double inv = 1.0 / std::sqrt(rx * rx + ry * ry + rz * rz + e2[j0 + j]);
        const double inv3 = inv * inv * inv;
        // Written out term by term (with the terms in an array the loop stayed scalar).
        const double v0 = inv + e2[j0 + j] * inv3, v1 = rx * rx * inv3, v2 = rx * ry * inv3,
                     v3 = rx * rz * inv3, v4 = ry * ry * inv3, v5 = ry * rz * inv3,
                     v6 = rz * rz * inv3;
        double* q = s + j;
        q[0 * kSpan] += v0, q[1 * kSpan] += v1, q[2 * kSpan] += v2, q[3 * kSpan] += v3;
        q[4 * kSpan] += v4, q[5 * kSpan] += v5, q[6 * kSpan] += v6;
        q[7 * kSpan] += dx * v0, q[8 * kSpan] += dx * v1, q[9 * kSpan] += dx * v2;
        q[10 * kSpan] += dx * v3, q[11 * kSpan] += dx * v4, q[12 * kSpan] += dx * v5;
        q[13 * kSpan] += dx * v6;
        q[14 * kSpan] += dy * v0, q[15 * kSpan] += dy * v1, q[16 * kSpan] += dy * v2;
        q[17 * kSpan] += dy * v3, q[18 * kSpan] += dy * v4, q[19 * kSpan] += dy * v5;
        q[20 * kSpan] += dy * v6;
        q[21 * kSpan] += dz * v0, q[22 * kSpan] += dz * v1, q[23 * kSpan] += dz * v2;
        q[24 * kSpan] += dz * v3, q[25 * kSpan] += dz * v4, q[26 * kSpan] += dz * v5;
        q[27 * kSpan] += dz * v6;
      }
    }
    for (int k = 0; k < 28; ++k)
      std::copy(s + k * kSpan, s + k * kSpan + ns, t + k * static_cast<std::ptrdiff_t>(np) + j0);
  }
}

// The same at one point p (x, y, z) with ε² = e2.
void SumPointStokeslets(const double* xs, const double* ys, const double* zs, double e2, int n,
                        const double* p, double t[7]) {
  SumChunkAtPoints(xs, ys, zs, n, p, p + 1, p + 2, &e2, 1, nullptr, t);
}

Mat3 StokesletMatrix(const double t[7]) {
  Mat3 s;
  s << t[0] + t[1], t[2], t[3], t[2], t[0] + t[4], t[5], t[3], t[5], t[0] + t[6];
  return s;
}

// Z at a node of arm d (its offset from the chunk's centroid over the chunk's radius), 3 × K: [I]
// (K = 3) or [I, −[d]×] (K = 6: the nodal force F + Ω × d = F − [d]× Ω).
template <int K>
Eigen::Matrix<double, 3, K> ModesAt(const Vec3& d) {
  Eigen::Matrix<double, 3, K> z;
  z.template leftCols<3>().setIdentity();
  if constexpr (K == 6) z.template rightCols<3>() = -CrossMatrix(d);
  return z;
}

// Zᵀ b for a node of arm d (K × b's columns): b, or [b; [d]× b].
template <int K, class B>
Eigen::Matrix<double, K, B::ColsAtCompileTime> ModesTransposedTimes(const Vec3& d, const B& b) {
  if constexpr (K == 3) {
    return b;
  } else {
    Eigen::Matrix<double, K, B::ColsAtCompileTime> out;
    out << b, CrossMatrix(d) * b;
    return out;
  }
}

// e's K × K block (K a, K b) = m, in single precision (written out: Eigen's cast into a block of
// a column-major float matrix was slower, E of a hundred helices 44–60 against 35–43 ms).
template <int K>
void PutBlock(const Eigen::Matrix<double, K, K>& m, int a, int b, Eigen::MatrixXf* e) {
  float* column = e->data() + static_cast<std::ptrdiff_t>(K) * b * e->rows() + K * a;
  for (int c = 0; c < K; ++c, column += e->rows())
    for (int r = 0; r < K; ++r) column[r] = static_cast<float>(m(r, c));
}

}  // namespace

CoarseLayout CoarseLayout::For(int num_rods) {
  if (num_rods <= kTurnsUpToRods)
    return {.chunks_per_rod = 4, .turns = true, .points_per_chunk = 4, .fixed_chunk = false};
  return {};
}

bool CoarseLevel::Build(const std::vector<CoarseRod>& rods, const std::vector<MatX>& blocks,
                        double scale) {
  return Build(rods, blocks, scale, CoarseLayout::For(static_cast<int>(rods.size())));
}

bool CoarseLevel::Build(const std::vector<CoarseRod>& rods, const std::vector<MatX>& blocks,
                        double scale, const CoarseLayout& layout) {
  SR_ASSERT(blocks.size() == rods.size(), "one block per rod");
  SR_ASSERT(layout.chunks_per_rod >= 1 && layout.points_per_chunk >= 1, "a chunk and a point per chunk");
  layout_ = layout;
  scale_ = scale;
  chunk_first_.clear();
  chunk_rod_.clear();
  rod_first_chunk_.clear();
  rod_first_node_.clear();
  point_first_.clear();
  point_chunk_.clear();
  chunk_first_point_.clear();
  for (std::size_t r = 0; r < rods.size(); ++r) {
    const int n = static_cast<int>(rods[r].x->cols()), first = rods[r].node_offset;
    // The fixed nodes' chunk [first, first + fixed), then `free_chunks` over the rest.
    const bool own_chunk = layout.fixed_chunk && layout.chunks_per_rod >= 2;
    const int fixed = own_chunk ? std::clamp(rods[r].fixed_nodes, 0, n - 1) : 0;
    const int free_nodes = n - fixed;
    const int free_chunks = std::min(layout.chunks_per_rod - (fixed > 0 ? 1 : 0), free_nodes);
    const int chunks = free_chunks + (fixed > 0 ? 1 : 0);
    rod_first_chunk_.push_back(static_cast<int>(chunk_first_.size()));
    rod_first_node_.push_back(first);
    // The free chunks' edges from the first free node: evenly spaced, or graded from the fixed
    // nodes (each chunk at least one node: a short rod's first edges pushed up).
    std::vector<int> edge(static_cast<size_t>(free_chunks) + 1);
    for (int k = 0; k <= free_chunks; ++k) {
      int e = k * free_nodes / free_chunks;
      if (fixed > 0 && k > 0 && k < free_chunks) {
        const double graded = std::pow(static_cast<double>(k) / free_chunks, CoarseLayout::kFreeChunkGrading);
        e = std::clamp(static_cast<int>(std::lround(free_nodes * graded)),
                       edge[static_cast<size_t>(k) - 1] + 1, free_nodes - (free_chunks - k));
      }
      edge[static_cast<size_t>(k)] = e;
    }
    for (int a = 0; a < chunks; ++a) {
      const int f = a - (fixed > 0 ? 1 : 0);  // the chunk among the free ones (−1: the fixed one)
      const int begin = f < 0 ? first : first + fixed + edge[static_cast<size_t>(f)];
      const int end = f < 0 ? first + fixed : first + fixed + edge[static_cast<size_t>(f) + 1];
      const int points = std::min(layout.points_per_chunk, end - begin);
      chunk_first_point_.push_back(static_cast<int>(point_first_.size()));
      for (int q = 0; q < points; ++q) {
        point_first_.push_back(begin + q * (end - begin) / points);
        point_chunk_.push_back(static_cast<int>(chunk_first_.size()));
      }
      chunk_first_.push_back(begin);
      chunk_rod_.push_back(static_cast<int>(r));
    }
  }
  const int nc = static_cast<int>(chunk_first_.size());
  const int np = static_cast<int>(point_first_.size());
  const int m = rods.empty() ? 0 : rods.back().node_offset + static_cast<int>(rods.back().x->cols());
  chunk_first_.push_back(m);
  chunk_first_point_.push_back(np);
  point_first_.push_back(m);
  rod_first_chunk_.push_back(nc);
  rod_first_node_.push_back(m);
  return layout.turns ? BuildWith<6>(rods, blocks) : BuildWith<3>(rods, blocks);
}

template <int K>
bool CoarseLevel::BuildWith(const std::vector<CoarseRod>& rods, const std::vector<MatX>& blocks) {
  using Block = Eigen::Matrix<double, 3, K>;
  const double scale = scale_;
  const int nc = num_chunks(), np = static_cast<int>(point_first_.size()) - 1, m = chunk_first_.back();
  // Nodes (3 × M, and by rows for the vectorized sums), centroids of chunks and of points.
  NodeRows x(3, m);
  for (const CoarseRod& rod : rods) x.middleCols(rod.node_offset, rod.x->cols()) = *rod.x;
  centroids_.resize(3, nc);
  chunk_radius_.resize(nc);
  arms_.resize(3, m);
  for (int b = 0; b < nc; ++b) {
    const int begin = chunk_first_[static_cast<size_t>(b)], end = chunk_first_[static_cast<size_t>(b) + 1];
    centroids_.col(b) = x.middleCols(begin, end - begin).rowwise().mean();
    const double radius = std::sqrt(
        (x.middleCols(begin, end - begin).colwise() - centroids_.col(b)).squaredNorm() / (end - begin));
    chunk_radius_(b) = radius > 0.0 ? radius : 1.0;  // one node: no turn at all, any length
    for (int i = begin; i < end; ++i) arms_.col(i) = (x.col(i) - centroids_.col(b)) / chunk_radius_(b);
  }
  points_.resize(3, np);
  point_arms_.resize(3, np);
  point_nodes_.resize(np);
  point_eps_.resize(np);
  std::vector<Block> point_modes(static_cast<size_t>(np));  // scale N_s Z((Y_s − X_b) / ρ_b)
  for (int s = 0; s < np; ++s) {
    const int begin = point_first_[static_cast<size_t>(s)], end = point_first_[static_cast<size_t>(s) + 1];
    const int b = point_chunk_[static_cast<size_t>(s)];
    point_nodes_(s) = end - begin;
    points_.col(s) = x.middleCols(begin, end - begin).rowwise().mean();
    point_eps_(s) = rods[static_cast<size_t>(chunk_rod_[static_cast<size_t>(b)])].eps;
    point_arms_.col(s) = (points_.col(s) - centroids_.col(b)) / chunk_radius_(b);
    point_modes[static_cast<size_t>(s)] = (scale * point_nodes_(s)) * ModesAt<K>(point_arms_.col(s));
  }

  // Within a rod: D_k Z_k, the block's columns combined over each chunk's nodes.
  std::vector<MatX> own(rods.size());  // in double until E is formed; own_ keeps it in single
  for (std::size_t r = 0; r < rods.size(); ++r) {
    const int first = rods[r].node_offset, n = static_cast<int>(rods[r].x->cols());
    const int c0 = rod_first_chunk_[r], chunks = rod_first_chunk_[r + 1] - c0;
    own[r].setZero(3 * n, K * chunks);
    for (int a = 0; a < chunks; ++a)
      for (int j = chunk_first_[static_cast<size_t>(c0 + a)]; j < chunk_first_[static_cast<size_t>(c0 + a) + 1]; ++j) {
        own[r].middleCols<3>(K * a) += blocks[r].middleCols<3>(3 * (j - first));
        if constexpr (K == 6)
          own[r].middleCols<3>(K * a + 3) -= blocks[r].middleCols<3>(3 * (j - first)).lazyProduct(CrossMatrix(arms_.col(j)));
      }
  }

  // Between rods: the points' Stokeslets at the nodes (single precision, a preconditioner),
  // corrected to the nodes' own Stokeslets where a node is near the point.
  // Built with the preconditioner (kept up to 40 steps of ~4 GMRES products), applied once per
  // product: 40 Applies per Build is what a preconditioner rebuilt every 10 steps would see.
  // Summed directly below kCoarseDirectBelowPairs: on a hundred helices (800 points, 6500 nodes,
  // 5.2 M pairs) the FMM's model put its tree at 0.92 of the direct sum's cost, and alone
  // (bench_stokeslet_sum BM_CentroidSum) the two took 1.19 and 1.20 ms, but within a step, where
  // its translations come from memory at every application, 1.78 against 1.25 ms (one thread,
  // session 35). Above, the model decides (not measured beyond a hundred helices).
  between_ = MakeFastStokesletSum({.tolerance = 1e-3,
                                   .direct_below_pairs = kCoarseDirectBelowPairs,
                                   .applies_per_build = 40.0});
  between_->Build(points_, point_eps_, Matrix3X(x));
  FindNearPoints<K>(x);

  // E = Zᵀ W: W's rows combined over each chunk a (Zᵀ = [I] or [I; [x_i − X_a]× / ρ_a] per node), each
  // block in double and kept in single precision (what its LU takes; a double E of a hundred
  // helices is 46 MB fresh at every rebuild). Row by row: within a rod the exact own blocks;
  // between rods chunk a's nodes against every point at once (SumChunkAtPoints; one call per
  // pair of chunks, as before 2026-11-28, took 92–121 ms of a rebuild on a hundred helices,
  // 2400 × 2400, one thread, against 40–58 ms, and 23–37 against 10–16 ms on fifty, alternated
  // in one sitting). With turns, Σ_i [d_i]× S_i = Σ_k [e_k]× (Σ_i d_ik S_i) from the moments.
  Eigen::MatrixXf e(K * nc, K * nc);  // every block is written below
  const NodeRows point_rows = points_;
  const VecX point_e2 = point_eps_.cwiseProduct(point_eps_);
#pragma omp parallel
  {
    MatX sums(np, K == 6 ? 28 : 7);  // per point s, the sums over a's nodes (and moments)
#pragma omp for schedule(dynamic, 4)
    for (int a = 0; a < nc; ++a) {
      const int rod_a = chunk_rod_[static_cast<size_t>(a)];
      const int begin = chunk_first_[static_cast<size_t>(a)], end = chunk_first_[static_cast<size_t>(a) + 1];
      const int first = rods[static_cast<size_t>(rod_a)].node_offset;
      const int own_first = rod_first_chunk_[static_cast<size_t>(rod_a)];
      const int own_end = rod_first_chunk_[static_cast<size_t>(rod_a) + 1];
      SumChunkAtPoints(x.row(0).data() + begin, x.row(1).data() + begin, x.row(2).data() + begin,
                       end - begin, point_rows.row(0).data(), point_rows.row(1).data(),
                       point_rows.row(2).data(), point_e2.data(), np,
                       K == 6 ? centroids_.col(a).data() : nullptr, sums.data());
      for (int b = 0; b < nc; ++b) {
        Eigen::Matrix<double, K, K> block = Eigen::Matrix<double, K, K>::Zero();
        if (b >= own_first && b < own_end) {
          for (int i = begin; i < end; ++i)
            block += ModesTransposedTimes<K>(
                arms_.col(i), own[static_cast<size_t>(rod_a)].block<3, K>(3 * (i - first), K * (b - own_first)));
        } else {
          for (int s = chunk_first_point_[static_cast<size_t>(b)]; s < chunk_first_point_[static_cast<size_t>(b) + 1]; ++s) {
            double t[7];
            for (int k = 0; k < 7; ++k) t[k] = sums(s, k);
            Eigen::Matrix<double, K, 3> zs;
            zs.template topRows<3>() = StokesletMatrix(t);
            if constexpr (K == 6) {
              zs.template bottomRows<3>().setZero();
              for (int d = 0; d < 3; ++d) {
                for (int k = 0; k < 7; ++k) t[k] = sums(s, 7 + 7 * d + k);
                zs.template bottomRows<3>() += CrossMatrix(Vec3::Unit(d)) * StokesletMatrix(t);
              }
              zs.template bottomRows<3>() /= chunk_radius_(a);  // the moments of x_i − X_a
            }
            block += zs * point_modes[static_cast<size_t>(s)];
          }
        }
        PutBlock<K>(block, a, b, &e);
      }
    }
  }
  for (int i = 0, a = 0; i < m; ++i) {  // W's corrections near points (added in single precision)
    while (i >= chunk_first_[static_cast<size_t>(a) + 1]) ++a;
    for (int k = near_start_[static_cast<size_t>(i)]; k < near_start_[static_cast<size_t>(i) + 1]; ++k) {
      const int b = point_chunk_[static_cast<size_t>(near_point_[static_cast<size_t>(k)])];
      const Eigen::Map<const Block> near(near_block_.data() + 3 * K * static_cast<std::ptrdiff_t>(k));
      e.block<K, K>(K * a, K * b) += ModesTransposedTimes<K>(arms_.col(i), near).template cast<float>();
    }
  }
  if constexpr (K == 6) {
    // A chunk whose nodes lie on a line (a straight rod) cannot turn about that line: Z's column
    // is zero, and so are E's row and column. τ on each turn's diagonal, a thousandth of the
    // chunk's force diagonal, keeps E regular; it leaves such a turn at zero (its right-hand side
    // Zᵀ r is zero too) and the others changed by ~1e-3 (the turns are scaled by the chunk's
    // radius, so both diagonals are of a size).
    for (int a = 0; a < nc; ++a) {
      const float tau = kTurnRegularization * (e(6 * a, 6 * a) + e(6 * a + 1, 6 * a + 1) + e(6 * a + 2, 6 * a + 2)) / 3.0f;
      for (int k = 3; k < 6; ++k) e(6 * a + k, 6 * a + k) += tau;
    }
  }
  const bool regular = lu_.Compute(std::move(e), LuStorage::kHalf);

  // between_ sums every point, the own rod's too: take the own points' Stokeslets out of own
  // (after E, which has the exact own blocks), so that W c = own c_k + between_.
  for (std::size_t r = 0; r < rods.size(); ++r) {
    const int first = rods[r].node_offset, n = static_cast<int>(rods[r].x->cols());
    const int c0 = rod_first_chunk_[r];
    for (int s = chunk_first_point_[static_cast<size_t>(c0)]; s < chunk_first_point_[static_cast<size_t>(rod_first_chunk_[r + 1])]; ++s) {
      const int b = point_chunk_[static_cast<size_t>(s)];
      for (int i = 0; i < n; ++i) {
        double t[7];
        SumPointStokeslets(x.row(0).data() + first + i, x.row(1).data() + first + i,
                           x.row(2).data() + first + i, point_eps_(s) * point_eps_(s), 1,
                           points_.col(s).data(), t);
        own[r].block<3, K>(3 * i, K * (b - c0)) -= StokesletMatrix(t) * point_modes[static_cast<size_t>(s)];
      }
    }
  }
  // Applied in single precision with double sums (GemvRowsMixed): half the bytes per product.
  own_.assign(rods.size(), Eigen::MatrixXf());
  for (std::size_t r = 0; r < rods.size(); ++r) own_[r] = own[r].cast<float>();
  return regular;
}

template <int K>
void CoarseLevel::FindNearPoints(const NodeRows& x) {
  using Block = Eigen::Matrix<double, 3, K>;
  const int np = static_cast<int>(point_first_.size()) - 1, m = chunk_first_.back();
  VecX reach2(np);  // (kNearReach × the point's radius about its centroid)²
  for (int s = 0; s < np; ++s) {
    double radius2 = 0.0;
    for (int j = point_first_[static_cast<size_t>(s)]; j < point_first_[static_cast<size_t>(s) + 1]; ++j)
      radius2 = std::max(radius2, (Vec3(x.col(j)) - points_.col(s)).squaredNorm());
    reach2(s) = kNearReach * kNearReach * radius2;
  }
  // Node by node over the threads (each node's entries in point order), then joined in node
  // order: the same lists on any number of threads.
  std::vector<std::vector<int>> node_points(static_cast<size_t>(m));
  std::vector<std::vector<double>> node_blocks(static_cast<size_t>(m));
#pragma omp parallel for schedule(dynamic, 64)
  for (int i = 0; i < m; ++i) {
    const int rod = static_cast<int>(std::upper_bound(rod_first_node_.begin(), rod_first_node_.end(), i) -
                                     rod_first_node_.begin()) - 1;
    const Vec3 p = x.col(i);
    for (int s = 0; s < np; ++s) {
      const int b = point_chunk_[static_cast<size_t>(s)];
      if (chunk_rod_[static_cast<size_t>(b)] == rod || (p - points_.col(s)).squaredNorm() >= reach2(s))
        continue;
      // scale (Σ_j S(x_i − x_j) Z_j − N_s S(x_i − Y_s) Z_s) over the point's nodes j, Z at the
      // arms of x_j and Y_s (with forces alone Z = I: the nodes' Stokeslets summed at once).
      const int begin = point_first_[static_cast<size_t>(s)], end = point_first_[static_cast<size_t>(s) + 1];
      const double e2 = point_eps_(s) * point_eps_(s);
      Block block;
      double t[7];
      if constexpr (K == 6) {
        block.setZero();
        for (int j = begin; j < end; ++j) {
          SumPointStokeslets(x.row(0).data() + j, x.row(1).data() + j, x.row(2).data() + j, e2, 1,
                             p.data(), t);
          block += StokesletMatrix(t) * ModesAt<K>(arms_.col(j));
        }
      } else {
        SumPointStokeslets(x.row(0).data() + begin, x.row(1).data() + begin, x.row(2).data() + begin,
                           e2, end - begin, p.data(), t);
        block = StokesletMatrix(t);
      }
      const double* ys = points_.col(s).data();
      SumPointStokeslets(ys, ys + 1, ys + 2, e2, 1, p.data(), t);
      block -= point_nodes_(s) * StokesletMatrix(t) * ModesAt<K>(point_arms_.col(s));
      block *= scale_;
      node_points[static_cast<size_t>(i)].push_back(s);
      node_blocks[static_cast<size_t>(i)].insert(node_blocks[static_cast<size_t>(i)].end(), block.data(),
                                                 block.data() + block.size());
    }
  }
  near_start_.assign(1, 0);
  near_point_.clear();
  near_block_.clear();
  for (int i = 0; i < m; ++i) {
    near_point_.insert(near_point_.end(), node_points[static_cast<size_t>(i)].begin(),
                       node_points[static_cast<size_t>(i)].end());
    near_block_.insert(near_block_.end(), node_blocks[static_cast<size_t>(i)].begin(),
                       node_blocks[static_cast<size_t>(i)].end());
    near_start_.push_back(static_cast<int>(near_point_.size()));
  }
}

VecX CoarseLevel::Solve(const VecX& v) const {
  const int modes = layout_.modes();
  const int nc = num_chunks();
  VecX zv = VecX::Zero(modes * nc);
  for (int a = 0; a < nc; ++a)
    for (int i = chunk_first_[static_cast<size_t>(a)]; i < chunk_first_[static_cast<size_t>(a) + 1]; ++i) {
      const Vec3 vi = v.segment<3>(3 * i);
      zv.segment<3>(modes * a) += vi;
      if (layout_.turns) zv.segment<3>(modes * a + 3) += Vec3(arms_.col(i)).cross(vi);
    }
  Eigen::VectorXf c = zv.cast<float>();
  lu_.Solve(&c);
  return c.cast<double>();
}

void CoarseLevel::ApplyW(const VecX& c, VecX* out) const {
  const int modes = layout_.modes();
  const int np = static_cast<int>(point_first_.size()) - 1, m = chunk_first_.back();
  strengths_.resize(3, np);
  for (int s = 0; s < np; ++s) {
    const int b = point_chunk_[static_cast<size_t>(s)];
    Vec3 force = c.segment<3>(modes * b);
    if (layout_.turns) force += c.segment<3>(modes * b + 3).cross(point_arms_.col(s));
    strengths_.col(s) = (scale_ * point_nodes_(s)) * force;
  }
  between_->Apply(strengths_, &velocity_);  // every point, its own rod's too
  out->resize(3 * m);
  const int num_rods = static_cast<int>(own_.size());
  ForEachStatic(num_rods, num_rods > 1, [&](int r) {
    const int first = rod_first_node_[static_cast<size_t>(r)];
    const int n = rod_first_node_[static_cast<size_t>(r) + 1] - first;
    const int c0 = rod_first_chunk_[static_cast<size_t>(r)];
    const int chunks = rod_first_chunk_[static_cast<size_t>(r) + 1] - c0;
    const Eigen::MatrixXf& own = own_[static_cast<size_t>(r)];
    SR_ASSERT(own.cols() == modes * chunks, "the coarse level's own block does not match its chunks");
    GemvRowsMixed(own, 0, 3 * n, c.data() + modes * c0, out->data() + 3 * first);
    for (int i = first; i < first + n; ++i) {
      Vec3 u = velocity_.col(i);
      for (int k = near_start_[static_cast<size_t>(i)]; k < near_start_[static_cast<size_t>(i) + 1]; ++k) {
        const int b = point_chunk_[static_cast<size_t>(near_point_[static_cast<size_t>(k)])];
        const double* block = near_block_.data() + 3 * modes * static_cast<std::ptrdiff_t>(k);
        if (layout_.turns)
          u += Eigen::Map<const Eigen::Matrix<double, 3, 6>>(block) * c.segment<6>(6 * b);
        else
          u += Eigen::Map<const Mat3>(block) * c.segment<3>(3 * b);
      }
      out->segment<3>(3 * i) += u;
    }
  });
}

void CoarseLevel::AddZ(const VecX& c, VecX* out) const {
  const int modes = layout_.modes();
  for (int a = 0; a < num_chunks(); ++a)
    for (int i = chunk_first_[static_cast<size_t>(a)]; i < chunk_first_[static_cast<size_t>(a) + 1]; ++i) {
      out->segment<3>(3 * i) += c.segment<3>(modes * a);
      if (layout_.turns)
        out->segment<3>(3 * i) += c.segment<3>(modes * a + 3).cross(Vec3(arms_.col(i)));
    }
}

}  // namespace stokesrods
