// Speed of the pieces of a time step and of whole steps, on the paper's cases.
// Run: build/release/bench/bench_step --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>

#include "common/helix_lattice.h"
#include "stokesrods/contact/broad_phase.h"
#include "stokesrods/contact/segment_distance.h"
#include "stokesrods/fluid/mobility_reuse_half.h"
#include "stokesrods/io/build_model.h"
#include "stokesrods/io/config.h"
#include "stokesrods/sim/coarse_level.h"
#include "stokesrods/sim/elastic_assembly.h"
#include "stokesrods/sim/hydro_coupling.h"
#include "stokesrods/sim/integrator.h"
#include "stokesrods/solver/blas.h"
#include "stokesrods/solver/dense_lu.h"

extern "C" {  // LAPACK's banded LU, the reference BandedMatrix replaced (OpenBLAS)
void dgbtrf_(const int* m, const int* n, const int* kl, const int* ku, double* ab,
             const int* ldab, int* ipiv, int* info);
void dgbtrs_(const char* trans, const int* n, const int* kl, const int* ku, const int* nrhs,
             const double* ab, const int* ldab, const int* ipiv, double* b, const int* ldb,
             int* info, std::size_t trans_len);
}

extern "C" void sgetrf_(const int* m, const int* n, float* a, const int* lda, int* ipiv, int* info);

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

// One rod's elastic assembly: by edges (AddElasticForces, its stencils on the widest instruction
// set, on AVX2 or one at a time) or by the reference path, stencil by stencil
// (AddElasticForcesPerStencil).
using ElasticAssembly = double (*)(const RodModel&, const VecX&, const RodFrames&, VecX*,
                                   BandedMatrix*);
template <StencilPath kPath>
double ByEdges(const RodModel& rod, const VecX& q, const RodFrames& frames, VecX* force,
               BandedMatrix* hessian) {
  return AddElasticForces(rod, q, frames, force, hessian, kPath);
}

void BM_ElasticForcesAndJacobian(benchmark::State& st, ElasticAssembly assemble) {
  const Model model = PaperModel(1, static_cast<int>(st.range(0)), "none", "implicit");
  const State rest = MakeRestState(model);
  BandedMatrix jac(model.num_dofs, 10);
  VecX force(model.num_dofs);
  for (auto _ : st) {
    force.setZero();
    jac.SetZero();
    assemble(model.rods[0], rest.q, rest.rods[0], &force, &jac);
    benchmark::DoNotOptimize(force.data());
  }
  st.SetComplexityN(st.range(0));
}
BENCHMARK_CAPTURE(BM_ElasticForcesAndJacobian, by_edges, &ByEdges<StencilPath::kWidest>)
    ->RangeMultiplier(4)->Range(64, 4096)->Complexity(benchmark::oN)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_ElasticForcesAndJacobian, by_edges_avx2, &ByEdges<StencilPath::kAvx2>)
    ->Arg(64)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_ElasticForcesAndJacobian, by_edges_portable,
                  &ByEdges<StencilPath::kPortable>)
    ->Arg(64)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_ElasticForcesAndJacobian, per_stencil, &AddElasticForcesPerStencil)
    ->Arg(64)->Unit(benchmark::kMicrosecond);

// The forces alone (the Newton test's evaluation at each trial point).
void BM_ElasticForces(benchmark::State& st, ElasticAssembly assemble) {
  const Model model = PaperModel(1, static_cast<int>(st.range(0)), "none", "implicit");
  const State rest = MakeRestState(model);
  VecX force(model.num_dofs);
  for (auto _ : st) {
    force.setZero();
    assemble(model.rods[0], rest.q, rest.rods[0], &force, nullptr);
    benchmark::DoNotOptimize(force.data());
  }
}
BENCHMARK_CAPTURE(BM_ElasticForces, by_edges, &ByEdges<StencilPath::kWidest>)->Arg(64)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_ElasticForces, by_edges_portable, &ByEdges<StencilPath::kPortable>)
    ->Arg(64)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_ElasticForces, per_stencil, &AddElasticForcesPerStencil)->Arg(64)
    ->Unit(benchmark::kMicrosecond);

