// Build and Apply of the regularized-Stokeslet sums, direct against the FMM, on the lattice of
// helices of the far-field mobility (65 nodes per helix as targets, 2 Gauss points per segment as
// sources, ε = 1.02e-3 m, bases 0.04 m apart). Arguments: number of helices, expansion order p of
// the FMM (0: the direct sum), at the tolerance that selects it. Counters: the error (the norm of
// stokeslet_sum.h, against the direct sum, one random g), the pairs summed exactly (near) and by
// expansions (far), the memory, 3n. A third argument, 0, takes the FMM's M2L summed directly
// instead of by Fourier transforms (the reference, fmm_m2l_fft.h); 2 builds the tree even where
// the cost model would sum directly.
// Run: OMP_NUM_THREADS=1 build/release/bench/bench_stokeslet_sum --benchmark_repetitions=3
//        --benchmark_report_aggregates_only=true   (and OMP_NUM_THREADS=2)
#include <benchmark/benchmark.h>

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>

#include "common/helix_lattice.h"
#include "stokesrods/fluid/fmm_m2l_fft.h"
#include "stokesrods/fluid/fmm_operators.h"
#include "stokesrods/fluid/mobility_operator.h"
#include "stokesrods/fluid/stokeslet_sum.h"

namespace stokesrods {
namespace {

using Lattice = testing::PointCloud;

// N helices on rows × cols: 1 = 1×1, 10 = 2×5, 20 = 4×5, 50 = 5×10, 100 = 10×10.
Lattice HelixLattice(int helices) {
  const int rows = helices == 1 ? 1 : helices == 10 ? 2 : helices == 20 ? 4 : helices == 50 ? 5 : 10;
  return testing::HelixLattice(rows, helices / rows);
}

// The tolerance of each order (fmm_sum.cc); the FMM's own cost model decides whether it is used.
// variant: 1 M2L by Fourier transforms, 0 summed directly, 2 by transforms with the tree built
// whatever the cost model says (to time what it estimates).
std::unique_ptr<StokesletSum> MakeSum(int order, int variant = 1) {
  if (order == 0) return MakeDirectStokesletSum();
  const double tolerance = order == 4 ? 1e-4 : order == 5 ? 2.1e-5 : 1.25e-6;
  return MakeFastStokesletSum(
      {.tolerance = tolerance, .choose_by_cost = variant != 2, .m2l_by_fft = variant != 0});
}

Matrix3X RandomStrengths(Eigen::Index n) {
  std::mt19937 rng(1);
  std::normal_distribution<double> normal;
  Matrix3X g(3, n);
  for (Eigen::Index k = 0; k < n; ++k) g.col(k) = Vec3(normal(rng), normal(rng), normal(rng));
  return g;
}

// max over targets of |w − w_direct| / Σ_s |S(x_t − y_s)|₂ |g_s|.
double Error(const Lattice& c, const Matrix3X& g, const Matrix3X& w) {
  auto direct = MakeDirectStokesletSum();
  direct->Build(c.sources, c.regularization, c.targets);
  Matrix3X ref;
  direct->Apply(g, &ref);
  return testing::StokesletSumError(c, g, w, ref);
}

void SetCounters(benchmark::State& st, const StokesletSum& sum, const Lattice& c) {
  const StokesletSumStats stats = sum.Stats();
  st.counters["far_pairs"] = static_cast<double>(stats.far_pairs);
  st.counters["near_pairs"] = static_cast<double>(stats.near_pairs);
  st.counters["MB"] = 8e-6 * static_cast<double>(stats.stored_values);
  st.counters["3n"] = stats.max_rank;
  // The tree's estimated cost relative to the direct sum's pairs (1 when summing directly).
  st.counters["cost_ratio"] =
      stats.cost / (static_cast<double>(c.sources.cols()) * static_cast<double>(c.targets.cols()));
  st.SetLabel(fmt::format("{} sources, {} targets", c.sources.cols(), c.targets.cols()));
}

// Arguments: helices, order (0 = the direct sum).
void BM_StokesletSumBuild(benchmark::State& st) {
  const Lattice c = HelixLattice(static_cast<int>(st.range(0)));
  auto sum = MakeSum(static_cast<int>(st.range(1)), static_cast<int>(st.range(2)));
  for (auto _ : st) sum->Build(c.sources, c.regularization, c.targets);
  SetCounters(st, *sum, c);
}

void BM_StokesletSumApply(benchmark::State& st) {
  const Lattice c = HelixLattice(static_cast<int>(st.range(0)));
  auto sum = MakeSum(static_cast<int>(st.range(1)), static_cast<int>(st.range(2)));
  sum->Build(c.sources, c.regularization, c.targets);
  const Matrix3X g = RandomStrengths(c.sources.cols());
  Matrix3X w;
  for (auto _ : st) {
    sum->Apply(g, &w);
    benchmark::DoNotOptimize(w.data());
  }
  SetCounters(st, *sum, c);
  st.counters["error"] = st.range(1) == 0 ? 0.0 : Error(c, g, w);
}

void Cases(benchmark::internal::Benchmark* b) {
  for (int helices : {10, 20, 50, 100})
    for (int order : {0, 4, 5, 6})
      for (int variant : {1, 0, 2})
        if (order > 0 || variant == 1) b->Args({helices, order, variant});
}
BENCHMARK(BM_StokesletSumBuild)->Apply(Cases)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_StokesletSumApply)->Apply(Cases)->Unit(benchmark::kMillisecond);

// The coarse level's sum of the preconditioner (sim/coarse_level.h): 8 chunks of consecutive
// nodes per helix, each a point Stokeslet at its centroid, summed at all nodes at tolerance 1e-3.
// Arguments: helices; 1 the fast sum (its cost model decides), 2 the FMM's tree whatever the cost
// model says, 0 the direct sum in single precision. Counter build_ms: one Build.
void BM_CentroidSum(benchmark::State& st) {
  const Lattice c = HelixLattice(static_cast<int>(st.range(0)));
  constexpr int kNodes = 65, kChunks = 8;
  const Eigen::Index helices = c.targets.cols() / kNodes;
  Matrix3X centroids(3, helices * kChunks);
  for (Eigen::Index h = 0; h < helices; ++h)
    for (int a = 0; a < kChunks; ++a) {
      const int begin = a * kNodes / kChunks, end = (a + 1) * kNodes / kChunks;
      centroids.col(h * kChunks + a) =
          c.targets.middleCols(h * kNodes + begin, end - begin).rowwise().mean();
    }
  const VecX eps = VecX::Constant(centroids.cols(), 1.02e-3);
  auto sum = st.range(1) != 0
                 ? MakeFastStokesletSum({.tolerance = 1e-3, .choose_by_cost = st.range(1) == 1})
                 : MakeDirectStokesletSum(true);
  const auto start = std::chrono::steady_clock::now();
  sum->Build(centroids, eps, c.targets);
  st.counters["build_ms"] =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  const Matrix3X g = RandomStrengths(centroids.cols());
  Matrix3X w;
  for (auto _ : st) {
    sum->Apply(g, &w);
    benchmark::DoNotOptimize(w.data());
  }
  const StokesletSumStats stats = sum->Stats();
  st.counters["cost_ratio"] = stats.cost / (static_cast<double>(centroids.cols()) *
                                            static_cast<double>(c.targets.cols()));
  st.counters["near_pairs"] = static_cast<double>(stats.near_pairs);
}
BENCHMARK(BM_CentroidSum)->ArgsProduct({{20, 50, 100}, {1, 2, 0}})->Unit(benchmark::kMillisecond);

// The V-list translations of one level alone: 64 boxes, each taking the first `entries` of the
// 316 offsets (all: 20 224 M2Ls) from random source boxes. Arguments: order p; 1 by Fourier
// transforms in single precision (fmm_m2l_fft.h), 0 evaluated directly in single precision
// (AddM2l); entries per box. Counter: ns per M2L (with one entry per box: the transforms' cost).
void BM_M2lLevel(benchmark::State& st) {
  const int order = static_cast<int>(st.range(0));
  const FmmOperators& op = GetFmmOperators(order, 1e-6);
  constexpr int kBoxes = 64;
  std::mt19937 rng(2);
  std::uniform_int_distribution<int> pick(0, kBoxes - 1);
  FmmList list;
  for (int t = 0; t < kBoxes; ++t) {
    for (int o = 0, taken = 0; o < 343 && taken < st.range(2); ++o)
      if (std::max({std::abs(o / 49 - 3), std::abs(o / 7 % 7 - 3), std::abs(o % 7 - 3)}) >= 2) {
        ++taken;
        list.box.push_back(pick(rng));
        list.offset.push_back(o);
      }
    list.start.push_back(static_cast<int>(list.box.size()));
  }
  std::normal_distribution<double> normal;
  MatX up(3 * op.points, kBoxes);
  for (Eigen::Index k = 0; k < up.size(); ++k) up.data()[k] = normal(rng);
  MatX check = MatX::Zero(3 * op.points, kBoxes);
  M2lFftScratch<float> fft;
  M2lScratch direct;
  const M2lSpectra& spectra = GetM2lSpectra(op);
  const M2lByOffset entries = SortByOffset(list);  // once per tree, as in the FMM
  for (auto _ : st) {
    if (st.range(1) != 0) {
      AddM2lByFft(spectra, entries, up, &check, &fft);
    } else {
      for (int t = 0; t < kBoxes; ++t)
        AddM2l(op, list.box.data() + list.start[t], list.offset.data() + list.start[t],
               list.start[t + 1] - list.start[t], up, true, &direct, check.col(t).data());
    }
    benchmark::DoNotOptimize(check.data());
  }
  st.counters["ns_per_m2l"] = benchmark::Counter(
      static_cast<double>(list.box.size()) * 1e-9,
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_M2lLevel)->ArgsProduct({{4, 5, 6}, {1, 0}, {316, 1}})->Unit(benchmark::kMillisecond);

// The matrix-free RSS mobility on helices (65 nodes, r0 = 1 mm) on a lattice 4R apart (helices
// = 10, 20, 50, 100) or on a ring 3R apart (helices = -10, the bench's ring10), with the near zone
// at most `max_delta` segment lengths (12: 2 Gauss points at the default accuracy 1e-4, δ = 5.77;
// 2: 3 points, δ = 1.72; 0: the split chosen by the cost model). Counters: near blocks (3×3, per node pair), the far sum's cost estimate
// (pairs), Gauss points: the data behind the split's cost model (mobility_operator.cc).
struct Helices {
  std::vector<Matrix3X> x;
  std::vector<HydroRod> rods;
};
Helices MakeHelices(int helices) {
  const int count = std::abs(helices);
  Helices h;
  h.x.reserve(static_cast<size_t>(count));
  for (int k = 0; k < count; ++k) {
    const double helix_radius = 0.01;
    const Vec3 base = helices < 0 ? Vec3(3.0 * helix_radius / (2.0 * std::sin(kPi / count)) *
                                             Vec3(std::cos(2.0 * kPi * k / count),
                                                  std::sin(2.0 * kPi * k / count), 0.0))
                                  : Vec3(0.04 * (k / 10), 0.04 * (k % 10), 0.0);
    Matrix3X x(3, 65);
    for (int i = 0; i < 65; ++i) {
      const double z = 0.2 * i / 64.0, phi = 2.0 * kPi * z / 0.05;
      x.col(i) = base + Vec3(helix_radius * std::cos(phi), helix_radius * std::sin(phi), -z);
    }
    h.x.push_back(x);
  }
  for (const Matrix3X& x : h.x) h.rods.push_back({&x, 1e-3});
  return h;
}

std::unique_ptr<MobilityOperator> MakeMatrixFree(double max_delta) {
  MobilityOptions options;
  options.kind = MobilityKind::kMatrixFree;
  options.split_by_cost = max_delta == 0.0;  // 0: the split the cost model chooses
  options.fast_sum_near_delta = options.split_by_cost ? 12.0 : max_delta;
  return MakeMobilityOperator(FluidParams{}, options);
}

// Arguments: helices (negative: a ring), max_delta.
void BM_MatrixFreeUpdate(benchmark::State& st) {
  const Helices h = MakeHelices(static_cast<int>(st.range(0)));
  auto m = MakeMatrixFree(static_cast<double>(st.range(1)));
  for (auto _ : st) m->Update(h.rods);
}

void BM_MatrixFreeApply(benchmark::State& st) {
  const Helices h = MakeHelices(static_cast<int>(st.range(0)));
  auto m = MakeMatrixFree(static_cast<double>(st.range(1)));
  m->Update(h.rods);
  const VecX f = RandomStrengths(m->size() / 3).reshaped();
  VecX u;
  for (auto _ : st) {
    m->Apply(f, &u);
    benchmark::DoNotOptimize(u.data());
  }
  const MobilityCostCounts counts = m->cost_counts();
  st.counters["near_blocks"] = static_cast<double>(counts.near_blocks);
  st.counters["far_pairs"] = counts.far_sum_cost;
  st.counters["points"] = counts.gauss_points;
}

void MatrixFreeCases(benchmark::internal::Benchmark* b) {
  for (int helices : {-10, 10, 20, 50, 100})
    for (int max_delta : {12, 2, 0}) b->Args({helices, max_delta});
}
BENCHMARK(BM_MatrixFreeUpdate)->Apply(MatrixFreeCases)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MatrixFreeApply)->Apply(MatrixFreeCases)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace stokesrods

BENCHMARK_MAIN();
