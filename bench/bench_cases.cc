// Whole simulations of the paper's helices, from two (Fig. 1) to a hundred, timed step by step.
// A plain program (no Google Benchmark) so that each case runs in its own process and its peak
// memory is its own; bench/run_table.py runs the cases and prints the table (bench/README.md).
//
//   bench_cases CASE [--steps K] [--warmup W] [--set dotted.key=value]... [--step-times FILE]
//   bench_cases CASE --print-config     (the case as a configuration file, for stokesrods run)
//
// Builds the case's configuration as TOML text, applies the --set overrides (SPEC syntax), runs W
// untimed steps from rest, then K steps each timed with steady_clock, and prints one line of JSON.
// --step-times writes one CSV line per timed step (the step's number, wall ms, Newton iterations,
// GMRES products, whether 𝕄 was assembled): where periodic work falls (restart points, rebuilds).
// Exit codes: 0 success, 2 invalid input (unknown case, bad option, bad --set), 3 a step failed
// or memory ran out. The JSON line is printed in every case but a bad command line.
#include <sys/resource.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <new>
#include <numbers>
#include <numeric>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "stokesrods/io/build_model.h"
#include "stokesrods/io/config.h"
#include "stokesrods/io/runner.h"
#include "stokesrods/sim/integrator.h"
#include "stokesrods/sim/state.h"
#include "stokesrods/solver/blas.h"

namespace stokesrods {
namespace {

constexpr double kHelixRadius = 0.01;  // R [m], the paper's helix
constexpr int kDefaultWarmup = 100;  // past the start from rest (bench/run_table.py)
constexpr int kDefaultSteps = 50;

/// One benchmark case: the paper's helices (shape, material, omega_bar = 320 of Fig. 1) at the
/// given bases, N nodes each, one fluid model and coupling, one time step.
struct CaseSpec {
  std::string name;
  std::vector<Vec3> bases;  ///< node 0 of each helix [m]
  int nodes = 65;
  std::string fluid = "rss";
  std::string coupling = "implicit";
  double h = 1e-3;          ///< [s]
};

/// rows × cols helices 4R apart in the plane z = 0.
std::vector<Vec3> LatticeBases(int rows, int cols) {
  std::vector<Vec3> bases;
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j)
      bases.emplace_back(4.0 * kHelixRadius * j, 4.0 * kHelixRadius * i, 0.0);
  return bases;
}

/// n helices on a ring whose neighbouring bases are 3R apart (ring radius 3R / (2 sin(π/n))).
std::vector<Vec3> RingBases(int n) {
  const double ring = 3.0 * kHelixRadius / (2.0 * std::sin(std::numbers::pi / n));
  std::vector<Vec3> bases;
  for (int k = 0; k < n; ++k) {
    const double phi = 2.0 * std::numbers::pi * k / n;
    bases.emplace_back(ring * std::cos(phi), ring * std::sin(phi), 0.0);
  }
  return bases;
}

std::vector<std::string> CaseNames() {
  return {"fig1_h1ms",  "fig1_h10ms", "fig1_explicit", "fig1_lsbt_N195", "ring10",
          "lattice2",   "lattice4",   "lattice10",     "lattice20",      "lattice50",
          "lattice100", "lattice200", "lattice400"};
}

std::optional<CaseSpec> FindCase(const std::string& name) {
  const std::vector<Vec3> fig1 = {Vec3(0.0, 0.0, 0.0), Vec3(3.0 * kHelixRadius, 0.0, 0.0)};
  if (name == "fig1_h1ms") return CaseSpec{.name = name, .bases = fig1};
  if (name == "fig1_h10ms") return CaseSpec{.name = name, .bases = fig1, .h = 1e-2};
  if (name == "fig1_explicit")
    return CaseSpec{.name = name, .bases = fig1, .coupling = "explicit", .h = 2e-4};
  if (name == "fig1_lsbt_N195")
    return CaseSpec{.name = name, .bases = fig1, .nodes = 195, .fluid = "lsbt"};
  if (name == "ring10") return CaseSpec{.name = name, .bases = RingBases(10)};
  const std::vector<std::pair<int, std::pair<int, int>>> lattices = {
      {2, {1, 2}},   {4, {2, 2}},     {10, {2, 5}},    {20, {4, 5}},
      {50, {5, 10}}, {100, {10, 10}}, {200, {10, 20}}, {400, {20, 20}}};
  for (const auto& [count, shape] : lattices)
    if (name == fmt::format("lattice{}", count))
      return CaseSpec{.name = name, .bases = LatticeBases(shape.first, shape.second)};
  return std::nullopt;
}

/// The case as a configuration file (the keys of examples/fig1_bundling.toml).
std::string CaseToml(const CaseSpec& spec) {
  std::string text = fmt::format(
      "[run]\nname = \"bench-{}\"\nduration = 1.0\ntime_step = {}\nframes = false\n"
      "[fluid]\nmodel = \"{}\"\ncoupling = \"{}\"\n[contact]\nenabled = true\n",
      spec.name, spec.h, spec.fluid, spec.coupling);
  for (const Vec3& b : spec.bases)
    text += fmt::format(
        "[[rods]]\nshape = \"helix\"\nnodes = {}\naxis_length = 0.2\npitch = 0.05\n"
        "helix_radius = {}\nradius = 1e-3\nhandedness = \"right\"\nclamped_nodes = 2\n"
        "omega_bar = 320\nbase = [{:.17g}, {:.17g}, {:.17g}]\n",
        spec.nodes, kHelixRadius, b.x(), b.y(), b.z());
  return text;
}

double PeakRssMb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // Linux: kilobytes
}