// The banded Newton matrix of one rod (N nodes, 4N − 1 DOFs, half bandwidth 10): LU and one solve.
BandedMatrix RandomRodJacobian(int nodes) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  BandedMatrix a(4 * nodes - 1, 10);
  for (int i = 0; i < a.size(); ++i)
    for (int j = std::max(0, i - 10); j <= std::min(a.size() - 1, i + 10); ++j)
      a(i, j) = (i == j ? 20.0 : 0.0) + u(rng);
  return a;
}

void BM_BandedFactorize(benchmark::State& st) {
  const BandedMatrix a = RandomRodJacobian(static_cast<int>(st.range(0)));
  for (auto _ : st) {
    BandedMatrix lu = a;
    benchmark::DoNotOptimize(lu.Factorize());
  }
  st.SetComplexityN(st.range(0));
}
BENCHMARK(BM_BandedFactorize)->Arg(65)->Arg(195)->Arg(1025)->Complexity(benchmark::oN)
    ->Unit(benchmark::kMicrosecond);

void BM_BandedSolve(benchmark::State& st) {
  BandedMatrix lu = RandomRodJacobian(static_cast<int>(st.range(0)));
  lu.Factorize();
  VecX b = VecX::Ones(lu.size());
  for (auto _ : st) {
    lu.Solve(&b);
    benchmark::DoNotOptimize(b.data());
  }
  st.SetComplexityN(st.range(0));
}
BENCHMARK(BM_BandedSolve)->Arg(65)->Arg(195)->Arg(1025)->Complexity(benchmark::oN)
    ->Unit(benchmark::kMicrosecond);

// The Schur blocks' solve: a unit right-hand side per position DOF (3 per node) at once.
void BM_BandedSolveMany(benchmark::State& st) {
  BandedMatrix lu = RandomRodJacobian(static_cast<int>(st.range(0)));
  lu.Factorize();
  const MatX b = MatX::Identity(lu.size(), 3 * st.range(0));
  for (auto _ : st) {
    MatX x = b;
    lu.Solve(&x);
    benchmark::DoNotOptimize(x.data());
  }
}
BENCHMARK(BM_BandedSolveMany)->Arg(65)->Unit(benchmark::kMicrosecond);

// A product with Fig. 1's 𝕄 (3M = 390): the double matrix (OpenBLAS dgemv) and the reused,
// single-precision one with double sums (solver/gemv_mixed.cc).
void BM_MobilityProduct(benchmark::State& st, bool single) {
  const int n = 390;
  const MatX a = MatX::Random(n, n);
  const Eigen::MatrixXf af = a.cast<float>();
  const VecX x = VecX::Random(n);
  VecX y(n);
  for (auto _ : st) {
    if (single)
      GemvRowsMixed(af, 0, n, x.data(), y.data());
    else
      GemvRows(a, 0, n, x.data(), y.data());
    benchmark::DoNotOptimize(y.data());
  }
}
BENCHMARK_CAPTURE(BM_MobilityProduct, double, false)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_MobilityProduct, single_double_sums, true)->Unit(benchmark::kMicrosecond);

