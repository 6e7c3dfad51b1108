// Build and Apply of the regularized-Stokeslet sums, direct against fast, on the lattice of
// helices of the far-field mobility (65 nodes per helix as targets, 2 Gauss points per segment as
// sources, ε = 1.02e-3 m, bases 0.04 m apart). Arguments: number of helices, −log10(tolerance).
// Run: OMP_NUM_THREADS=1 build/release/bench/bench_stokeslet_sum --benchmark_repetitions=3
//        --benchmark_report_aggregates_only=true   (and OMP_NUM_THREADS=2)
#include <benchmark/benchmark.h>

#include <fmt/format.h>

#include <cmath>
#include <random>

#include "common/helix_lattice.h"
#include "stokesrods/fluid/stokeslet_sum.h"

namespace stokesrods {
namespace {

using Lattice = testing::PointCloud;

// N helices on rows × cols: 1 = 1×1, 10 = 2×5, 20 = 4×5, 50 = 5×10, 100 = 10×10.
Lattice HelixLattice(int helices) {
  const int rows = helices == 1 ? 1 : helices == 10 ? 2 : helices == 20 ? 4 : helices == 50 ? 5 : 10;
  return testing::HelixLattice(rows, helices / rows);
}

std::unique_ptr<StokesletSum> MakeSum(int digits) {
  if (digits == 0) return MakeDirectStokesletSum();
  return MakeFastStokesletSum({.tolerance = std::pow(10.0, -digits)});
}

void SetCounters(benchmark::State& st, const StokesletSum& sum, const Lattice& c) {
  const StokesletSumStats stats = sum.Stats();
  st.counters["far_pairs"] = static_cast<double>(stats.far_pairs);
  st.counters["near_pairs"] = static_cast<double>(stats.near_pairs);
  st.counters["MB"] = 8e-6 * static_cast<double>(stats.stored_values);
  st.counters["max_rank"] = stats.max_rank;
  st.SetLabel(fmt::format("{} sources, {} targets", c.sources.cols(), c.targets.cols()));
}

// Arguments: helices, digits (0 = the direct sum).
void BM_StokesletSumBuild(benchmark::State& st) {
  const Lattice c = HelixLattice(static_cast<int>(st.range(0)));
  auto sum = MakeSum(static_cast<int>(st.range(1)));
  for (auto _ : st) sum->Build(c.sources, c.regularization, c.targets);
  SetCounters(st, *sum, c);
}

void BM_StokesletSumApply(benchmark::State& st) {
  const Lattice c = HelixLattice(static_cast<int>(st.range(0)));
  auto sum = MakeSum(static_cast<int>(st.range(1)));
  sum->Build(c.sources, c.regularization, c.targets);
  std::mt19937 rng(1);
  std::normal_distribution<double> normal;
  Matrix3X g(3, c.sources.cols());
  for (Eigen::Index k = 0; k < g.cols(); ++k) g.col(k) = Vec3(normal(rng), normal(rng), normal(rng));
  Matrix3X w;
  for (auto _ : st) {
    sum->Apply(g, &w);
    benchmark::DoNotOptimize(w.data());
  }
  SetCounters(st, *sum, c);
}

void Cases(benchmark::internal::Benchmark* b) {
  for (int helices : {1, 10, 20, 50, 100})
    for (int digits : {0, 4, 6, 8}) b->Args({helices, digits});
}
BENCHMARK(BM_StokesletSumBuild)->Apply(Cases)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_StokesletSumApply)->Apply(Cases)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace stokesrods

BENCHMARK_MAIN();