int MaxThreads() {
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}

struct Options {
  std::string case_name;
  int steps = kDefaultSteps;
  int warmup = kDefaultWarmup;
  std::vector<std::string> overrides;
  bool print_config = false;  ///< print the case's TOML (before overrides) and exit
  std::string step_times;     ///< CSV file of the per-step times, if given
};

void PrintUsage(std::FILE* to) {
  std::string names;
  for (const std::string& n : CaseNames()) names += " " + n;
  fmt::print(to,
             "usage: bench_cases CASE [--steps K] [--warmup W] [--set dotted.key=value]...\n"
             "                  [--step-times FILE]\n"
             "       bench_cases CASE --print-config\n"
             "cases:{}\n",
             names);
}

/// Parses the command line; nullopt (after a message on stderr) when it is wrong.
std::optional<Options> ParseArgs(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() -> std::optional<std::string> {
      if (i + 1 >= argc) return std::nullopt;
      return std::string(argv[++i]);
    };
    auto count = [&](int* out) {
      const std::optional<std::string> v = value();
      if (!v) return false;
      try {
        std::size_t used = 0;
        *out = std::stoi(*v, &used);
        return used == v->size() && *out >= 0;
      } catch (const std::exception&) {
        return false;
      }
    };
    if (arg == "--steps" || arg == "--warmup") {
      if (!count(arg == "--steps" ? &o.steps : &o.warmup)) {
        fmt::print(stderr, "bench_cases: {} needs a count ≥ 0\n", arg);
        return std::nullopt;
      }
    } else if (arg == "--set") {
      const std::optional<std::string> v = value();
      if (!v) {
        fmt::print(stderr, "bench_cases: --set needs KEY=VALUE\n");
        return std::nullopt;
      }
      o.overrides.push_back(*v);
    } else if (arg.rfind("--set=", 0) == 0) {
      o.overrides.push_back(arg.substr(6));
    } else if (arg == "--step-times") {
      const std::optional<std::string> v = value();
      if (!v || v->empty()) {
        fmt::print(stderr, "bench_cases: --step-times needs a file name\n");
        return std::nullopt;
      }
      o.step_times = *v;
    } else if (arg == "--print-config") {
      o.print_config = true;
    } else if (arg == "-h" || arg == "--help") {
      PrintUsage(stdout);
      std::exit(0);
    } else if (!arg.empty() && arg[0] != '-' && o.case_name.empty()) {
      o.case_name = arg;
    } else {
      fmt::print(stderr, "bench_cases: unexpected argument '{}'\n", arg);
      return std::nullopt;
    }
  }
  if (o.case_name.empty()) {
    fmt::print(stderr, "bench_cases: no case given\n");
    return std::nullopt;
  }
  return o;
}