// One step's pass of the dense 𝕄's reuse on Fig. 1 (3M = 390, fluid/mobility_reuse.h): forming
// 𝕄 = 𝕄_c + s D₁ + c D₂ with D₁, D₂ in single precision (the portable pass, cloned for AVX-512 F
// and AVX2 as in mobility_reuse.cc) or in half precision (fluid/mobility_reuse_half.h).
__attribute__((target_clones("avx512f", "avx2", "default"))) void ExtrapolateSingle(
    Eigen::Index n, const float* base, float s, const float* slope, float c, const float* curve,
    float* out) {
#pragma omp simd
  for (Eigen::Index i = 0; i < n; ++i) out[i] = base[i] + s * slope[i] + c * curve[i];
}
void BM_ReuseExtrapolate(benchmark::State& st, bool half) {
  if (!HasHalfDifferences()) return st.SkipWithError("neither AVX-512 BW nor F16C on this CPU");
  const int n = 390;
  const Eigen::MatrixXf base = Eigen::MatrixXf::Random(n, n);
  Eigen::MatrixXf slope = 1e-2f * Eigen::MatrixXf::Random(n, n);
  Eigen::MatrixXf curve = 1e-4f * Eigen::MatrixXf::Random(n, n);
  std::vector<std::uint16_t> slope_half(static_cast<std::size_t>(n) * n), curve_half(slope_half);
  const float slope_scale = RoundToHalf(slope.size(), slope.data(), slope_half.data());
  const float curve_scale = RoundToHalf(curve.size(), curve.data(), curve_half.data());
  Eigen::MatrixXf out(n, n);
  const float s = 0.37f, c = s * (s + 1.0f);
  for (auto _ : st) {
    if (half)
      ExtrapolateHalf(out.size(), base.data(), s / slope_scale, slope_half.data(),
                      c / curve_scale, curve_half.data(), out.data());
    else
      ExtrapolateSingle(out.size(), base.data(), s, slope.data(), c, curve.data(), out.data());
    benchmark::DoNotOptimize(out.data());
  }
}
BENCHMARK_CAPTURE(BM_ReuseExtrapolate, single, false)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_ReuseExtrapolate, half, true)->Unit(benchmark::kMicrosecond);

// The preconditioner's solve of one vector with a float LU of size n: Fig. 1's C (3M = 390) and
// the coarse level's E on 100 helices (2400; from 1024 on, the panels over the OpenMP threads):
// getrs against the blocked substitution of solver/lu_solve_avx512.cc (AVX-512) or
// lu_solve_avx2.cc, and that substitution on factors in half precision (LuStorage::kHalf, as the
// preconditioners keep them; where the CPU has neither kernel, kHalf keeps floats).
void BM_FloatLuSolve(benchmark::State& st, bool lapack, LuStorage storage) {
  const int n = static_cast<int>(st.range(0));
  const Eigen::MatrixXf a = Eigen::MatrixXf::Random(n, n) + n * Eigen::MatrixXf::Identity(n, n);
  DenseLu<float> lu;
  lu.Compute(a, storage);
  const Eigen::VectorXf b = Eigen::VectorXf::Random(n);
  for (auto _ : st) {
    Eigen::VectorXf x = b;
    lu.Solve(&x, lapack);
    benchmark::DoNotOptimize(x.data());
  }
}
BENCHMARK_CAPTURE(BM_FloatLuSolve, getrs, true, LuStorage::kNative)
    ->Arg(390)->Arg(2400)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_FloatLuSolve, blocked, false, LuStorage::kNative)
    ->Arg(390)->Arg(2400)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_FloatLuSolve, half, false, LuStorage::kHalf)
    ->Arg(390)->Arg(2400)->Unit(benchmark::kMicrosecond);

// The same from memory, as in a step, where the rest of the step's data has evicted the factors
// (E at a hundred helices, 11.5 MB in half precision): 64 MB read between the timed solves.
void BM_FloatLuSolveCold(benchmark::State& st, LuStorage storage) {
  const int n = static_cast<int>(st.range(0));
  const Eigen::MatrixXf a = Eigen::MatrixXf::Random(n, n) + n * Eigen::MatrixXf::Identity(n, n);
  DenseLu<float> lu;
  lu.Compute(a, storage);
  const Eigen::VectorXf b = Eigen::VectorXf::Random(n);
  const Eigen::VectorXf evict = Eigen::VectorXf::Ones(16 << 20);
  for (auto _ : st) {
    st.PauseTiming();
    float sum = evict.sum();
    benchmark::DoNotOptimize(sum);
    Eigen::VectorXf x = b;
    st.ResumeTiming();
    lu.Solve(&x);
    benchmark::DoNotOptimize(x.data());
  }
}
BENCHMARK_CAPTURE(BM_FloatLuSolveCold, blocked, LuStorage::kNative)
    ->Arg(2400)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_FloatLuSolveCold, half, LuStorage::kHalf)
    ->Arg(2400)->Unit(benchmark::kMicrosecond);

