// The fast sum (the FMM of fluid/fmm_sum.cc) against the direct sum: random clouds and the helix
// lattice of bench/bench_stokeslet_sum.cc at the tolerances of each expansion order, the
// regularization (targets on sources, mixed and large ε), and the edge cases (empty, coincident
// and single points, targets far from the sources, collinear points, six decades of distance).
#include "common/helix_lattice.h"
#include "stokesrods/fluid/stokeslet_sum.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "stokesrods/fluid/point_stokeslet.h"
#include "stokesrods/fluid/stokeslet_segment.h"

namespace stokesrods {
namespace {

using Cloud = testing::PointCloud;

Matrix3X RandomStrengths(int n, std::mt19937* rng) {
  std::normal_distribution<double> normal;
  Matrix3X g(3, n);
  for (int k = 0; k < n; ++k) g.col(k) = Vec3(normal(*rng), normal(*rng), normal(*rng));
  return g;
}

Cloud RandomCloud(int ns, int nt, double size, double eps, std::mt19937* rng) {
  std::uniform_real_distribution<double> unit(0.0, size);
  Cloud c;
  c.sources.resize(3, ns);
  c.targets.resize(3, nt);
  for (int k = 0; k < ns; ++k) c.sources.col(k) = Vec3(unit(*rng), unit(*rng), unit(*rng));
  for (int k = 0; k < nt; ++k) c.targets.col(k) = Vec3(unit(*rng), unit(*rng), unit(*rng));
  c.regularization = VecX::Constant(ns, eps);
  return c;
}

using testing::HelixLattice;

struct Result {
  double error = 0.0;
  StokesletSumStats stats;
};

Result Compare(const Cloud& c, StokesletSumOptions options, std::mt19937* rng) {
  auto direct = MakeDirectStokesletSum();
  auto fast = MakeFastStokesletSum(options);
  direct->Build(c.sources, c.regularization, c.targets);
  fast->Build(c.sources, c.regularization, c.targets);
  const Matrix3X g = RandomStrengths(static_cast<int>(c.sources.cols()), rng);
  Matrix3X w, ref;
  direct->Apply(g, &ref);
  fast->Apply(g, &w);
  EXPECT_TRUE(w.allFinite());
  Matrix3X w2;  // Apply is repeatable (the scratch is reset)
  fast->Apply(g, &w2);
  EXPECT_TRUE(w == w2) << "Apply is not repeatable";
  const StokesletSumStats stats = fast->Stats();
  EXPECT_EQ(stats.near_pairs + stats.far_pairs, c.sources.cols() * c.targets.cols());
  return {testing::StokesletSumError(c, g, w, ref), fast->Stats()};
}

TEST(StokesletSumTest, DirectSumMatchesTheKernel) {
  std::mt19937 rng(1);
  Cloud c = RandomCloud(7, 5, 1.0, 0.1, &rng);
  c.regularization[3] = 0.3;
  c.targets.col(2) = c.sources.col(4);  // a target on a source: S_ε(0) = (2/ε) I
  const Matrix3X g = RandomStrengths(7, &rng);
  auto direct = MakeDirectStokesletSum();
  direct->Build(c.sources, c.regularization, c.targets);
  Matrix3X w;
  direct->Apply(g, &w);
  for (int t = 0; t < 5; ++t) {
    Vec3 ref = Vec3::Zero();
    for (int s = 0; s < 7; ++s)
      ref += RegularizedStokesletMatrix(c.targets.col(t) - c.sources.col(s), c.regularization[s]) *
             g.col(s);
    EXPECT_LT((w.col(t) - ref).norm(), 1e-14 * ref.norm()) << t;
  }
}

// The tolerances at which the order changes (fmm_sum.cc: p = 4, 5, 6); forced to use the tree.
constexpr double kTolerances[] = {1e-4, 2.1e-5, 1.25e-6};

StokesletSumOptions Forced(double tolerance) {
  return {.tolerance = tolerance, .direct_below_pairs = 0, .choose_by_cost = false};
}

TEST(StokesletSumTest, RandomCloudsMeetTheTolerance) {
  std::mt19937 rng(2);
  const Cloud c = RandomCloud(6000, 3000, 1.0, 1e-4, &rng);
  for (double tol : kTolerances) {
    const Result r = Compare(c, Forced(tol), &rng);
    std::printf("random cloud, tolerance %.2g: error %.2e, far pairs %lld, 3n %d\n", tol, r.error,
                static_cast<long long>(r.stats.far_pairs), r.stats.max_rank);
    EXPECT_LT(r.error, tol) << tol;
    EXPECT_GT(r.error, 1e-3 * tol) << "suspiciously exact: " << tol;
    EXPECT_GT(r.stats.far_pairs, r.stats.near_pairs) << tol;
  }
}

TEST(StokesletSumTest, HelixLatticeMeetsTheTolerance) {
  std::mt19937 rng(3);
  const Cloud c = HelixLattice(4, 5);  // 20 helices: 2560 sources, 1300 targets
  for (double tol : kTolerances) {
    const Result r = Compare(c, Forced(tol), &rng);
    std::printf("20 helices, tolerance %.2g: error %.2e, far pairs %lld\n", tol, r.error,
                static_cast<long long>(r.stats.far_pairs));
    EXPECT_LT(r.error, tol) << tol;
    EXPECT_GT(r.error, 1e-3 * tol) << tol;
    EXPECT_GT(r.stats.far_pairs, 0) << tol;
  }
}

// By cost, the root cube of 50 helices (6400 sources × 3250 targets) is wider than the points
// (fmm_tree.cc: extent × 2^(k/4)): its leaves leave 5.7 M near pairs where the root of side
// `extent` left 12.0 M (and 8.8 M far), and the sum still meets the tolerance.
TEST(StokesletSumTest, ChoosesTheRootWidthByCostAndMeetsTheTolerance) {
  std::mt19937 rng(10);
  const Cloud c = HelixLattice(5, 10);
  const Result r = Compare(c, {.tolerance = 1e-4, .direct_below_pairs = 0}, &rng);
  std::printf("50 helices by cost: error %.2e, near pairs %lld, far pairs %lld\n", r.error,
              static_cast<long long>(r.stats.near_pairs), static_cast<long long>(r.stats.far_pairs));
  EXPECT_LT(r.error, 1e-4);
  EXPECT_GT(r.error, 1e-7);
  EXPECT_LT(r.stats.near_pairs, 8'000'000);
}

TEST(StokesletSumTest, BelowTheReachOfTheExpansionsSumsDirectly) {
  std::mt19937 rng(8);
  const Cloud c = HelixLattice(2, 5);
  const Result r = Compare(c, Forced(1e-6), &rng);  // no order reaches 1e-6
  EXPECT_EQ(r.stats.far_pairs, 0);
  EXPECT_LT(r.error, 1e-15);
}

TEST(StokesletSumTest, SumsDirectlyWhenTheTreeDoesNotPay) {
  std::mt19937 rng(9);
  const Cloud c = HelixLattice(2, 5);  // 1280 × 650 pairs: the cost model prefers the direct sum
  const Result r = Compare(c, {.tolerance = 1e-4, .direct_below_pairs = 0}, &rng);
  EXPECT_EQ(r.stats.far_pairs, 0);
}

// The tree's Build is charged to the Applies it serves: the preconditioner's coarse sum (8 points
// per helix at the nodes of 100 helices, tolerance 1e-3), whose tree saves ~15 % of an Apply and
// costs ~half an Apply to build, sums directly when built for one Apply and takes the tree when
// built for 40 (its estimate: 0.82 of the pairs per Apply, plus 0.49 or 0.012 for the Build).
TEST(StokesletSumTest, TheBuildsShareDecidesWhetherTheTreePays) {
  std::mt19937 rng(10);
  const Cloud lattice = HelixLattice(10, 10);
  Cloud c;
  c.targets = lattice.targets;
  c.sources.resize(3, lattice.sources.cols() / 16);
  for (Eigen::Index k = 0; k < c.sources.cols(); ++k) c.sources.col(k) = lattice.sources.col(16 * k);
  c.regularization = VecX::Constant(c.sources.cols(), lattice.regularization(0));
  const Result once = Compare(c, {.tolerance = 1e-3, .applies_per_build = 1.0}, &rng);
  const Result many = Compare(c, {.tolerance = 1e-3, .applies_per_build = 40.0}, &rng);
  EXPECT_EQ(once.stats.far_pairs, 0);
  EXPECT_GT(many.stats.far_pairs, 0);
  EXPECT_LT(many.error, 1e-3);
}

TEST(StokesletSumTest, MixedRegularizationAndTargetsOnSources) {
  std::mt19937 rng(4);
  Cloud c = RandomCloud(3000, 2000, 1.0, 1e-3, &rng);
  std::uniform_real_distribution<double> eps(1e-3, 2e-2);
  for (int s = 0; s < c.sources.cols(); ++s) c.regularization[s] = eps(rng);
  for (int t = 0; t < 1000; ++t) c.targets.col(t) = c.sources.col(3 * t);
  // Leaves at least ε_max (2/tol)^¼ = 0.24 wide: depth 2 (0.25) is the only one allowed.
  const Result r = Compare(c, Forced(1e-4), &rng);
  EXPECT_LT(r.error, 1e-4);
  EXPECT_GT(r.error, 1e-7);
  EXPECT_GT(r.stats.far_pairs, 0);
}

TEST(StokesletSumTest, BlobsWiderThanTheLeavesAllowSumDirectly) {
  std::mt19937 rng(10);
  const Cloud c = RandomCloud(2000, 1000, 1.0, 0.1, &rng);  // ε (2/tol)^¼ = 3.8 > the cloud
  const Result r = Compare(c, Forced(1.25e-6), &rng);
  EXPECT_EQ(r.stats.far_pairs, 0);
  EXPECT_LT(r.error, 1e-15);
}

TEST(StokesletSumTest, DegenerateInputs) {
  std::mt19937 rng(5);
  for (auto [ns, nt] : {std::pair{1, 1}, {1, 500}, {500, 1}, {2, 3}, {40, 40}}) {
    const Cloud c = RandomCloud(ns, nt, 1.0, 1e-4, &rng);
    // By the cost model: summed directly.
    EXPECT_LT(Compare(c, {.tolerance = 1.25e-6, .direct_below_pairs = 0}, &rng).error, 1e-15);
    // Forced through the tree (p = 6): few sources, so single interactions dominate, whose worst
    // error fmm_sum.cc states (1.8e-4 over 20 placements of one source).
    EXPECT_LT(Compare(c, Forced(1.25e-6), &rng).error, 5e-4) << ns << " " << nt;
  }
  Cloud same = RandomCloud(300, 200, 1.0, 1e-3, &rng);  // all points at one place
  same.sources.colwise() = Vec3(0.3, 0.2, 0.1);
  same.targets.colwise() = Vec3(0.3, 0.2, 0.1);
  EXPECT_LT(Compare(same, Forced(1.25e-6), &rng).error, 1e-15);
  for (auto [ns, nt] : {std::pair{0, 10}, {10, 0}, {0, 0}}) {  // nothing to sum
    const Cloud c = RandomCloud(ns, nt, 1.0, 1e-3, &rng);
    auto fast = MakeFastStokesletSum(Forced(1.25e-6));
    fast->Build(c.sources, c.regularization, c.targets);
    Matrix3X w;
    fast->Apply(Matrix3X(3, ns), &w);
    EXPECT_EQ(w.cols(), nt);
    EXPECT_TRUE(w.isZero());
  }
}

TEST(StokesletSumTest, TargetsFarFromTheSources) {
  std::mt19937 rng(11);
  Cloud c = RandomCloud(2000, 1000, 1.0, 1e-3, &rng);
  c.targets.array() += 1e3;  // a cube 1 m wide, 1.7 km away
  const Result r = Compare(c, Forced(1.25e-6), &rng);
  EXPECT_LT(r.error, 1.25e-6);
  EXPECT_EQ(r.stats.near_pairs, 0);
}

TEST(StokesletSumTest, PointsOnALine) {
  std::mt19937 rng(6);
  Cloud c = RandomCloud(4000, 2000, 1.0, 1e-5, &rng);
  c.sources.row(1).setZero();
  c.sources.row(2).setZero();
  c.targets.row(1).setZero();
  c.targets.row(2).setZero();
  const Result r = Compare(c, Forced(1.25e-6), &rng);
  EXPECT_LT(r.error, 1.25e-6);
  EXPECT_GT(r.stats.far_pairs, 0);
}

TEST(StokesletSumTest, SixDecadesOfDistance) {
  // 19 balls of 100 sources and 60 targets, centred 10^(−k/3) m from the origin (k = 0 … 18) in
  // random directions, of radius 0.2 × that distance: distances from 2e-8 m to 2 m, ε = 1e-9 m.
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  auto direction = [&] { return Vec3(Vec3(normal(rng), normal(rng), normal(rng)).normalized()); };
  Cloud c;
  c.sources.resize(3, 1900);
  c.targets.resize(3, 1140);
  for (int k = 0; k < 19; ++k) {
    const double distance = std::pow(10.0, -k / 3.0);
    const Vec3 centre = distance * direction();
    std::uniform_real_distribution<double> radius(0.0, 0.2 * distance);
    for (int s = 0; s < 100; ++s) c.sources.col(100 * k + s) = centre + radius(rng) * direction();
    for (int t = 0; t < 60; ++t) c.targets.col(60 * k + t) = centre + radius(rng) * direction();
  }
  c.regularization = VecX::Constant(1900, 1e-9);
  const Result r = Compare(c, Forced(1.25e-6), &rng);
  EXPECT_LT(r.error, 1.25e-6);
  EXPECT_GT(r.stats.far_pairs, 0);
}


// The single-precision direct sum (the fast sum's kernels from kSinglePrecisionTolerance = 1e-4)
// against the double one, on the 100-helix lattice (extent 0.4 m, ε = 1.02 mm: the positions'
// rounding is largest there) and a random cloud; measured 2.0e-7 and 8.2e-8 in the norm of
// stokeslet_sum.h, allowed a tenth of the tolerance that selects it.
TEST(StokesletSumTest, SinglePrecisionDirectSumIsWellWithinItsTolerance) {
  std::mt19937 rng(11);
  for (const Cloud& c : {HelixLattice(10, 10), RandomCloud(4000, 2000, 0.4, 1e-3, &rng)}) {
    auto single = MakeDirectStokesletSum(true);
    auto exact = MakeDirectStokesletSum(false);
    single->Build(c.sources, c.regularization, c.targets);
    exact->Build(c.sources, c.regularization, c.targets);
    const Matrix3X g = RandomStrengths(static_cast<int>(c.sources.cols()), &rng);
    Matrix3X w, ref;
    single->Apply(g, &w);
    exact->Apply(g, &ref);
    const double error = testing::StokesletSumError(c, g, w, ref);
    std::printf("single precision, %ld sources: error %.2e\n", static_cast<long>(c.sources.cols()), error);
    EXPECT_LT(error, 0.1 * kSinglePrecisionTolerance);
  }
}

// Σ |S(x − y_s)|₂ |g_s| over [begin, end) of an S × 7 source matrix, bounded by
// Σ (2/R + ε²/R³) |g_s|: the scale of a sum's rounding.
double SumScale(const MatX& src, Eigen::Index begin, Eigen::Index end, const Vec3& x) {
  double scale = 0.0;
  for (Eigen::Index s = begin; s < end; ++s) {
    const Vec3 r = x - src.row(s).head<3>().transpose();
    const double big_r = std::sqrt(r.squaredNorm() + src(s, 3));
    scale += (2.0 / big_r + src(s, 3) / std::pow(big_r, 3)) * src.row(s).tail<3>().norm();
  }
  return scale;
}

// The near field's kernel over several ranges of whole blocks, with padding sources of zero
// strength as the FMM lays them out, against the plain loop over the real sources in double:
// within float rounding (1e-6 relative to Σ|S||g|, well under kSinglePrecisionTolerance).
TEST(StokesletSumTest, BlockKernelOverRangesMatchesThePlainSum) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> unit(-0.1, 0.1), size(0.5e-3, 2e-3);
  const int blocks = 9;
  Eigen::MatrixXf padded = Eigen::MatrixXf::Zero(blocks * kPointSumBlock, 7);
  MatX real(0, 7);
  std::vector<SourceRange> ranges = {{0, 2 * kPointSumBlock}, {3 * kPointSumBlock, 4 * kPointSumBlock},
                                     {6 * kPointSumBlock, 9 * kPointSumBlock}};
  for (const SourceRange& r : ranges)
    for (int s = r.begin; s < r.end; ++s) {
      if (s % 5 == 4) {  // padding: zero strength, any finite point, ε² = 1
        padded.row(s) << 0.05f, -0.02f, 0.01f, 1.0f, 0.0f, 0.0f, 0.0f;
        continue;
      }
      Eigen::Matrix<double, 1, 7> row;
      const double eps = size(rng);
      row << unit(rng), unit(rng), unit(rng), eps * eps, unit(rng), unit(rng), unit(rng);
      padded.row(s) = row.cast<float>();
      real.conservativeResize(real.rows() + 1, 7);
      real.row(real.rows() - 1) = padded.row(s).cast<double>();  // the same rounded points
    }
  for (int trial = 0; trial < 20; ++trial) {
    const Vec3 x(unit(rng), unit(rng), unit(rng));
    const Eigen::Vector3f xf = x.cast<float>();
    double w[3] = {0.0, 0.0, 0.0}, portable[3] = {0.0, 0.0, 0.0}, ref[3] = {0.0, 0.0, 0.0};
    AddPointSumBlocks(ColumnsF(padded), ranges.data(), static_cast<int>(ranges.size()), xf.data(), w);
    PointSumBlocksPortable(ColumnsF(padded), ranges.data(), static_cast<int>(ranges.size()),
                           xf.data(), portable);
    const Vec3 xd = xf.cast<double>();
    AddPointSum(Columns(real), 0, real.rows(), xd.data(), ref);
    const double scale = SumScale(real, 0, real.rows(), xd);
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(w[c], ref[c], 1e-6 * scale) << trial;
      EXPECT_NEAR(portable[c], ref[c], 1e-6 * scale) << trial;
    }
  }
}

