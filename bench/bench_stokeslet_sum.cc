// Build and Apply of the regularized-Stokeslet sums, direct against fast, on the lattice of
// helices of the far-field mobility (65 nodes per helix as targets, 2 Gauss points per segment as
// sources, ε = 1.02e-3 m, bases 0.04 m apart). Arguments: number of helices, −log10(tolerance).
// Run: OMP_NUM_THREADS=1 build/release/bench/bench_stokeslet_sum --benchmark_repetitions=3
//        --benchmark_report_aggregates_only=true   (and OMP_NUM_THREADS=2)
#include <benchmark/benchmark.h>

#include <fmt/format.h>

#include <cmath>
#include <random>

#include "stokesrods/fluid/stokeslet_sum.h"

namespace stokesrods {
namespace {

struct Lattice {
  Matrix3X sources, targets;
  VecX regularization;
};

// N helices on rows × cols: 1 = 1×1, 10 = 2×5, 20 = 4×5, 50 = 5×10, 100 = 10×10.
Lattice HelixLattice(int helices) {
  const int rows = helices == 1 ? 1 : helices == 10 ? 2 : helices == 20 ? 4 : helices == 50 ? 5 : 10;
  const int cols = helices / rows;
  const int nodes = 65;
  const double radius = 0.01, pitch = 0.05, length = 0.2, spacing = 0.04;
  Lattice c;
  c.targets.resize(3, rows * cols * nodes);
  c.sources.resize(3, rows * cols * 2 * (nodes - 1));
  int nt = 0, ns = 0;
  for (int i = 0; i < rows; ++i) {
    for (int j = 0; j < cols; ++j) {
      const Vec3 base(spacing * i, spacing * j, 0.0);
      auto at = [&](double z) {
        const double phi = 2.0 * kPi * z / pitch;
        return Vec3(base + Vec3(radius * std::cos(phi), radius * std::sin(phi), -z));
      };
      for (int k = 0; k < nodes; ++k) c.targets.col(nt++) = at(length * k / (nodes - 1));
      for (int k = 0; k + 1 < nodes; ++k)
        for (double a : {0.5 - 0.5 / std::sqrt(3.0), 0.5 + 0.5 / std::sqrt(3.0)})
          c.sources.col(ns++) = at(length * (k + a) / (nodes - 1));
    }
  }
  c.regularization = VecX::Constant(ns, 1.02e-3);
  return c;
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