// The preconditioner's fine level on a hundred helices (CapacitancePreconditioner::SolveBlocks):
// a hundred LUs of 195 × 195 (65 nodes) in half precision, 7.6 MB, solved in turn. Variant 0 as
// SolveBlocks: each solve brings the next one's factors into L2 along the way
// (DenseLu::SolveThenPrefetch); 1: the next one's prefetched at once before each solve (before
// session 35); 2: variant 0 from cache. 0 and 1 from memory: 64 MB read between the timed passes,
// as the rest of a step evicts the factors. Counter: µs per block.
void BM_BlockSolves(benchmark::State& st) {
  const int n = 195, blocks = static_cast<int>(st.range(0)), variant = static_cast<int>(st.range(1));
  std::vector<DenseLu<float>> lu(static_cast<std::size_t>(blocks));
  for (auto& l : lu)
    l.Compute(Eigen::MatrixXf(Eigen::MatrixXf::Random(n, n) + n * Eigen::MatrixXf::Identity(n, n)),
              LuStorage::kHalf);
  const Eigen::VectorXf b = Eigen::VectorXf::Random(n);
  const Eigen::VectorXf evict = Eigen::VectorXf::Ones(16 << 20);
  for (auto _ : st) {
    if (variant != 2) {
      st.PauseTiming();
      float sum = evict.sum();
      benchmark::DoNotOptimize(sum);
      st.ResumeTiming();
    }
    for (int k = 0; k < blocks; ++k) {
      Eigen::VectorXf x = b;
      const DenseLu<float>& lu_k = lu[static_cast<std::size_t>(k)];
      if (k + 1 == blocks) {
        lu_k.Solve(&x);
      } else if (variant == 1) {
        lu[static_cast<std::size_t>(k) + 1].Prefetch();
        lu_k.Solve(&x);
      } else {
        lu_k.SolveThenPrefetch(&x, lu[static_cast<std::size_t>(k) + 1]);
      }
      benchmark::DoNotOptimize(x.data());
    }
  }
  st.counters["us_per_block"] = benchmark::Counter(
      static_cast<double>(blocks) * 1e-6,
      benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_BlockSolves)->Args({100, 0})->Args({100, 1})->Args({100, 2})
    ->Unit(benchmark::kMicrosecond);

// The float LU's factorization at the coarse level's sizes (E: 1200 at fifty helices, 2400 at a
// hundred): one getrf call against LuFactor (from kBlockedLuFrom getrf's blocked algorithm with
// its updates over the OpenMP threads, solver/dense_lu.h); run with OMP_NUM_THREADS 1 and 2.
void BM_FloatLuFactor(benchmark::State& st, bool getrf) {
  const int n = static_cast<int>(st.range(0));
  const Eigen::MatrixXf a = Eigen::MatrixXf::Random(n, n);
  Eigen::MatrixXf f;
  std::vector<int> pivots(static_cast<size_t>(n));
  int info = 0;
  for (auto _ : st) {
    f = a;
    if (getrf)
      sgetrf_(&n, &n, f.data(), &n, pivots.data(), &info);
    else
      LuFactor(n, f.data(), pivots.data(), &info);
    benchmark::DoNotOptimize(f.data());
  }
}
BENCHMARK_CAPTURE(BM_FloatLuFactor, getrf, true)->Arg(1200)->Arg(2400)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_FloatLuFactor, blocked, false)->Arg(1200)->Arg(2400)->Unit(benchmark::kMillisecond);