// n sources as rows (x, y, z, ε², g) in a 0.2 m cube, ε in [0.5, 2] mm, g in [−0.1, 0.1]³.
MatX RandomSourceRows(int n, std::mt19937* rng) {
  std::uniform_real_distribution<double> unit(-0.1, 0.1), size(0.5e-3, 2e-3);
  MatX src(n, 7);
  for (Eigen::Index s = 0; s < n; ++s) {
    const double eps = size(*rng);
    src.row(s) << unit(*rng), unit(*rng), unit(*rng), eps * eps, unit(*rng), unit(*rng), unit(*rng);
  }
  return src;
}

// The double kernel over ranges that are not whole blocks (AVX-512: a masked last block of 8;
// portable: a remainder loop), both against the kernel summed pair by pair, to round-off.
TEST(StokesletSumTest, DoubleKernelOverAnyRangeMatchesTheKernel) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(-0.1, 0.1);
  const MatX src = RandomSourceRows(29, &rng);
  for (const auto& [begin, end] : {std::pair{0, 29}, std::pair{3, 14}, std::pair{8, 16},
                                   std::pair{5, 6}, std::pair{7, 7}}) {
    const Vec3 x(unit(rng), unit(rng), unit(rng));
    Vec3 ref = Vec3::Zero();
    for (int s = begin; s < end; ++s)
      ref += RegularizedStokesletMatrix(x - src.row(s).head<3>().transpose(), std::sqrt(src(s, 3))) *
             src.row(s).tail<3>().transpose();
    double w[3] = {0.0, 0.0, 0.0}, portable[3] = {0.0, 0.0, 0.0};
    AddPointSum(Columns(src), begin, end, x.data(), w);
    PointSumPortable(Columns(src), begin, end, x.data(), portable);
    const double scale = SumScale(src, begin, end, x);
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(w[c], ref[c], 1e-14 * scale) << begin << " " << end;
      EXPECT_NEAR(portable[c], ref[c], 1e-14 * scale) << begin << " " << end;
    }
  }
}