double Median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/// CPU time of the process (all threads) [ms].
double ProcessCpuMs() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return 1e3 * static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_nsec);
}

/// NaN (no steps timed) as JSON null.
nlohmann::ordered_json Number(double x) {
  return std::isfinite(x) ? nlohmann::ordered_json(x) : nlohmann::ordered_json(nullptr);
}

/// A line on stderr after a step, at most one every half second and after the last, so that a run
/// killed by a timeout still says how far it got (a line after every step cost 3 % of the CPU
/// time of Fig. 1's 0.45 ms step, which cpu_ms_per_step counts).
void PrintProgress(const char* phase, int done, int of,
                   std::chrono::steady_clock::time_point start) {
  static auto last = std::chrono::steady_clock::time_point{};
  const auto now = std::chrono::steady_clock::now();
  if (done < of && now - last < std::chrono::milliseconds(500)) return;
  last = now;
  const double ms = std::chrono::duration<double, std::milli>(now - start).count();
  fmt::print(stderr, "# {} {}/{} {:.4g} ms\n", phase, done, of, ms);
  std::fflush(stderr);
}

/// Builds and runs the case, filling `out`; returns the exit code.
int RunCase(const Options& options, const CaseSpec& spec, nlohmann::ordered_json* out) {
  nlohmann::ordered_json& j = *out;
  const Config config = ParseConfig(CaseToml(spec), "bench.toml", options.overrides);
  const Model model = BuildModel(config);
  const double h = MakeRunPlan(config, model).time_step;
  j["rods"] = model.rods.size();
  j["nodes"] = model.num_nodes;
  j["dofs"] = model.num_dofs;
  j["h"] = h;
  fmt::print(stderr, "# model rods={} nodes={} dofs={} h={}\n", model.rods.size(), model.num_nodes,
             model.num_dofs, h);

  State state = MakeRestState(model);
  Workspace ws(model);
  // As a run does (io/runner.h): the reuse across steps is forgotten at every restart point.
  auto step = [&]() {
    const StepReport r = Step(model, h, &state, &ws);
    if (r.ok && state.step % kRestartSteps == 0) ForgetReuse(&ws);
    return r;
  };
  std::string failure;
  for (int k = 0; k < options.warmup && failure.empty(); ++k) {
    const auto start = std::chrono::steady_clock::now();
    const StepReport r = step();
    if (!r.ok)
      failure = fmt::format("warm-up step {} (t = {:.6g} s): {}", k + 1, state.time, r.message);
    PrintProgress("warmup", k + 1, options.warmup, start);
  }
  std::vector<double> ms;
  long newton = 0, krylov = 0;
  const MobilityReuseStats reuse_start =
      ws.nonlocal_fluid ? ws.hydro.mobility().reuse_stats() : MobilityReuseStats{};
  const long builds_start = ws.nonlocal_fluid ? ws.hydro.preconditioner_builds() : 0;
  std::FILE* step_times = nullptr;
  if (!options.step_times.empty()) {
    step_times = std::fopen(options.step_times.c_str(), "w");
    if (!step_times)
      throw ConfigError(options.step_times, "--step-times", "cannot be written");
    fmt::print(step_times, "step,ms,newton,krylov,assembled\n");
  }
  auto assemblies = [&]() {
    return ws.nonlocal_fluid ? ws.hydro.mobility().reuse_stats().assemblies : 0L;
  };
  const double cpu_start = ProcessCpuMs();
  for (int k = 0; k < options.steps && failure.empty(); ++k) {
    const long assemblies_before = assemblies();
    const auto start = std::chrono::steady_clock::now();
    const StepReport r = step();
    const auto stop = std::chrono::steady_clock::now();
    if (!r.ok) {
      failure = fmt::format("timed step {} (t = {:.6g} s): {}", k + 1, state.time, r.message);
      break;
    }
    ms.push_back(std::chrono::duration<double, std::milli>(stop - start).count());
    if (step_times)
      fmt::print(step_times, "{},{:.4f},{},{},{}\n", state.step, ms.back(), r.newton_iterations,
                 r.krylov_iterations, assemblies() - assemblies_before);
    PrintProgress("step", k + 1, options.steps, start);
    newton += r.newton_iterations;
    krylov += r.krylov_iterations;
  }
  const double cpu_ms = ProcessCpuMs() - cpu_start;
  if (step_times) std::fclose(step_times);
  const double n = static_cast<double>(ms.size());
  const double mean = ms.empty() ? std::nan("") : std::accumulate(ms.begin(), ms.end(), 0.0) / n;
  j["steps"] = ms.size();
  j["warmup"] = options.warmup;
  j["ms_per_step_median"] = Number(Median(ms));
  j["ms_per_step_mean"] = Number(mean);
  // CPU time of all threads over the timed steps (progress lines included), per step: on a shared
  // machine the one-thread figure to compare, since other processes do not enter it.
  j["cpu_ms_per_step"] = Number(ms.empty() ? std::nan("") : cpu_ms / n);
  j["newton_per_step"] = Number(ms.empty() ? std::nan("") : static_cast<double>(newton) / n);
  j["krylov_per_step"] = Number(ms.empty() ? std::nan("") : static_cast<double>(krylov) / n);
  j["wall_s_per_sim_s"] = Number(mean * 1e-3 / h);
  if (ws.nonlocal_fluid)  // of the Krylov preconditioner
    j["preconditioner_builds_per_step"] = Number(
        ms.empty() ? std::nan("")
                   : static_cast<double>(ws.hydro.preconditioner_builds() - builds_start) / n);
  // The reuse of the dense 𝕄, or of the matrix-free operator's near corrections.
  if (ws.nonlocal_fluid && ws.hydro.mobility().reuse_stats().updates > 0) {
    const MobilityReuseStats reuse = ws.hydro.mobility().reuse_stats();
    j["assemblies_per_step"] =
        Number(ms.empty() ? std::nan("") : static_cast<double>(reuse.assemblies - reuse_start.assemblies) / n);
    j["reuse_largest_error"] = reuse.largest_error;
  }
  // The matrix-free operator's work per product at the last step: its near 3×3 blocks and its
  // far sum's cost in kernel evaluations (source–target pairs where the sum is direct).
  if (ws.nonlocal_fluid && model.hydro.mobility.kind == MobilityKind::kMatrixFree) {
    const MobilityCostCounts cost = ws.hydro.mobility().cost_counts();
    j["near_blocks"] = cost.near_blocks;
    j["far_cost_per_product"] = cost.far_sum_cost;
    j["gauss_points"] = cost.gauss_points;
  }
  j["ok"] = failure.empty();
  if (!failure.empty()) j["message"] = failure;
  return failure.empty() ? 0 : 3;
}

}  // namespace
}  // namespace stokesrods

