#include "stokesrods/fluid/fmm_operators.h"

#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <utility>

#include "stokesrods/common/assert.h"
#include "stokesrods/fluid/point_stokeslet.h"
#include "stokesrods/fluid/stokeslet_segment.h"
#include "stokesrods/solver/dense_spectral.h"

namespace stokesrods {
namespace {

/// The points of the m × m × m grid of [−1, 1]³ on the cube's surface.
Matrix3X CubeSurface(int m) {
  std::vector<Vec3> points;
  const double step = 2.0 / (m - 1);
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j)
      for (int k = 0; k < m; ++k)
        if (i == 0 || j == 0 || k == 0 || i == m - 1 || j == m - 1 || k == m - 1)
          points.emplace_back(-1.0 + step * i, -1.0 + step * j, -1.0 + step * k);
  Matrix3X out(3, static_cast<Eigen::Index>(points.size()));
  for (std::size_t c = 0; c < points.size(); ++c) out.col(static_cast<Eigen::Index>(c)) = points[c];
  return out;
}

/// [S(x_i − y_j)] (3|X| × 3|Y|), singular Stokeslets; X and Y disjoint.
MatX KernelMatrix(const Matrix3X& x, const Matrix3X& y) {
  MatX k(3 * x.cols(), 3 * y.cols());
  for (Eigen::Index j = 0; j < y.cols(); ++j)
    for (Eigen::Index i = 0; i < x.cols(); ++i)
      k.block<3, 3>(3 * i, 3 * j) = StokesletMatrix(x.col(i) - y.col(j));
  return k;
}

std::unique_ptr<FmmOperators> MakeOperators(int order, double cutoff) {
  auto op = std::make_unique<FmmOperators>();
  op->order = order;
  op->cutoff = cutoff;
  op->surface = CubeSurface(order);
  op->points = static_cast<int>(op->surface.cols());
  const Matrix3X inner = kFmmInnerRadius * op->surface, outer = kFmmOuterRadius * op->surface;
  op->check_to_up = PseudoInverse(KernelMatrix(outer, inner), cutoff);
  op->check_to_down = PseudoInverse(KernelMatrix(inner, outer), cutoff);
  for (int c = 0; c < 8; ++c) {
    // Child c's centre in the parent's units (bit 2: +x, bit 1: +y, bit 0: +z).
    const Vec3 o(c & 4 ? 0.25 : -0.25, c & 2 ? 0.25 : -0.25, c & 1 ? 0.25 : -0.25);
    const Matrix3X child_inner = (0.5 * inner).colwise() + o;
    op->m2m[static_cast<size_t>(c)] = op->check_to_up * KernelMatrix(outer, child_inner);
    const Matrix3X parent_outer = (2.0 * outer).colwise() - 2.0 * o;  // in the child's units
    op->l2l[static_cast<size_t>(c)] = op->check_to_down * KernelMatrix(inner, parent_outer);
  }
  for (std::size_t c = 0; c < 8; ++c) {
    op->m2m_single[c] = op->m2m[c].cast<float>();
    op->l2l_single[c] = op->l2l[c].cast<float>();
  }
  return op;
}

/// The sources of AddM2l (S × 7, point_stokeslet.h): n equivalent Stokeslets per V-list entry at
/// its box's surface r_in around the offset v, then zero-strength padding to whole blocks of
/// kPointSumBlock (at the last source, ε² = 1).
template <class Matrix>
void FillM2lSources(const FmmOperators& op, const int* boxes, const int* offsets, int count,
                    const MatX& up, Matrix* src) {
  const int n = op.points;
  const Eigen::Index used = static_cast<Eigen::Index>(count) * n;
  const Eigen::Index rows = (used + kPointSumBlock - 1) / kPointSumBlock * kPointSumBlock;
  src->resize(rows, 7);
  using T = typename Matrix::Scalar;
  for (int e = 0; e < count; ++e) {
    const int o = offsets[e];
    const Vec3 v(o / 49 - 3, o / 7 % 7 - 3, o % 7 - 3);
    const double* g = up.col(boxes[e]).data();
    for (int j = 0; j < n; ++j) {
      const Eigen::Index row = static_cast<Eigen::Index>(e) * n + j;
      const Vec3 y = kFmmInnerRadius * op.surface.col(j) + v;
      for (int d = 0; d < 3; ++d) {
        (*src)(row, d) = static_cast<T>(y[d]);
        (*src)(row, 4 + d) = static_cast<T>(g[3 * j + d]);
      }
      (*src)(row, 3) = T(0);
    }
  }
  for (Eigen::Index row = used; row < rows; ++row) {
    src->row(row).template head<3>() = src->row(used - 1).template head<3>();
    (*src)(row, 3) = T(1);
    src->row(row).template tail<3>().setZero();
  }
}

}  // namespace

void AddM2l(const FmmOperators& op, const int* boxes, const int* offsets, int count,
            const MatX& up, bool single, M2lScratch* scratch, double* check) {
  if (count == 0) return;
  const int n = op.points;
  if (single) {
    FillM2lSources(op, boxes, offsets, count, up, &scratch->sources_single);
    const SourceColumnsF c = ColumnsF(scratch->sources_single);
    const SourceRange all{0, static_cast<int>(scratch->sources_single.rows())};
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector3f x = (kFmmInnerRadius * op.surface.col(i)).cast<float>();
      AddPointSumBlocks(c, &all, 1, x.data(), check + 3 * i);
    }
    return;
  }
  FillM2lSources(op, boxes, offsets, count, up, &scratch->sources);
  const SourceColumns c = Columns(scratch->sources);
  for (int i = 0; i < n; ++i) {
    const Vec3 x = kFmmInnerRadius * op.surface.col(i);
    AddPointSum(c, 0, scratch->sources.rows(), x.data(), check + 3 * i);
  }
}

const FmmOperators& GetFmmOperators(int order, double cutoff) {
  SR_ASSERT(order >= 2 && order <= 12, "FMM order out of range");
  static std::mutex mutex;
  static std::map<std::pair<int, double>, std::unique_ptr<FmmOperators>> cache;
  const std::lock_guard<std::mutex> lock(mutex);
  auto& entry = cache[{order, cutoff}];
  if (!entry) entry = MakeOperators(order, cutoff);
  return *entry;
}

}  // namespace stokesrods