// The single-precision kernel over ranges that are not whole blocks (the AVX-512 path masks the
// last block; the portable loop has a remainder), against the plain loop in double.
TEST(StokesletSumTest, SingleKernelOverAnyRangeMatchesThePlainSum) {
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> unit(-0.1, 0.1);
  MatX real = RandomSourceRows(53, &rng);
  const Eigen::MatrixXf single = real.cast<float>();
  real = single.cast<double>();  // the same rounded points
  for (const auto& [begin, end] : {std::pair{0, 53}, std::pair{3, 40}, std::pair{16, 32},
                                   std::pair{5, 6}, std::pair{7, 7}}) {
    for (int trial = 0; trial < 5; ++trial) {
      const Eigen::Vector3f xf = Vec3(unit(rng), unit(rng), unit(rng)).cast<float>();
      double w[3] = {0.0, 0.0, 0.0}, portable[3] = {0.0, 0.0, 0.0}, ref[3] = {0.0, 0.0, 0.0};
      AddPointSumSingle(ColumnsF(single), begin, end, xf.data(), w);
      PointSumSinglePortable(ColumnsF(single), begin, end, xf.data(), portable);
      const Vec3 xd = xf.cast<double>();
      AddPointSum(Columns(real), begin, end, xd.data(), ref);
      const double scale = SumScale(real, begin, end, xd);
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(w[c], ref[c], 1e-6 * scale) << begin << " " << end;
        EXPECT_NEAR(portable[c], ref[c], 1e-6 * scale) << begin << " " << end;
      }
    }
  }
}

