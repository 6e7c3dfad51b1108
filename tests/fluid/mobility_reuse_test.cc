// Reuse of the dense 𝕄 across steps (fluid/mobility_reuse.h) against assembling it at every
// step: two helices 3R apart turning about their own axes (the motion of paper Fig. 1), the
// extrapolated 𝕄 compared with the exact one at every step.
#include "stokesrods/fluid/mobility_reuse.h"

#include <gtest/gtest.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>

#include <Eigen/Geometry>

#include "stokesrods/fluid/mobility_operator.h"
#include "stokesrods/fluid/mobility_reuse_half.h"
#include "stokesrods/fluid/rss.h"
#include "stokesrods/rod/geometry.h"
#include "stokesrods/solver/blas.h"

namespace stokesrods {
namespace {

// Two 33-node helices, bases 3 cm apart, each turned by `angle` about its own axis (z).
std::vector<Matrix3X> TurnedHelices(double angle) {
  std::vector<Matrix3X> x;
  for (const double base : {0.0, 0.03}) {
    HelixGeometry g;
    g.nodes = 33;
    Matrix3X nodes = HelixNodes(g);
    nodes = Eigen::AngleAxisd(angle, Vec3::UnitZ()).toRotationMatrix() * nodes;
    nodes.row(0).array() += base;
    x.push_back(nodes);
  }
  return x;
}

std::vector<HydroRod> Rods(const std::vector<Matrix3X>& x) {
  return {{&x[0], 1e-3}, {&x[1], 1e-3}};
}

struct Outcome {
  double worst_error = 0.0;  ///< max over steps of ‖𝕄_used − 𝕄_exact‖_F / ‖𝕄_exact‖_F
  MobilityReuseStats stats;
  MobilityReuseStats fast;  ///< after the fast turns
  bool exact_where_assembled = true;
};

// `steps` updates turning by `step_angle` each (after `fast_steps` of `fast_angle` each, if
// any), the operator's 𝕄 against the exact one.
Outcome Turn(double tolerance, double step_angle, int steps, int forget_every = 0,
             int fast_steps = 0, double fast_angle = 0.0) {
  FluidParams params;
  MobilityOptions options;
  options.reuse_tolerance = tolerance;
  const auto op = MakeMobilityOperator(params, options);
  Outcome out;
  long assemblies = 0;
  for (int k = 0; k < fast_steps + steps; ++k) {
    if (forget_every > 0 && k % forget_every == 0) op->ForgetHistory();
    const double angle = k < fast_steps ? k * fast_angle
                                        : fast_steps * fast_angle + (k - fast_steps) * step_angle;
    const std::vector<Matrix3X> x = TurnedHelices(angle);
    if (k == fast_steps) out.fast = op->reuse_stats();
    op->Update(Rods(x));
    MatX exact;
    AssembleMobility(params, Rods(x), &exact);
    const double error = (*op->matrix() - exact).norm() / exact.norm();
    out.worst_error = std::max(out.worst_error, error);
    if (op->reuse_stats().assemblies > assemblies && error != 0.0) out.exact_where_assembled = false;
    assemblies = op->reuse_stats().assemblies;
  }
  out.stats = op->reuse_stats();
  return out;
}

// Fig. 1 at h = 1 ms turns its helices by ω h = 1.6e-3 rad per step. At tolerance 1e-4 the
// extrapolated 𝕄 stays within the tolerance (allowed: 1.5 ×, the interval is set after the fact),
// the error measured at the assemblies bounds the true one, and most steps reuse 𝕄.
TEST(MobilityReuse, ExtrapolatesWithinTheToleranceAndMeasuresItsError) {
  const double tolerance = 1e-4;
  FluidParams params;
  MatX before, after;
  const std::vector<Matrix3X> x0 = TurnedHelices(0.0), x1 = TurnedHelices(1.6e-3);
  AssembleMobility(params, Rods(x0), &before);
  AssembleMobility(params, Rods(x1), &after);
  std::printf("  one step changes 𝕄 by %.2e (relative Frobenius)\n",
              (after - before).norm() / before.norm());
  const Outcome o = Turn(tolerance, 1.6e-3, 200);
  std::printf("  turn 1.6e-3 rad per step: %ld of %ld updates assembled, worst error %.2e, "
              "largest measured %.2e\n", o.stats.assemblies, o.stats.updates, o.worst_error,
              o.stats.largest_error);
  EXPECT_EQ(o.stats.updates, 200);
  EXPECT_LT(o.stats.assemblies, 200 / 4);
  EXPECT_LT(o.worst_error, 1.5 * tolerance);
  EXPECT_GT(o.worst_error, 0.0);
  EXPECT_GE(o.stats.largest_error, o.worst_error);
  EXPECT_TRUE(o.exact_where_assembled);
}

// Ten times the turn per step (Fig. 1 at h = 10 ms): the linear extrapolation of one step
// misses by more than a fifth of the tolerance, the quadratic one by little enough for two
// steps, so 𝕄 is reused once three assemblies are held, within the tolerance. Sixty times the
// turn (0.1 rad per step): the quadratic one misses too, and 𝕄 is assembled at every step, exactly
// as without reuse.
TEST(MobilityReuse, LargeStepsAssembleEveryTime) {
  const Outcome ten = Turn(1e-4, 1.6e-2, 30);
  std::printf("  turn 1.6e-2 rad per step: %ld of 30 updates assembled, worst error %.2e\n",
              ten.stats.assemblies, ten.worst_error);
  EXPECT_LT(ten.stats.assemblies, 30 / 2);
  EXPECT_LT(ten.worst_error, 1.5e-4);
  EXPECT_TRUE(ten.exact_where_assembled);
  const Outcome sixty = Turn(1e-4, 0.1, 30);
  EXPECT_EQ(sixty.stats.assemblies, 30);
  EXPECT_EQ(sixty.worst_error, 0.0);
  EXPECT_EQ(sixty.stats.largest_error, 0.0);
}

// Where even the quadratic extrapolation misses for two steps, measurements are skipped (1, 2,
// 4, 8 assemblies in a row, then three that rebuild and measure the history): over 60 large turns
// a third or fewer of the assemblies measure. When the motion slows to Fig. 1's at h = 1 ms, the
// reuse starts again within kMaxSkip + 2 assemblies of its start without skipping: 150 updates
// then assemble fewer than 150/4 + kMaxSkip + 2 times, within the tolerance.
TEST(MobilityReuse, LargeStepsSkipMeasurementsAndSlowerOnesReuseAgain) {
  const Outcome large = Turn(1e-4, 0.1, 60);
  std::printf("  turn 0.1 rad per step: %ld of 60 assemblies measured\n", large.stats.measurements);
  EXPECT_EQ(large.stats.assemblies, 60);
  EXPECT_EQ(large.worst_error, 0.0);
  EXPECT_GT(large.stats.measurements, 0);
  EXPECT_LE(large.stats.measurements, 60 / 3);
  const Outcome slower = Turn(1e-4, 1.6e-3, 150, 0, 40, 0.1);
  const long slow_assemblies = slower.stats.assemblies - slower.fast.assemblies;
  std::printf("  then 1.6e-3 rad per step: %ld of 150 updates assembled, worst error %.2e\n",
              slow_assemblies, slower.worst_error);
  EXPECT_EQ(slower.fast.assemblies, 40);
  EXPECT_LT(slow_assemblies, 150 / 4 + MobilityReuse::kMaxSkip + 2);
  EXPECT_LT(slower.worst_error, 1.5e-4);
  EXPECT_TRUE(slower.exact_where_assembled);
}

// The history is kept in single precision (6e-8 relative): a tolerance below what that rounding
// allows assembles at every step, exact, even where the motion is slow enough for a double
// history to be extrapolated; a tolerance above it reuses 𝕄 on the same motion, within it.
TEST(MobilityReuse, TolerancesBelowSinglePrecisionAssembleEveryTime) {
  const Outcome fine = Turn(1e-8, 1e-6, 30);
  EXPECT_EQ(fine.stats.assemblies, 30);
  EXPECT_EQ(fine.worst_error, 0.0);
  const Outcome coarse = Turn(1e-5, 1e-6, 30);
  EXPECT_LT(coarse.stats.assemblies, 30 / 2);
  EXPECT_GT(coarse.worst_error, 0.0);
  EXPECT_LT(coarse.worst_error, 1.5e-5);
}

TEST(MobilityReuse, ToleranceZeroAssemblesEveryTime) {
  const Outcome o = Turn(0.0, 1.6e-3, 30);
  EXPECT_EQ(o.stats.assemblies, 30);
  EXPECT_EQ(o.worst_error, 0.0);
}

// ForgetHistory (a restart point) starts over: two assemblies for the slope, then one-step
// intervals doubling at most (assemblies at 0, 1, 2, 4, 8, 16 of each window at best): 10
// windows of 20 steps assemble at least 60 times.
TEST(MobilityReuse, ForgettingRestartsFromTwoAssemblies) {
  const Outcome o = Turn(1e-4, 1.6e-3, 200, 20);
  std::printf("  forgetting every 20 updates: %ld of %ld assembled, worst error %.2e\n",
              o.stats.assemblies, o.stats.updates, o.worst_error);
  EXPECT_GE(o.stats.assemblies, 60);
  EXPECT_LT(o.stats.assemblies, 200 / 2);
  EXPECT_LT(o.worst_error, 1.5e-4);
}

// A restart point keeps the reuse (AtRestartPoint), and a fresh operator given its history
// (reuse_history, as a checkpoint keeps it) assembles the history's matrices again and then
// gives the same 𝕄 as the uninterrupted operator at every later update, bit for bit, assembling
// where it assembles: the exact resume of a run (io/checkpoint.h) rests on this.
TEST(MobilityReuse, RestoredHistoryContinuesBitForBit) {
  FluidParams params;
  MobilityOptions options;
  options.reuse_tolerance = 1e-4;
  const auto run = MakeMobilityOperator(params, options);
  const double step_angle = 1.6e-3;
  for (int k = 0; k < 37; ++k) {
    const std::vector<Matrix3X> x = TurnedHelices(k * step_angle);
    run->Update(Rods(x));
  }
  const long assemblies_before = run->reuse_stats().assemblies;
  run->AtRestartPoint();
  const MobilityReuseHistory kept = run->reuse_history();
  ASSERT_EQ(kept.geometries.size(), 3u);  // extrapolating quadratically, some updates since
  ASSERT_GT(kept.interval, 2);
  ASSERT_GT(kept.since, 0);
  const auto resumed = MakeMobilityOperator(params, options);
  resumed->RestoreReuse(kept);
  long restored_extra = -1;  // the resumed operator's assemblies beyond the run's
  for (int k = 37; k < 120; ++k) {
    const std::vector<Matrix3X> x = TurnedHelices(k * step_angle);
    run->Update(Rods(x));
    resumed->Update(Rods(x));
    if (restored_extra < 0) restored_extra = resumed->reuse_stats().assemblies - (run->reuse_stats().assemblies - assemblies_before);
    EXPECT_EQ(resumed->reuse_stats().assemblies - restored_extra,
              run->reuse_stats().assemblies - assemblies_before) << "update " << k;
    ASSERT_EQ((*run->matrix() - *resumed->matrix()).cwiseAbs().maxCoeff(), 0.0) << "update " << k;
    VecX u_run, u_resumed;  // and the products the Newton residuals take
    run->Apply(VecX::Ones(run->size()), &u_run);
    resumed->Apply(VecX::Ones(run->size()), &u_resumed);
    ASSERT_EQ((u_run - u_resumed).cwiseAbs().maxCoeff(), 0.0) << "update " << k;
  }
  EXPECT_EQ(restored_extra, 3);  // the history's three matrices
  // The run kept extrapolating across its restart point: 83 updates, a few assemblies.
  EXPECT_LT(run->reuse_stats().assemblies - assemblies_before, 83 / 4);
}

// Where 𝕄 is assembled at every step (a turn of 0.1 rad per step), the products take it in
// single precision from a tolerance of kSinglePrecisionTolerance on: the product of the rounded
// matrix, summed in double (GemvRowsMixed), within 1e-6 of the double product relative to
// |𝕄| |f|; below that tolerance they take the double 𝕄. matrix() stays the assembled one.
TEST(MobilityReuse, ProductsTakeTheAssembledMatrixInSinglePrecisionFromItsTolerance) {
  FluidParams params;
  for (const double tolerance : {kSinglePrecisionTolerance, 1e-5}) {
    MobilityOptions options;
    options.reuse_tolerance = tolerance;
    const auto op = MakeMobilityOperator(params, options);
    for (int k = 0; k < 4; ++k) {
      const std::vector<Matrix3X> x = TurnedHelices(0.1 * k);
      op->Update(Rods(x));
      MatX exact;
      AssembleMobility(params, Rods(x), &exact);
      ASSERT_EQ(op->reuse_stats().assemblies, k + 1);
      ASSERT_EQ((*op->matrix() - exact).cwiseAbs().maxCoeff(), 0.0);
      const VecX f = VecX::LinSpaced(exact.cols(), -1.0, 2.0);
      VecX u, rounded(exact.rows());
      op->Apply(f, &u);
      const Eigen::MatrixXf single = exact.cast<float>();
      GemvRowsMixed(single, 0, single.rows(), f.data(), rounded.data());
      const double scale = (exact.cwiseAbs() * f.cwiseAbs()).maxCoeff();
      const double from_double = (u - exact * f).cwiseAbs().maxCoeff() / scale;
      if (tolerance >= kSinglePrecisionTolerance) {
        EXPECT_EQ((u - rounded).cwiseAbs().maxCoeff(), 0.0) << "update " << k;
        EXPECT_GT(from_double, 0.0);
        EXPECT_LT(from_double, 1e-6);
        ASSERT_NE(op->single_matrix(), nullptr);
      } else {
        EXPECT_LT(from_double, 1e-14) << "update " << k;
        EXPECT_EQ(op->single_matrix(), nullptr);
      }
    }
  }
}

// The same while measurements are skipped (large turns, then slow ones): a history taken in the
// middle of a run of skipped measurements continues as the uninterrupted operator, bit for bit,
// measuring and assembling where it does.
TEST(MobilityReuse, RestoredHistoryContinuesBitForBitWhileSkipping) {
  FluidParams params;
  MobilityOptions options;
  options.reuse_tolerance = 1e-4;
  const auto angle = [](int k) { return k < 40 ? 0.1 * k : 4.0 + 1.6e-3 * (k - 40); };
  const auto run = MakeMobilityOperator(params, options);
  int first = 0;  // the restart: past the first skipped measurement, one skipped next
  while (first < 40 && (first < 8 || run->reuse_history().skip == 0))
    run->Update(Rods(TurnedHelices(angle(first++))));
  run->AtRestartPoint();
  const MobilityReuseHistory kept = run->reuse_history();
  ASSERT_GT(kept.skip, 0);  // in the middle of skipped measurements
  const MobilityReuseStats before = run->reuse_stats();
  const auto resumed = MakeMobilityOperator(params, options);
  resumed->RestoreReuse(kept);
  const VecX f = VecX::Ones(run->size());
  for (int k = first; k < 140; ++k) {
    const std::vector<Matrix3X> x = TurnedHelices(angle(k));
    run->Update(Rods(x));
    resumed->Update(Rods(x));
    const long extra = static_cast<long>(kept.geometries.size());  // assembled again on restore
    ASSERT_EQ(resumed->reuse_stats().assemblies - extra,
              run->reuse_stats().assemblies - before.assemblies) << "update " << k;
    ASSERT_EQ(resumed->reuse_stats().measurements,
              run->reuse_stats().measurements - before.measurements) << "update " << k;
    VecX u_run, u_resumed;
    run->Apply(f, &u_run);
    resumed->Apply(f, &u_resumed);
    ASSERT_EQ((u_run - u_resumed).cwiseAbs().maxCoeff(), 0.0) << "update " << k;
  }
  EXPECT_LT(run->reuse_stats().assemblies - before.assemblies, 140 - first - 50);  // reused again
}

// A history of another size (another model) is dropped: the operator starts over.
TEST(MobilityReuse, RestoredHistoryOfAnotherSizeIsDropped) {
  FluidParams params;
  MobilityOptions options;
  options.reuse_tolerance = 1e-4;
  const auto op = MakeMobilityOperator(params, options);
  MobilityReuseHistory other{.since = 1, .interval = 4, .geometries = {VecX::Zero(9), VecX::Ones(9)}};
  op->RestoreReuse(other);
  const std::vector<Matrix3X> x = TurnedHelices(0.0);
  op->Update(Rods(x));
  MatX exact;
  AssembleMobility(params, Rods(x), &exact);
  EXPECT_EQ(op->reuse_stats().assemblies, 1);
  EXPECT_EQ((*op->matrix() - exact).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(op->reuse_history().geometries.size(), 1u);
}

// IEEE half precision to single, decoded bit by bit (the reference for the kernels' vcvtph2ps).
float DecodeHalf(std::uint16_t h) {
  const int exponent = (h >> 10) & 0x1f, mantissa = h & 0x3ff;
  const float sign = (h & 0x8000) ? -1.0f : 1.0f;
  if (exponent == 0) return sign * std::ldexp(static_cast<float>(mantissa), -24);
  if (exponent == 31) return mantissa ? NAN : sign * INFINITY;
  return sign * std::ldexp(static_cast<float>(1024 + mantissa), exponent - 25);
}

// Entries over nine decades, with signs and zeros, n = 1 … 1000 (the kernels' masked tails): each
// is replaced by what its half value stands for (the decoded half over the scale, exactly), within
// half precision's rounding (2⁻¹¹ relative in its normal range, 2⁻²⁵ of the scale below it); the
// scale is the power of two that puts the largest entry in [2¹⁴, 2¹⁵). Both kernels (AVX-512 where
// the CPU has it, and AVX2 with F16C), which give the same bits.
void CheckRoundsToWhatTheHalfValuesStandFor(bool f16c) {
  std::mt19937 random(7);
  std::uniform_real_distribution<float> decade(-7.0f, 2.0f), unit(-1.0f, 1.0f);
  // (kTwoPartsFrom + 3: in two parts over the threads, the largest entry in the second.)
  const int two_parts = static_cast<int>(kTwoPartsFrom);
  for (const int n : {1, 15, 16, 17, 1000, two_parts + 3}) {
    std::vector<float> d(static_cast<std::size_t>(n));
    for (float& v : d) v = unit(random) * std::pow(10.0f, decade(random));
    if (n > 2) d[1] = 0.0f;
    if (n > 1000) d[static_cast<std::size_t>(n) - 3] = 1e3f;
    const std::vector<float> before = d;
    std::vector<std::uint16_t> half(d.size());
    const float scale = RoundToHalf(n, d.data(), half.data(), f16c);
    std::vector<float> widest_d = before;
    std::vector<std::uint16_t> widest(d.size());
    EXPECT_EQ(RoundToHalf(n, widest_d.data(), widest.data()), scale);
    EXPECT_EQ(widest, half) << "n " << n;
    EXPECT_EQ(widest_d, d) << "n " << n;
    float largest = 0.0f;
    for (const float v : before) largest = std::max(largest, std::abs(v));
    EXPECT_EQ(std::ldexp(1.0f, std::ilogb(scale)), scale) << "a power of two";
    EXPECT_GE(largest * scale, 16384.0f);
    EXPECT_LT(largest * scale, 32768.0f);
    for (std::size_t i = 0; i < d.size(); ++i) {
      ASSERT_EQ(d[i], DecodeHalf(half[i]) / scale) << "n " << n << " entry " << i;
      const float bound = std::max(std::abs(before[i]) * std::ldexp(1.0f, -11),
                                   std::ldexp(1.0f, -25) / scale);
      ASSERT_LE(std::abs(d[i] - before[i]), bound) << "n " << n << " entry " << i;
    }
  }
  std::vector<float> zeros(20, 0.0f);
  std::vector<std::uint16_t> half(20, 0xffff);
  EXPECT_EQ(RoundToHalf(20, zeros.data(), half.data(), f16c), 1.0f);
  EXPECT_EQ(half[19], 0);
  for (const float bad : {NAN, INFINITY}) {
    // In a whole block of 8 or 16, or in the last entries; of kTwoPartsFrom + 1, in the second
    // part.
    for (const auto& [n, where] :
         {std::pair{39, 3}, {39, 33}, {39, 38}, {two_parts + 1, two_parts}}) {
      std::vector<float> d(static_cast<std::size_t>(n), 1.0f);
      d[static_cast<std::size_t>(where)] = bad;
      std::vector<std::uint16_t> untouched(d.size(), 0x1234);
      EXPECT_EQ(RoundToHalf(n, d.data(), untouched.data(), f16c), 0.0f) << where;
      EXPECT_EQ(untouched[0], 0x1234);
      EXPECT_EQ(d[0], 1.0f);
    }
  }
}

// The rounding of a large matrix (two parts over the threads from kTwoPartsFrom entries) gives
// the same scale and bits on one thread and on two.
TEST(MobilityReuseHalf, RoundsToTheSameBitsOnAnyNumberOfThreads) {
  if (!HasHalfDifferences()) GTEST_SKIP() << "neither AVX-512 BW nor F16C on this CPU";
#ifdef _OPENMP
  std::mt19937 random(9);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  const int n = static_cast<int>(kTwoPartsFrom) + 9 * 20011;
  std::vector<float> before(static_cast<std::size_t>(n));
  for (float& v : before) v = unit(random);
  before[static_cast<std::size_t>(n) - 5] = 7.5f;  // the largest, in the second part
  std::vector<float> d[2] = {before, before};
  std::vector<std::uint16_t> half[2] = {std::vector<std::uint16_t>(before.size()),
                                        std::vector<std::uint16_t>(before.size())};
  float scale[2];
  const int saved = omp_get_max_threads();
  for (int threads = 1; threads <= 2; ++threads) {
    omp_set_num_threads(threads);
    scale[threads - 1] = RoundToHalf(n, d[threads - 1].data(), half[threads - 1].data());
  }
  omp_set_num_threads(saved);
  EXPECT_EQ(scale[0], scale[1]);
  EXPECT_EQ(scale[0], 4096.0f);  // 2^(14 − ⌊log₂ 7.5⌋)
  EXPECT_TRUE(half[0] == half[1]);
  EXPECT_TRUE(d[0] == d[1]);
#else
  GTEST_SKIP() << "built without OpenMP";
#endif
}

TEST(MobilityReuseHalf, RoundsToWhatTheHalfValuesStandFor) {
  if (!HasHalfDifferences()) GTEST_SKIP() << "neither AVX-512 BW nor F16C on this CPU";
  for (const bool f16c : {false, true}) {
    SCOPED_TRACE(f16c ? "AVX2 with F16C" : "the widest kernel");
    CheckRoundsToWhatTheHalfValuesStandFor(f16c);
  }
}

// The extrapolation from half-precision differences is base + a · slope + b · curve on the
// decoded values, to single precision's rounding of the sum (with and without the curve; n with
// masked tails, and in two parts), by both kernels.
TEST(MobilityReuseHalf, ExtrapolatesTheDecodedDifferences) {
  if (!HasHalfDifferences()) GTEST_SKIP() << "neither AVX-512 BW nor F16C on this CPU";
  std::mt19937 random(11);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  for (const int n : {5, 16, 21, 390 * 390, static_cast<int>(kTwoPartsFrom) + 5}) {
    std::vector<float> base(static_cast<std::size_t>(n)), slope(base), curve(base), out(base);
    for (std::size_t i = 0; i < base.size(); ++i)
      base[i] = unit(random), slope[i] = 1e-2f * unit(random), curve[i] = 1e-4f * unit(random);
    std::vector<std::uint16_t> slope_half(base.size()), curve_half(base.size());
    const float s1 = RoundToHalf(n, slope.data(), slope_half.data());
    const float s2 = RoundToHalf(n, curve.data(), curve_half.data());
    for (const bool quadratic : {false, true}) {
      const float a = 0.37f, b = quadratic ? 0.37f * 1.37f : 0.0f;
      ExtrapolateHalf(n, base.data(), a / s1, slope_half.data(), b / s2,
                      quadratic ? curve_half.data() : nullptr, out.data());
      std::vector<float> f16c(base.size());  // the AVX2 kernel: the same bits
      ExtrapolateHalf(n, base.data(), a / s1, slope_half.data(), b / s2,
                      quadratic ? curve_half.data() : nullptr, f16c.data(), true);
      EXPECT_EQ(f16c, out) << "n " << n << " quadratic " << quadratic;
      double worst = 0.0;
      for (std::size_t i = 0; i < base.size(); ++i) {
        const double exact = static_cast<double>(base[i]) + static_cast<double>(a) * slope[i] +
                             (quadratic ? static_cast<double>(b) * curve[i] : 0.0);
        worst = std::max(worst, std::abs(out[i] - exact) /
                                    (std::abs(base[i]) + std::abs(a * slope[i]) + 1e-30));
      }
      EXPECT_LT(worst, 2.0 * std::ldexp(1.0, -24)) << "n " << n << " quadratic " << quadratic;
    }
  }
}

// The reuse with D₁, D₂ in half precision against the same reuse in single precision, on the
// motion of Fig. 1 at h = 1 ms (1.6e-3 rad per step): while the two hold the same assemblies
// their extrapolated 𝕄 differ by half's rounding of s D₁ + c D₂ (2⁻¹¹ of them, with ‖D₁‖ about
// the interval's change of 𝕄, ~1e-2: ≤ 1e-5 of 𝕄), both stay within the tolerance, and the
// half one assembles about as often (its error measured on the values it uses).
TEST(MobilityReuseHalf, ExtrapolatesAsTheSinglePrecisionHistoryWithinTheTolerance) {
  if (!HasHalfDifferences()) GTEST_SKIP() << "neither AVX-512 BW nor F16C on this CPU";
  const double tolerance = 1e-4;
  FluidParams params;
  MobilityReuse half(tolerance, true), single(tolerance, false);
  double worst_half = 0.0, worst_single = 0.0, worst_apart = 0.0;
  int compared = 0;
  for (int k = 0; k < 200; ++k) {
    const std::vector<Matrix3X> x = TurnedHelices(1.6e-3 * k);
    const auto assemble_at = [&](const VecX& at, MatX* m) {
      std::vector<Matrix3X> moved = {Eigen::Map<const Matrix3X>(at.data(), 3, 33),
                                     Eigen::Map<const Matrix3X>(at.data() + 99, 3, 33)};
      AssembleMobility(params, Rods(moved), m);
    };
    VecX at(198);
    at << x[0].reshaped(), x[1].reshaped();
    MatX exact, assembled_half, assembled_single;
    assemble_at(at, &exact);
    Eigen::MatrixXf from_half, from_single;
    const bool assembled_h = half.Update(at, assemble_at, &assembled_half, &from_half);
    const bool assembled_s = single.Update(at, assemble_at, &assembled_single, &from_single);
    const double norm = exact.norm();
    if (!assembled_h) worst_half = std::max(worst_half, (from_half.cast<double>() - exact).norm() / norm);
    if (!assembled_s)
      worst_single = std::max(worst_single, (from_single.cast<double>() - exact).norm() / norm);
    if (!assembled_h && !assembled_s && half.stats().assemblies == single.stats().assemblies) {
      worst_apart = std::max(worst_apart, (from_half - from_single).cast<double>().norm() / norm);
      ++compared;
    }
  }
  std::printf("  half: %ld assemblies, worst error %.2e; single: %ld, %.2e; apart by %.2e over "
              "%d steps\n", half.stats().assemblies, worst_half, single.stats().assemblies,
              worst_single, worst_apart, compared);
  EXPECT_GT(compared, 20);
  EXPECT_GT(worst_apart, 0.0);
  EXPECT_LT(worst_apart, 1e-5);
  EXPECT_LT(worst_half, 1.5 * tolerance);
  EXPECT_LT(worst_single, 1.5 * tolerance);
  EXPECT_LE(half.stats().assemblies, single.stats().assemblies + 2);
}


// REMAP: columns that join a history get the history they would have had. Reuse A holds every
// column of 𝕄 twice from the start (interleaved: 2j and 2j + 1 are column j); reuse B holds 𝕄
// twice as [𝕄, 𝕄] until update k, then is remapped to A's layout: even columns kept from its first
// copy, odd ones kept from its second copy for odd j and assembled anew (at its held geometries)
// for even j, so runs of kept and new columns alternate. Each copy appears twice in both, so A and
// B measure the same errors and assemble at the same updates. Without half precision the passes
// over the new columns are those A made over them: after the remap B gives A's matrices bit for
// bit, at every history length (k = 1: one geometry held; 2: linear; 3 and more: quadratic, in
// mid-interval). With D₁, D₂ in half precision the new columns' past D₁ was not rounded to half
// as A's was (only the last, at the remap): their D₂ differs by that rounding, ≤ 2⁻¹¹ |D₁| per
// entry, so the extrapolation by ≤ 2⁻¹¹ |α β s (s + 1)| |D₁| ≈ 1.5e-5 |𝕄| at most (s ≤ 2, α β =
// 1/2 at equal intervals, |D₁| ≈ 1e-2 |𝕄| over an interval); measured 1.0e-6 of |𝕄|, allowed
// 1e-5, a tenth of the reuse tolerance.
void RemapAgainstHeldFromTheStart(bool half) {
  FluidParams params;
  const std::vector<Matrix3X> x0 = TurnedHelices(0.0);
  MatX probe;
  AssembleMobility(params, Rods(x0), &probe);
  const Eigen::Index n = probe.cols();
  auto geometry = [](const std::vector<Matrix3X>& x) {
    VecX g(3 * (x[0].cols() + x[1].cols()));
    g << x[0].reshaped(), x[1].reshaped();
    return g;
  };
  auto exact = [&](const VecX& g) {
    const Matrix3X all = g.reshaped(3, g.size() / 3);
    const std::vector<Matrix3X> x = {all.leftCols(33), all.rightCols(33)};
    MatX m;
    AssembleMobility(params, Rods(x), &m);
    return m;
  };
  const MobilityReuse::Assemble interleaved = [&](const VecX& g, MatX* out) {
    const MatX m = exact(g);
    out->resize(m.rows(), 2 * n);
    for (Eigen::Index j = 0; j < n; ++j) out->col(2 * j) = m.col(j), out->col(2 * j + 1) = m.col(j);
  };
  const MobilityReuse::Assemble stacked = [&](const VecX& g, MatX* out) {
    const MatX m = exact(g);
    out->resize(m.rows(), 2 * n);
    *out << m, m;
  };
  std::vector<int> old_column(static_cast<size_t>(2 * n));
  std::vector<Eigen::Index> fresh;
  for (Eigen::Index j = 0; j < n; ++j) {
    old_column[static_cast<size_t>(2 * j)] = static_cast<int>(j);
    old_column[static_cast<size_t>(2 * j + 1)] = j % 2 == 1 ? static_cast<int>(n + j) : -1;
    if (j % 2 == 0) fresh.push_back(j);
  }
  auto fresh_columns = [&](const VecX& g, MatX* out) {
    const MatX m = exact(g);
    out->resize(m.rows(), static_cast<Eigen::Index>(fresh.size()));
    for (std::size_t i = 0; i < fresh.size(); ++i)
      out->col(static_cast<Eigen::Index>(i)) = m.col(fresh[i]);
  };
  const double step_angle = 1.6e-3;
  double worst = 0.0;
  for (const int k : {1, 2, 3, 8, 29}) {
    MobilityReuse a(1e-4, half), b(1e-4, half);
    MatX assembled_a, assembled_b;
    Eigen::MatrixXf extrapolated_a, extrapolated_b;
    for (int step = 0; step < 90; ++step) {
      const VecX g = geometry(TurnedHelices(step * step_angle));
      if (step == k) b.Remap(old_column, fresh_columns);
      const bool assembled = a.Update(g, interleaved, &assembled_a, &extrapolated_a);
      ASSERT_EQ(b.Update(g, step < k ? stacked : interleaved, &assembled_b, &extrapolated_b),
                assembled)
          << "k " << k << " update " << step;
      if (assembled || step < k) continue;
      const double difference =
          (extrapolated_a - extrapolated_b).cast<double>().norm() / assembled_a.norm();
      worst = std::max(worst, difference);
      if (!half) {
        ASSERT_EQ(difference, 0.0) << "k " << k << " update " << step;
      }
    }
    EXPECT_EQ(b.stats().remaps, 1);
    EXPECT_EQ(b.stats().assemblies, a.stats().assemblies) << "k " << k;
    EXPECT_LT(a.stats().assemblies, 90 / 3) << "k " << k;  // it did extrapolate
  }
  std::printf("  half %d: remapped against held from the start, worst %.2e of |M|\n", half, worst);
  EXPECT_LT(worst, 1e-5);
}

TEST(MobilityReuse, RemappedColumnsContinueAsIfHeldFromTheStart) {
  RemapAgainstHeldFromTheStart(false);
}

TEST(MobilityReuseHalf, RemappedColumnsContinueAsIfHeldFromTheStart) {
  if (!HasHalfDifferences()) GTEST_SKIP() << "neither AVX-512 BW nor F16C on this CPU";
  RemapAgainstHeldFromTheStart(true);
}

// Row weights (the matrix-free operator's near blocks keep a symmetric 3 × 3 block's six entries,
// the off-diagonal ones weighted 2): 300 symmetric blocks depending smoothly on the position
// along a gently curved path, held as nine rows and as six. The six-row history measures the
// nine-row one's errors (to rounding), so it assembles at the same steps and extrapolates the
// same values; without the weights its measure differs. With half-precision differences (the
// default from tolerance 1e-4) the same bits; with single-precision ones to float rounding (the
// vectorized passes contract their multiply–adds by an entry's position in the vector: 6e-8 of
// the largest entry, measured 0 or 1 ulp).
void SymmetricBlocksAgainstFullOnes(bool half) {
  const int blocks = 300;
  std::mt19937 rng(17);
  std::normal_distribution<double> normal;
  MatX terms[3];
  for (MatX& m : terms) m = MatX::NullaryExpr(6, blocks, [&](Eigen::Index, Eigen::Index) { return normal(rng); });
  const auto six_rows = [&](double t) {  // the blocks' distinct entries at t
    return MatX(terms[0] + std::sin(t) * terms[1] + 0.3 * t * t * terms[2]);
  };
  const auto nine_rows = [&](double t) {
    const MatX e = six_rows(t);
    MatX m(9, blocks);
    for (Eigen::Index j = 0; j < blocks; ++j)
      m.col(j) << e(0, j), e(1, j), e(2, j), e(1, j), e(3, j), e(4, j), e(2, j), e(4, j), e(5, j);
    return m;
  };
  const int in_nine[6] = {0, 1, 2, 4, 5, 8};  // where each of the six sits in the nine
  MobilityReuse nine(1e-4, half), six(1e-4, half), unweighted(1e-4, half);
  six.set_row_weights({1.0, 2.0, 2.0, 1.0, 2.0, 1.0});
  bool same_bits = true;
  double worst = 0.0;  // of the extrapolated entries, relative to the largest
  for (int k = 0; k < 150; ++k) {
    const double t = 0.004 * k;
    VecX x(6);
    x << t, 0.05 * t * t, 1.0, -t, 0.0, 2.0;
    MatX assembled;
    Eigen::MatrixXf full, packed, other;
    const bool a9 = nine.Update(x, [&](const VecX&, MatX* m) { *m = nine_rows(t); }, &assembled, &full);
    const bool a6 = six.Update(x, [&](const VecX&, MatX* m) { *m = six_rows(t); }, &assembled, &packed);
    unweighted.Update(x, [&](const VecX&, MatX* m) { *m = six_rows(t); }, &assembled, &other);
    ASSERT_EQ(a9, a6) << "k " << k;
    if (a9) continue;
    for (int r = 0; r < 6; ++r) {
      same_bits = same_bits && packed.row(r) == full.row(in_nine[r]);
      worst = std::max(worst, static_cast<double>((packed.row(r) - full.row(in_nine[r]))
                                                      .cwiseAbs().maxCoeff() /
                                                  full.cwiseAbs().maxCoeff()));
    }
  }
  if (half) {
    EXPECT_TRUE(same_bits);
  } else {
    EXPECT_LT(worst, 2e-7);
  }
  EXPECT_EQ(six.stats().assemblies, nine.stats().assemblies) << "half " << half;
  EXPECT_LT(nine.stats().assemblies, 150 / 3) << "half " << half;  // it did extrapolate
  EXPECT_NEAR(six.stats().largest_error, nine.stats().largest_error,
              (half ? 1e-12 : 1e-5) * nine.stats().largest_error) << "half " << half;
  EXPECT_GT(std::abs(unweighted.stats().largest_error - nine.stats().largest_error),
            1e-6 * nine.stats().largest_error) << "half " << half;
}

TEST(MobilityReuse, SymmetricBlocksWithRowWeightsMeasureAsTheFullOnes) {
  SymmetricBlocksAgainstFullOnes(false);
}

TEST(MobilityReuseHalf, SymmetricBlocksWithRowWeightsMeasureAsTheFullOnes) {
  if (!HasHalfDifferences()) GTEST_SKIP() << "neither AVX-512 BW nor F16C on this CPU";
  SymmetricBlocksAgainstFullOnes(true);
}

// JUMPS: a geometry that does not continue the motion is assembled, whatever the interval: one
// helix moved by 1 cm (across the line of the turn) or the turn taken 200 steps ahead (at least
// 5 intervals of ≤ 40: past kMaxLinePosition), in the middle of an interval.
TEST(MobilityReuse, GeometriesOffTheLineAreAssembled) {
  FluidParams params;
  MobilityOptions options;
  options.reuse_tolerance = 1e-4;
  for (const bool along : {false, true}) {
    const auto op = MakeMobilityOperator(params, options);
    const double step_angle = 1.6e-3;
    for (int k = 0; k < 60; ++k) op->Update(Rods(TurnedHelices(k * step_angle)));
    const MobilityReuseHistory kept = op->reuse_history();
    ASSERT_LT(kept.since + 1, kept.interval);  // the next would be extrapolated
    const long before = op->reuse_stats().assemblies;
    std::vector<Matrix3X> x = TurnedHelices((along ? 260 : 60) * step_angle);
    if (!along) x[1].row(1).array() += 0.01;
    op->Update(Rods(x));
    MatX exact;
    AssembleMobility(params, Rods(x), &exact);
    EXPECT_EQ(op->reuse_stats().assemblies, before + 1) << "along " << along;
    EXPECT_EQ((*op->matrix() - exact).cwiseAbs().maxCoeff(), 0.0) << "along " << along;
  }
}

}  // namespace
}  // namespace stokesrods
