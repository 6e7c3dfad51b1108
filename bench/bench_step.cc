// Speed of the pieces of a time step and of whole steps, on the paper's cases.
// Run: build/release/bench/bench_step --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <fmt/format.h>

#include "stokesrods/io/build_model.h"
#include "stokesrods/io/config.h"
#include "stokesrods/sim/elastic_assembly.h"
#include "stokesrods/sim/hydro_coupling.h"
#include "stokesrods/sim/integrator.h"

namespace stokesrods {
namespace {

// One or two of the paper's helices (3R apart), N nodes, the given fluid model and coupling.
Model PaperModel(int rods, int nodes, const std::string& fluid, const std::string& coupling,
                 double h = 1e-3) {
  std::string text = fmt::format(
      "[run]\nduration = 1.0\ntime_step = {}\n[fluid]\nmodel = \"{}\"\ncoupling = \"{}\"\n"
      "[contact]\nenabled = true\n",
      h, fluid, coupling);
  for (int r = 0; r < rods; ++r)
    text += fmt::format("[[rods]]\nnodes = {}\nomega_bar = 533\nbase = [{}, 0.0, 0.0]\n", nodes,
                        0.03 * r);
  return BuildModel(ParseConfig(text, "bench.toml"));
}

void BM_RssMobilityAssembly(benchmark::State& st) {
  const Model model = PaperModel(static_cast<int>(st.range(0)), 65, "rss", "implicit");
  const State rest = MakeRestState(model);
  std::vector<Matrix3X> x;
  for (int r = 0; r < static_cast<int>(model.rods.size()); ++r) x.push_back(RodPositions(model, r, rest.q));
  const std::vector<HydroRod> rods = MakeHydroRods(model, x);
  MatX m;
  for (auto _ : st) {
    AssembleMobility(model.fluid, rods, &m);
    benchmark::DoNotOptimize(m.data());
  }
  st.SetLabel(fmt::format("{} helices, 3M = {}", model.rods.size(), m.rows()));
}
BENCHMARK(BM_RssMobilityAssembly)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);

void BM_ElasticForcesAndJacobian(benchmark::State& st) {
  const Model model = PaperModel(1, static_cast<int>(st.range(0)), "none", "implicit");
  const State rest = MakeRestState(model);
  BandedMatrix jac(model.num_dofs, 10);
  VecX force(model.num_dofs);
  for (auto _ : st) {
    force.setZero();
    jac.SetZero();
    AddElasticForces(model.rods[0], rest.q, rest.rods[0], &force, &jac);
    benchmark::DoNotOptimize(force.data());
  }
  st.SetComplexityN(st.range(0));
}
BENCHMARK(BM_ElasticForcesAndJacobian)->RangeMultiplier(4)->Range(64, 4096)
    ->Complexity(benchmark::oN)->Unit(benchmark::kMicrosecond);

// Whole steps from a state already in motion (the first 20 steps are not timed).
void StepBenchmark(benchmark::State& st, int rods, int nodes, const std::string& fluid,
                   const std::string& coupling, double h) {
  const Model model = PaperModel(rods, nodes, fluid, coupling, h);
  State state = MakeRestState(model);
  Workspace ws(model);
  for (int k = 0; k < 20; ++k) Step(model, h, &state, &ws);
  long newton = 0, steps = 0;
  for (auto _ : st) {
    const StepReport r = Step(model, h, &state, &ws);
    if (!r.ok) st.SkipWithError(r.message.c_str());
    newton += r.newton_iterations;
    ++steps;
  }
  st.counters["newton_per_step"] = static_cast<double>(newton) / static_cast<double>(steps);
  st.counters["sim_s_per_wall_s"] = benchmark::Counter(h * static_cast<double>(steps),
                                                       benchmark::Counter::kIsRate);
}
BENCHMARK_CAPTURE(StepBenchmark, rss_1helix_N65_h1ms, 1, 65, "rss", "implicit", 1e-3)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(StepBenchmark, rss_1helix_N65_h10ms, 1, 65, "rss", "implicit", 1e-2)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(StepBenchmark, rss_explicit_1helix_N65_h0.2ms, 1, 65, "rss", "explicit", 2e-4)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(StepBenchmark, lsbt_1helix_N195_h1ms, 1, 195, "lsbt", "implicit", 1e-3)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(StepBenchmark, rss_2helices_N65_h1ms, 2, 65, "rss", "implicit", 1e-3)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(StepBenchmark, rss_2helices_N65_h10ms, 2, 65, "rss", "implicit", 1e-2)
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace stokesrods

BENCHMARK_MAIN();