// The sums at several targets at once (one read of each block of sources for all of them)
// against the one-target sums, for 1 … kPointSumTargets targets, in double, in float and over
// ranges of whole blocks: bit for bit, since each target's arithmetic and order are the same;
// and over ranges of any length together (AddPointSumRangesTargets), in float also flushed after
// every range (bit for bit the ranges one by one).
TEST(StokesletSumTest, SeveralTargetsAtOnceEqualEachTargetAlone) {
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> unit(-0.1, 0.1);
  const MatX src = RandomSourceRows(5 * kPointSumBlock + 3, &rng);
  const Eigen::MatrixXf src_f = src.cast<float>();
  const std::vector<SourceRange> ranges = {{0, 2 * kPointSumBlock},
                                           {3 * kPointSumBlock, 5 * kPointSumBlock}};
  const Eigen::Index begin = 2, end = src.rows() - 1;  // not whole blocks: the masked last one
  for (int n = 1; n <= kPointSumTargets; ++n) {
    Matrix3X x(3, n);
    for (Eigen::Index k = 0; k < x.size(); ++k) x.data()[k] = unit(rng);
    const Eigen::Matrix3Xf xf = x.cast<float>();
    Matrix3X together = Matrix3X::Zero(3, 3 * n), alone = Matrix3X::Zero(3, 3 * n);
    const double* xd[kPointSumTargets];
    const float* xs[kPointSumTargets];
    double* out[3][kPointSumTargets];
    for (int k = 0; k < n; ++k) {
      xd[k] = x.col(k).data(), xs[k] = xf.col(k).data();
      for (int kind = 0; kind < 3; ++kind) out[kind][k] = together.col(kind * n + k).data();
      AddPointSum(Columns(src), begin, end, x.col(k).data(), alone.col(k).data());
      AddPointSumSingle(ColumnsF(src_f), begin, end, xf.col(k).data(), alone.col(n + k).data());
      AddPointSumBlocks(ColumnsF(src_f), ranges.data(), 2, xf.col(k).data(),
                        alone.col(2 * n + k).data());
    }
    const SourceRange part{static_cast<int>(begin), static_cast<int>(end)};
    AddPointSumRangesTargets(Columns(src), &part, 1, n, xd, out[0]);
    AddPointSumRangesTargets(ColumnsF(src_f), &part, 1, n, xs, out[1]);
    AddPointSumBlocksTargets(ColumnsF(src_f), ranges.data(), 2, n, xs, out[2]);
    EXPECT_GT(alone.cwiseAbs().minCoeff(), 0.0);
    for (Eigen::Index k = 0; k < together.size(); ++k)
      EXPECT_EQ(together.data()[k], alone.data()[k]) << n << " targets, entry " << k;
    // Ranges of any length summed together: bit for bit one target alone over the same ranges,
    // and the sum of the ranges one by one to the rounding of the reduction.
    const std::vector<SourceRange> odd = {{1, 20}, {33, 50}, {52, static_cast<int>(src.rows())}};
    Matrix3X ranged = Matrix3X::Zero(3, 2 * n), ranged_alone = ranged, by_range = ranged;
    double* ranged_out[2][kPointSumTargets];
    for (int k = 0; k < n; ++k) {
      ranged_out[0][k] = ranged.col(k).data(), ranged_out[1][k] = ranged.col(n + k).data();
      double* one_d[1] = {ranged_alone.col(k).data()};
      double* one_f[1] = {ranged_alone.col(n + k).data()};
      AddPointSumRangesTargets(Columns(src), odd.data(), 3, 1, &xd[k], one_d);
      AddPointSumRangesTargets(ColumnsF(src_f), odd.data(), 3, 1, &xs[k], one_f);
      for (const SourceRange& r : odd) {
        AddPointSum(Columns(src), r.begin, r.end, xd[k], by_range.col(k).data());
        AddPointSumSingle(ColumnsF(src_f), r.begin, r.end, xs[k], by_range.col(n + k).data());
      }
    }
    AddPointSumRangesTargets(Columns(src), odd.data(), 3, n, xd, ranged_out[0]);
    AddPointSumRangesTargets(ColumnsF(src_f), odd.data(), 3, n, xs, ranged_out[1]);
    for (Eigen::Index k = 0; k < ranged.size(); ++k)
      EXPECT_EQ(ranged.data()[k], ranged_alone.data()[k]) << n << " targets, entry " << k;
    EXPECT_LT((ranged.leftCols(n) - by_range.leftCols(n)).cwiseAbs().maxCoeff(),
              1e-13 * by_range.leftCols(n).cwiseAbs().maxCoeff());
    EXPECT_LT((ranged.rightCols(n) - by_range.rightCols(n)).cwiseAbs().maxCoeff(),
              1e-6 * by_range.rightCols(n).cwiseAbs().maxCoeff());
    // Each range's lanes added to the ranges' sum after it: n targets bit for bit each alone,
    // and the ranges one by one to the rounding.
    Matrix3X flushed = Matrix3X::Zero(3, 2 * n);
    double* flushed_out[kPointSumTargets];
    for (int k = 0; k < n; ++k) {
      flushed_out[k] = flushed.col(k).data();
      double* one[1] = {flushed.col(n + k).data()};
      AddPointSumRangesTargets(ColumnsF(src_f), odd.data(), 3, 1, &xs[k], one, true);
    }
    AddPointSumRangesTargets(ColumnsF(src_f), odd.data(), 3, n, xs, flushed_out, true);
    for (Eigen::Index k = 0; k < 3 * n; ++k)
      EXPECT_EQ(flushed.data()[k], flushed.data()[3 * n + k]) << n << " targets, flushed";
    EXPECT_LT((flushed.leftCols(n) - by_range.rightCols(n)).cwiseAbs().maxCoeff(),
              1e-6 * by_range.rightCols(n).cwiseAbs().maxCoeff());
  }
}

