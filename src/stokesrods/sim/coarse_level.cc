#include "stokesrods/sim/coarse_level.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "stokesrods/common/assert.h"
#include "stokesrods/solver/blas.h"

namespace stokesrods {

namespace {

// t[k np + j], k < 7: over the n nodes (xs, ys, zs), Σ_i of (1/R + ε²/R³, then r rᵀ/R³ as xx,
// xy, xz, yy, yz, zz), r = p_j − x_i, R² = |r|² + ε_j², at each of the np points p_j = (px, py,
// pz)_j with its own ε_j² (e2): the point Stokeslets S_ε between a chunk of nodes and each point,
// summed over the chunk, all points at once (vectorized over the points).
__attribute__((target_clones("avx512f", "avx2", "default")))
void SumChunkAtPoints(const double* xs, const double* ys, const double* zs, int n,
                      const double* px, const double* py, const double* pz, const double* e2,
                      int np, double* t) {
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
}

// The same at one point p (x, y, z) with ε² = e2.
void SumPointStokeslets(const double* xs, const double* ys, const double* zs, double e2, int n,
                        const double* p, double t[7]) {
  SumChunkAtPoints(xs, ys, zs, n, p, p + 1, p + 2, &e2, 1, t);
}

// e's 3 × 3 block (3a, 3b) = m, in single precision (written out: Eigen's cast into a block of
// a column-major float matrix was slower, E of a hundred helices 44–60 against 35–43 ms).
void PutBlock(const Mat3& m, int a, int b, Eigen::MatrixXf* e) {
  float* column = e->data() + 3 * static_cast<std::ptrdiff_t>(b) * e->rows() + 3 * a;
  for (int c = 0; c < 3; ++c, column += e->rows())
    for (int r = 0; r < 3; ++r) column[r] = static_cast<float>(m(r, c));
}

Mat3 StokesletMatrix(const double t[7]) {
  Mat3 s;
  s << t[0] + t[1], t[2], t[3], t[2], t[0] + t[4], t[5], t[3], t[5], t[0] + t[6];
  return s;
}

}  // namespace

bool CoarseLevel::Build(const std::vector<CoarseRod>& rods, const std::vector<MatX>& blocks,
                        double scale) {
  SR_ASSERT(blocks.size() == rods.size(), "one block per rod");
  scale_ = scale;
  chunk_first_.clear();
  chunk_rod_.clear();
  rod_first_chunk_.clear();
  rod_first_node_.clear();
  for (std::size_t r = 0; r < rods.size(); ++r) {
    const int n = static_cast<int>(rods[r].x->cols()), first = rods[r].node_offset;
    const int chunks = std::min(kChunksPerRod, n);
    rod_first_chunk_.push_back(static_cast<int>(chunk_first_.size()));
    rod_first_node_.push_back(first);
    for (int a = 0; a < chunks; ++a) {
      chunk_first_.push_back(first + a * n / chunks);
      chunk_rod_.push_back(static_cast<int>(r));
    }
  }
  const int nc = static_cast<int>(chunk_first_.size());
  const int m = rods.empty() ? 0 : rods.back().node_offset + static_cast<int>(rods.back().x->cols());
  chunk_first_.push_back(m);
  rod_first_chunk_.push_back(nc);
  rod_first_node_.push_back(m);

  // Nodes (3 × M, and by rows for the vectorized sums), chunk centroids and sizes.
  NodeRows x(3, m);
  for (const CoarseRod& rod : rods) x.middleCols(rod.node_offset, rod.x->cols()) = *rod.x;
  Matrix3X centroids(3, nc);
  VecX chunk_eps(nc);
  chunk_nodes_.resize(nc);
  for (int b = 0; b < nc; ++b) {
    const int begin = chunk_first_[static_cast<size_t>(b)], end = chunk_first_[static_cast<size_t>(b) + 1];
    chunk_nodes_(b) = end - begin;
    centroids.col(b) = x.middleCols(begin, end - begin).rowwise().mean();
    chunk_eps(b) = rods[static_cast<size_t>(chunk_rod_[static_cast<size_t>(b)])].eps;
  }

  // Within a rod: D_k Z_k, the block's columns summed over each chunk.
  std::vector<MatX> own(rods.size());  // in double until E is formed; own_ keeps it in single
  for (std::size_t r = 0; r < rods.size(); ++r) {
    const int first = rods[r].node_offset, n = static_cast<int>(rods[r].x->cols());
    const int c0 = rod_first_chunk_[r], chunks = rod_first_chunk_[r + 1] - c0;
    own[r].setZero(3 * n, 3 * chunks);
    for (int a = 0; a < chunks; ++a)
      for (int j = chunk_first_[static_cast<size_t>(c0 + a)]; j < chunk_first_[static_cast<size_t>(c0 + a) + 1]; ++j)
        own[r].middleCols<3>(3 * a) += blocks[r].middleCols<3>(3 * (j - first));
  }

  // Between rods: the centroids' Stokeslets at the nodes (single precision, a preconditioner),
  // corrected to the nodes' own Stokeslets where a node is near the chunk.
  // Built with the preconditioner (kept up to 40 steps of ~4 GMRES products), applied once per
  // product: 40 Applies per Build is what a preconditioner rebuilt every 10 steps would see.
  between_ = MakeFastStokesletSum({.tolerance = 1e-3, .applies_per_build = 40.0});
  between_->Build(centroids, chunk_eps, Matrix3X(x));
  FindNearChunks(x, centroids, chunk_eps);

  // E = Zᵀ W: W's rows summed over each chunk a, each block in double and kept in single
  // precision (what its LU takes; a double E of a hundred helices is 46 MB fresh at every
  // rebuild). Row by row: within a rod the exact own blocks; between rods chunk a's nodes against
  // every centroid at once (SumChunkAtPoints; one call per pair of chunks, as before 2026-11-28,
  // took 92–121 ms of a rebuild on a hundred helices, 2400 × 2400, one thread, against 40–58 ms,
  // and 23–37 against 10–16 ms on fifty, alternated in one sitting).
  Eigen::MatrixXf e(3 * nc, 3 * nc);  // every block is written below
  const Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::RowMajor> centre_rows = centroids;
  const VecX chunk_e2 = chunk_eps.cwiseProduct(chunk_eps);
#pragma omp parallel
  {
    MatX sums(nc, 7);  // per centroid b, the seven sums over a's nodes
#pragma omp for schedule(dynamic, 4)
    for (int a = 0; a < nc; ++a) {
      const int rod_a = chunk_rod_[static_cast<size_t>(a)];
      const int begin = chunk_first_[static_cast<size_t>(a)], end = chunk_first_[static_cast<size_t>(a) + 1];
      const int first = rods[static_cast<size_t>(rod_a)].node_offset;
      const int own_first = rod_first_chunk_[static_cast<size_t>(rod_a)];
      const int own_end = rod_first_chunk_[static_cast<size_t>(rod_a) + 1];
      SumChunkAtPoints(x.row(0).data() + begin, x.row(1).data() + begin, x.row(2).data() + begin,
                       end - begin, centre_rows.row(0).data(), centre_rows.row(1).data(),
                       centre_rows.row(2).data(), chunk_e2.data(), nc, sums.data());
      for (int b = 0; b < nc; ++b) {
        Mat3 block = Mat3::Zero();
        if (b >= own_first && b < own_end) {
          for (int i = begin; i < end; ++i)
            block += own[static_cast<size_t>(rod_a)].block<3, 3>(3 * (i - first), 3 * (b - own_first));
        } else {
          const double t[7] = {sums(b, 0), sums(b, 1), sums(b, 2), sums(b, 3),
                               sums(b, 4), sums(b, 5), sums(b, 6)};
          block = (scale * chunk_nodes_(b)) * StokesletMatrix(t);
        }
        PutBlock(block, a, b, &e);
      }
    }
  }
  for (int i = 0, a = 0; i < m; ++i) {  // W's corrections near chunks (added in single precision)
    while (i >= chunk_first_[static_cast<size_t>(a) + 1]) ++a;
    for (int k = near_start_[static_cast<size_t>(i)]; k < near_start_[static_cast<size_t>(i) + 1]; ++k)
      e.block<3, 3>(3 * a, 3 * near_chunk_[static_cast<size_t>(k)]) += near_block_[static_cast<size_t>(k)].cast<float>();
  }
  const bool regular = lu_.Compute(std::move(e), LuStorage::kHalf);

  // between_ sums every chunk, the own rod's too: take the own centroids' Stokeslets out of own
  // (after E, which has the exact own blocks), so that W c = own c_k + between_.
  for (std::size_t r = 0; r < rods.size(); ++r) {
    const int first = rods[r].node_offset, n = static_cast<int>(rods[r].x->cols());
    const int c0 = rod_first_chunk_[r], chunks = rod_first_chunk_[r + 1] - c0;
    for (int i = 0; i < n; ++i)
      for (int a = 0; a < chunks; ++a) {
        const int b = c0 + a;
        double t[7];
        SumPointStokeslets(x.row(0).data() + first + i, x.row(1).data() + first + i,
                           x.row(2).data() + first + i, chunk_eps(b) * chunk_eps(b), 1,
                           centroids.col(b).data(), t);
        own[r].block<3, 3>(3 * i, 3 * a) -= (scale * chunk_nodes_(b)) * StokesletMatrix(t);
      }
  }
  // Applied in single precision with double sums (GemvRowsMixed): half the bytes per product.
  own_.assign(rods.size(), Eigen::MatrixXf());
  for (std::size_t r = 0; r < rods.size(); ++r) own_[r] = own[r].cast<float>();
  return regular;
}

void CoarseLevel::FindNearChunks(const NodeRows& x, const Matrix3X& centroids,
                                 const VecX& chunk_eps) {
  const int nc = num_chunks(), m = chunk_first_.back();
  VecX reach2(nc);  // (kNearReach × the chunk's radius about its centroid)²
  for (int b = 0; b < nc; ++b) {
    double radius2 = 0.0;
    for (int j = chunk_first_[static_cast<size_t>(b)]; j < chunk_first_[static_cast<size_t>(b) + 1]; ++j)
      radius2 = std::max(radius2, (Vec3(x.col(j)) - centroids.col(b)).squaredNorm());
    reach2(b) = kNearReach * kNearReach * radius2;
  }
  near_start_.assign(1, 0);
  near_chunk_.clear();
  near_block_.clear();
  int rod = 0;
  for (int i = 0; i < m; ++i) {
    while (i >= rod_first_node_[static_cast<size_t>(rod) + 1]) ++rod;
    const Vec3 p = x.col(i);
    for (int b = 0; b < nc; ++b) {
      if (chunk_rod_[static_cast<size_t>(b)] == rod || (p - centroids.col(b)).squaredNorm() >= reach2(b))
        continue;
      const int begin = chunk_first_[static_cast<size_t>(b)], end = chunk_first_[static_cast<size_t>(b) + 1];
      const double e2 = chunk_eps(b) * chunk_eps(b);
      double nodes[7], centroid[7];
      SumPointStokeslets(x.row(0).data() + begin, x.row(1).data() + begin, x.row(2).data() + begin,
                         e2, end - begin, p.data(), nodes);
      const double* xb = centroids.col(b).data();
      SumPointStokeslets(xb, xb + 1, xb + 2, e2, 1, p.data(), centroid);
      near_chunk_.push_back(b);
      near_block_.push_back(scale_ * (StokesletMatrix(nodes) - chunk_nodes_(b) * StokesletMatrix(centroid)));
    }
    near_start_.push_back(static_cast<int>(near_chunk_.size()));
  }
}

VecX CoarseLevel::Solve(const VecX& v) const {
  const int nc = num_chunks();
  VecX zv = VecX::Zero(3 * nc);
  for (int a = 0; a < nc; ++a)
    for (int i = chunk_first_[static_cast<size_t>(a)]; i < chunk_first_[static_cast<size_t>(a) + 1]; ++i)
      zv.segment<3>(3 * a) += v.segment<3>(3 * i);
  Eigen::VectorXf c = zv.cast<float>();
  lu_.Solve(&c);
  return c.cast<double>();
}

void CoarseLevel::ApplyW(const VecX& c, VecX* out) const {
  const int nc = num_chunks(), m = chunk_first_.back();
  strengths_.resize(3, nc);
  for (int b = 0; b < nc; ++b) strengths_.col(b) = (scale_ * chunk_nodes_(b)) * c.segment<3>(3 * b);
  between_->Apply(strengths_, &velocity_);  // every chunk, its own rod's too
  out->resize(3 * m);
  const int num_rods = static_cast<int>(own_.size());
#pragma omp parallel for schedule(static) if (num_rods > 1)
  for (int r = 0; r < num_rods; ++r) {
    const int first = rod_first_node_[static_cast<size_t>(r)];
    const int n = rod_first_node_[static_cast<size_t>(r) + 1] - first;
    const int c0 = rod_first_chunk_[static_cast<size_t>(r)];
    const int chunks = rod_first_chunk_[static_cast<size_t>(r) + 1] - c0;
    const Eigen::MatrixXf& own = own_[static_cast<size_t>(r)];
    SR_ASSERT(own.cols() == 3 * chunks, "the coarse level's own block does not match its chunks");
    GemvRowsMixed(own, 0, 3 * n, c.data() + 3 * c0, out->data() + 3 * first);
    for (int i = first; i < first + n; ++i) {
      Vec3 u = velocity_.col(i);
      for (int k = near_start_[static_cast<size_t>(i)]; k < near_start_[static_cast<size_t>(i) + 1]; ++k)
        u += near_block_[static_cast<size_t>(k)] * c.segment<3>(3 * near_chunk_[static_cast<size_t>(k)]);
      out->segment<3>(3 * i) += u;
    }
  }
}

void CoarseLevel::AddZ(const VecX& c, VecX* out) const {
  for (int a = 0; a < num_chunks(); ++a)
    for (int i = chunk_first_[static_cast<size_t>(a)]; i < chunk_first_[static_cast<size_t>(a) + 1]; ++i)
      out->segment<3>(3 * i) += c.segment<3>(3 * a);
}

}  // namespace stokesrods