// The same with LAPACK (dgbtrf, then dgbtrs for one right-hand side), same storage.
void BM_BandedLapack(benchmark::State& st, bool solve) {
  const int nodes = static_cast<int>(st.range(0)), n = 4 * nodes - 1, kd = 10, ldab = 3 * kd + 1;
  const MatX dense = RandomRodJacobian(nodes).ToDense();
  std::vector<double> band(static_cast<std::size_t>(ldab) * n, 0.0);
  for (int j = 0; j < n; ++j)
    for (int i = std::max(0, j - kd); i <= std::min(n - 1, j + kd); ++i)
      band[static_cast<std::size_t>(2 * kd + i - j + j * ldab)] = dense(i, j);
  std::vector<int> pivots(static_cast<std::size_t>(n));
  std::vector<double> lu = band;
  int info = 0, one = 1;
  dgbtrf_(&n, &n, &kd, &kd, lu.data(), &ldab, pivots.data(), &info);
  VecX b = VecX::Ones(n);
  const char trans = 'N';
  for (auto _ : st) {
    if (solve) {
      dgbtrs_(&trans, &n, &kd, &kd, &one, lu.data(), &ldab, pivots.data(), b.data(), &n, &info, 1);
      benchmark::DoNotOptimize(b.data());
    } else {
      lu = band;
      dgbtrf_(&n, &n, &kd, &kd, lu.data(), &ldab, pivots.data(), &info);
      benchmark::DoNotOptimize(lu.data());
    }
  }
}
BENCHMARK_CAPTURE(BM_BandedLapack, factorize, false)->Arg(65)->Arg(195)->Arg(1025)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_BandedLapack, solve, true)->Arg(65)->Arg(195)->Arg(1025)
    ->Unit(benchmark::kMicrosecond);

// Contact broad phase (uniform grid) on a lattice of k × k helices, against brute force.
std::vector<Matrix3X> LatticeRods(int k) {
  const testing::PointCloud c = testing::HelixLattice(k, k);
  std::vector<Matrix3X> rods;
  for (int r = 0; r < k * k; ++r) rods.push_back(c.targets.middleCols(65 * r, 65));
  return rods;
}

void BroadPhase(benchmark::State& st, bool brute_force) {
  const std::vector<Matrix3X> rods = LatticeRods(static_cast<int>(st.range(0)));
  std::vector<const Matrix3X*> pointers;
  for (const Matrix3X& x : rods) pointers.push_back(&x);
  std::size_t pairs = 0;
  for (auto _ : st) {
    const auto found = brute_force ? FindCandidatePairsBruteForce(pointers, 2e-3, 1)
                                   : FindCandidatePairs(pointers, 2e-3, 1);
    pairs = found.size();
  }
  st.SetLabel(fmt::format("{} helices, {} candidate pairs", rods.size(), pairs));
}
BENCHMARK_CAPTURE(BroadPhase, grid, false)->Arg(2)->Arg(4)->Arg(10)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BroadPhase, brute_force, true)->Arg(2)->Arg(4)->Arg(10)
    ->Unit(benchmark::kMicrosecond);

// The broad phase on moving rods, a new search at every call against the search kept across calls
// (CandidatePairList, a Verlet list with a skin of the margin): each rod of the lattice sways by
// 2 mm along its own direction at up to 16 µm per call (Fig. 1's flagella at h = 1 ms), so the
// kept list is found again every few dozen calls; both time the motion too (O(nodes)). Counter
// searches_per_call.
void BroadPhaseMoving(benchmark::State& st, bool kept) {
  const std::vector<Matrix3X> rest = LatticeRods(static_cast<int>(st.range(0)));
  std::vector<Matrix3X> rods = rest;
  std::vector<const Matrix3X*> pointers;
  for (const Matrix3X& x : rods) pointers.push_back(&x);
  CandidatePairList list;
  std::size_t pairs = 0;
  long calls = 0, searches = 0;
  constexpr double kAmplitude = 2e-3, kRate = 16e-6 / kAmplitude;  // per call
  for (auto _ : st) {
    const double sway = kAmplitude * std::sin(kRate * static_cast<double>(calls++));
    for (std::size_t r = 0; r < rods.size(); ++r) {
      const double angle = static_cast<double>(r);
      rods[r] = rest[r].colwise() + sway * Vec3(std::cos(angle), std::sin(angle), 0.0);
    }
    if (kept) {
      pairs = list.Pairs(pointers, 2e-3, 1).size();
    } else {
      pairs = FindCandidatePairs(pointers, 2e-3, 1).size();
      ++searches;
    }
  }
  if (kept) searches = list.searches();
  st.counters["searches_per_call"] =
      static_cast<double>(searches) / static_cast<double>(std::max(calls, 1L));
  st.SetLabel(fmt::format("{} helices, {} pairs", rods.size(), pairs));
}
BENCHMARK_CAPTURE(BroadPhaseMoving, new_search, false)->Arg(2)->Arg(4)->Arg(10)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BroadPhaseMoving, kept, true)->Arg(2)->Arg(4)->Arg(10)
    ->Unit(benchmark::kMicrosecond);