// Each instruction set's sums that this CPU can run (the dispatch takes the widest, so the
// narrower ones are checked here directly), against the kernel summed pair by pair in double over
// ranges of any length (whole and masked blocks): in double to round-off (1e-14 of Σ|S||g|), in
// float within its rounding (1e-6); and n targets at once bit for bit each target alone.
TEST(StokesletSumTest, EachInstructionSetsSumsMatchTheKernel) {
  using Sum = void (*)(const SourceColumns&, const SourceRange*, int, int, const double* const*,
                       double* const*, bool);
  using SumF = void (*)(const SourceColumnsF&, const SourceRange*, int, int, const float* const*,
                        double* const*, bool);
  struct Isa {
    const char* name;
    bool present;
    Sum sum;
    SumF sum_f;
  };
  std::vector<Isa> isas;
#if defined(__x86_64__)
  isas.push_back({"AVX-512", HasPointSumAvx512(), PointSumTargetsAvx512, PointSumTargetsAvx512});
  isas.push_back({"AVX2", HasPointSumAvx2(), PointSumTargetsAvx2, PointSumTargetsAvx2});
#endif
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> unit(-0.1, 0.1);
  MatX src = RandomSourceRows(61, &rng);
  const Eigen::MatrixXf src_f = src.cast<float>();
  const MatX rounded = src_f.cast<double>();
  const std::vector<SourceRange> ranges = {{0, 61}, {3, 21}, {16, 32}, {40, 41}, {7, 7}, {45, 58}};
  int checked = 0;
  for (const Isa& isa : isas) {
    if (!isa.present) continue;
    ++checked;
    for (const SourceRange& range : ranges) {
      Matrix3X x(3, kPointSumTargets);
      for (Eigen::Index k = 0; k < x.size(); ++k) x.data()[k] = unit(rng);
      const Eigen::Matrix3Xf xf = x.cast<float>();
      const double* xd[kPointSumTargets];
      const float* xs[kPointSumTargets];
      Matrix3X together = Matrix3X::Zero(3, 2 * kPointSumTargets), alone = together;
      double* out[2][kPointSumTargets];
      for (int k = 0; k < kPointSumTargets; ++k) {
        xd[k] = x.col(k).data(), xs[k] = xf.col(k).data();
        out[0][k] = together.col(k).data(), out[1][k] = together.col(kPointSumTargets + k).data();
        double* one_d[1] = {alone.col(k).data()};
        double* one_f[1] = {alone.col(kPointSumTargets + k).data()};
        isa.sum(Columns(src), &range, 1, 1, &xd[k], one_d, false);
        isa.sum_f(ColumnsF(src_f), &range, 1, 1, &xs[k], one_f, false);
        Vec3 ref = Vec3::Zero(), ref_f = Vec3::Zero();
        const Vec3 x_f = xf.col(k).cast<double>();
        for (int s = range.begin; s < range.end; ++s) {
          ref += RegularizedStokesletMatrix(x.col(k) - src.row(s).head<3>().transpose(),
                                            std::sqrt(src(s, 3))) *
                 src.row(s).tail<3>().transpose();
          ref_f += RegularizedStokesletMatrix(x_f - rounded.row(s).head<3>().transpose(),
                                              std::sqrt(rounded(s, 3))) *
                   rounded.row(s).tail<3>().transpose();
        }
        const double scale = SumScale(src, range.begin, range.end, x.col(k));
        const double scale_f = SumScale(rounded, range.begin, range.end, x_f);
        for (int c = 0; c < 3; ++c) {
          EXPECT_NEAR(alone(c, k), ref(c), 1e-14 * scale) << isa.name << " " << range.begin;
          EXPECT_NEAR(alone(c, kPointSumTargets + k), ref_f(c), 1e-6 * scale_f)
              << isa.name << " float " << range.begin;
        }
      }
      for (int n = 1; n <= kPointSumTargets; ++n) {
        together.setZero();
        isa.sum(Columns(src), &range, 1, n, xd, out[0], false);
        isa.sum_f(ColumnsF(src_f), &range, 1, n, xs, out[1], false);
        for (int k = 0; k < n; ++k)
          for (int c = 0; c < 3; ++c) {
            EXPECT_EQ(together(c, k), alone(c, k)) << isa.name << " " << n << " targets";
            EXPECT_EQ(together(c, kPointSumTargets + k), alone(c, kPointSumTargets + k))
                << isa.name << " float, " << n << " targets";
          }
      }
    }
  }
  if (checked == 0) GTEST_SKIP() << "neither AVX-512 nor AVX2 with FMA here: the portable loops";
}