int main(int argc, char** argv) {
  using namespace stokesrods;
  const std::optional<Options> options = ParseArgs(argc, argv);
  if (!options) {
    PrintUsage(stderr);
    return 2;
  }
  nlohmann::ordered_json j;
  j["case"] = options->case_name;
  int code = 0;
  const std::optional<CaseSpec> spec = FindCase(options->case_name);
  if (spec && options->print_config) {
    fmt::print("{}", CaseToml(*spec));
    return 0;
  }
  if (!spec) {
    j["ok"] = false;
    j["message"] = fmt::format("unknown case '{}'", options->case_name);
    code = 2;
  } else {
    try {
      code = RunCase(*options, *spec, &j);
    } catch (const ConfigError& e) {
      j["ok"] = false;
      j["message"] = e.what();
      code = 2;
    } catch (const std::bad_alloc&) {
      j["ok"] = false;
      j["message"] = "out of memory (std::bad_alloc)";
      code = 3;
    } catch (const std::exception& e) {
      j["ok"] = false;
      j["message"] = e.what();
      code = 3;
    }
  }
  j["threads"] = MaxThreads();
  j["blas_core"] = stokesrods::BlasCoreName();
  j["peak_rss_mb"] = PeakRssMb();
  std::cout << j.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace) << '\n';
  std::cout.flush();
  // After a std::bad_alloc thrown inside an OpenMP parallel region the other threads can be left
  // waiting at its barrier, and a normal exit would wait for them forever: leave at once.
  std::fflush(nullptr);
  std::_Exit(code);
}