// Contact narrow phase: closest points of random segment pairs, per pair.
void BM_SegmentClosestPoints(benchmark::State& st) {
  std::mt19937 rng(5);
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<Vec3> p(4096);
  for (Vec3& v : p) v = Vec3(n(rng), n(rng), n(rng));
  std::size_t i = 0;
  for (auto _ : st) {
    benchmark::DoNotOptimize(ClosestPointsBetweenSegments(p[i], p[i + 1], p[i + 2], p[i + 3]));
    i = (i + 4) % p.size();
  }
}
BENCHMARK(BM_SegmentClosestPoints);

// The coarse level of the preconditioner (sim/coarse_level.h) on a lattice of helices 4 cm apart
// (10 = 2 × 5, 20 = 4 × 5, 50 = 5 × 10), with random diagonally dominant per-rod blocks: one
// application as CapacitancePreconditioner::Apply makes it (c = E⁻¹ Zᵀ v, W c, Z c). Arguments:
// helices; the layout, 0 eight chunks of forces, 1 four chunks of forces and turns at four points
// each. Counter build_ms: one Build.
void BM_CoarseLevelApply(benchmark::State& st) {
  const int helices = static_cast<int>(st.range(0)), rows = helices == 10 ? 2 : helices == 20 ? 4 : 5;
  const Matrix3X all = testing::HelixLattice(rows, helices / rows).targets;
  constexpr int kNodes = 65;
  std::vector<Matrix3X> x;
  std::vector<MatX> blocks;
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  for (int r = 0; r < helices; ++r) {
    x.push_back(all.middleCols(r * kNodes, kNodes));
    blocks.push_back(MatX::NullaryExpr(3 * kNodes, 3 * kNodes, [&]() { return normal(rng); }) +
                     50.0 * MatX::Identity(3 * kNodes, 3 * kNodes));
  }
  std::vector<CoarseRod> rods;
  for (int r = 0; r < helices; ++r) rods.push_back({.x = &x[static_cast<size_t>(r)], .eps = 1.02e-3, .node_offset = r * kNodes, .fixed_nodes = 2});
  const CoarseLayout layout = st.range(1) == 0 ? CoarseLayout{}
                                               : CoarseLayout{.chunks_per_rod = 4, .turns = true, .points_per_chunk = 4};
  CoarseLevel coarse;
  const auto start = std::chrono::steady_clock::now();
  coarse.Build(rods, blocks, 0.37, layout);
  st.counters["build_ms"] =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  const VecX v = VecX::NullaryExpr(3 * kNodes * helices, [&]() { return normal(rng); });
  VecX wc, y;
  for (auto _ : st) {
    const VecX c = coarse.Solve(v);
    coarse.ApplyW(c, &wc);
    y = v - wc;
    coarse.AddZ(c, &y);
    benchmark::DoNotOptimize(y.data());
  }
}
BENCHMARK(BM_CoarseLevelApply)->ArgsProduct({{10, 20, 50}, {0, 1}})->Unit(benchmark::kMicrosecond);

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