// A run resumes bit for bit on another thread count (tests/reliability/kill_resume.py), so the
// fast sum's result must not depend on it: OpenMP splits only independent boxes (here 1 against 2
// OpenMP threads), and the BLAS runs on one thread of its own (tests/solver: Blas.RunsOnOneThread…).
TEST(StokesletSumTest, ResultDoesNotDependOnTheThreadCount) {
#ifdef _OPENMP
  std::mt19937 rng(3);
  const Cloud c = HelixLattice(6, 6);
  StokesletSumOptions options;
  options.tolerance = 1e-4;
  options.direct_below_pairs = 0;
  options.choose_by_cost = false;
  const Matrix3X g = RandomStrengths(static_cast<int>(c.sources.cols()), &rng);
  Matrix3X w[2];
  const int saved = omp_get_max_threads();
  for (int threads = 1; threads <= 2; ++threads) {
    omp_set_num_threads(threads);
    auto fast = MakeFastStokesletSum(options);
    fast->Build(c.sources, c.regularization, c.targets);
    ASSERT_GT(fast->Stats().far_pairs, 0);  // the tree, not the direct fallback
    fast->Apply(g, &w[threads - 1]);
  }
  omp_set_num_threads(saved);
  EXPECT_TRUE(w[0] == w[1]);
#else
  GTEST_SKIP() << "built without OpenMP";
#endif
}

}  // namespace
}  // namespace stokesrods
