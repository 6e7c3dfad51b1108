// The stokesrods command line (SPEC "Command line"): parse, run, map errors to exit codes.
//   0 success, 2 invalid input, 3 numerical failure, 4 input/output failure, 130 interrupted.
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <iostream>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "stokesrods/io/analysis.h"
#include "stokesrods/io/build_model.h"
#include "stokesrods/io/config.h"
#include "stokesrods/io/runner.h"
#include "stokesrods/io/writers.h"
#include "python_tools.h"
#include "analyze_command.h"
#include "sweep_command.h"

namespace {

// SIGINT/SIGTERM: the first lets the run go on to its next restart point (at most 120 steps) and
// checkpoint there, so that --resume continues exactly; a second stops after the current step.
volatile std::sig_atomic_t g_interrupted = 0;
void OnSignal(int) { g_interrupted = g_interrupted + 1; }

std::string Clock(double seconds) {
  const long s = std::lround(std::max(0.0, seconds));
  return fmt::format("{:02d}:{:02d}:{:02d}", s / 3600, (s / 60) % 60, s % 60);
}

// Progress on a terminal (one rewritten line), plain periodic lines otherwise.
void ShowProgress(const stokesrods::RunProgress& p) {
  static double last_plain = -1e9;
  const bool tty = isatty(fileno(stderr)) != 0;
  const double fraction = p.duration > 0 ? p.time / p.duration : 1.0;
  const double speed = p.wall_seconds > 0 ? p.time / p.wall_seconds : 0.0;  // sim s per wall s
  const double left = speed > 0 ? (p.duration - p.time) / speed : 0.0;
  const std::string line =
      fmt::format("t = {:.4g} s of {:.4g} s ({:5.1f}%), {:.3g} sim s per wall s, {} left",
                  p.time, p.duration, 100.0 * fraction, speed, Clock(left));
  if (tty) {
    fmt::print(stderr, "\r{}   ", line);
    if (fraction >= 1.0) fmt::print(stderr, "\n");
  } else if (p.wall_seconds - last_plain >= 10.0 || fraction >= 1.0) {
    last_plain = p.wall_seconds;
    fmt::print(stderr, "[stokesrods] {}\n", line);
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"stokesrods: elastic rods (Discrete Elastic Rods) in a viscous Stokes fluid, with "
               "hydrodynamic interaction and contact between rods"};
  app.set_version_flag("--version", std::string("stokesrods ") + STOKESRODS_VERSION);
  app.require_subcommand(1);

  std::string config_path, output;
  std::vector<std::string> overrides;
  bool resume = false;
  CLI::App* run = app.add_subcommand("run", "run one simulation");
  run->add_option("config", config_path, "configuration file (TOML)")->required();
  run->add_option("--set", overrides, "override one key: KEY=VALUE, e.g. run.time_step=5e-4");
  run->add_option("--output", output, "output directory (overrides run.output)");
  run->add_flag("--resume", resume, "continue an interrupted run from its last checkpoint");

  CLI::App* show = app.add_subcommand("show-config",
                                      "print the resolved configuration with derived quantities");
  show->add_option("config", config_path, "configuration file (TOML)")->required();
  show->add_option("--set", overrides, "override one key: KEY=VALUE");

  CLI::App* render = stokesrods::AddPythonTool(
      &app, "render",
      "pictures of a run: RUN_DIR [--times T...] [--color rod|contact_force|hydrodynamic_force] "
      "[--no-video] [--fps N] [--max-frames N] [--output-dir DIR]; writes RUN_DIR/render/"
      "{views.png,run.mp4,flow.png}");
  CLI::App* plot = stokesrods::AddPythonTool(
      &app, "plot", "time series of a run: RUN_DIR COLUMN... [--x time|t_bar] [--output FILE]");
  stokesrods::SweepCommandOptions sweep_options;
  CLI::App* sweep = app.add_subcommand(
      "sweep", "a parameter sweep: one run per case, --jobs at a time; under mpirun also on the other ranks");
  sweep->add_option("sweep", sweep_options.file, "sweep file (TOML)")->required();
  sweep->add_option("--jobs", sweep_options.jobs, "cases at a time on this machine (rank 0 under MPI)")
      ->check(CLI::PositiveNumber);
  sweep->add_option("--threads", sweep_options.threads, "OMP_NUM_THREADS of each case (default 1)")
      ->check(CLI::PositiveNumber);
  sweep->add_option("--output", sweep_options.output, "the sweep's folder (overrides `output`)");
  sweep->add_flag("--retry-failed", sweep_options.retry_failed, "rerun cases that failed numerically");

  stokesrods::AnalyzeOptions analyze_options;
  CLI::App* analyze = app.add_subcommand(
      "analyze", "derived results of a run or a sweep: crossing time, critical speeds, F̄p");
  analyze->add_option("dir", analyze_options.dir, "a run's or a sweep's output folder")->required();
  analyze->add_option("--line", analyze_options.line, "sweep key along which to find the critical value");
  analyze->add_option("--criterion", analyze_options.criterion, "crossed | ever_crossed | buckled")
      ->check(CLI::IsMember(stokesrods::OutcomeCriteria()));
  analyze->add_option("--single", analyze_options.single,
                      "a run or sweep of one flagellum: F̄p relative to it at the same omega_bar");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }

  if (*render) return stokesrods::RunPythonTool("render", render->remaining());
  if (*plot) return stokesrods::RunPythonTool("plot", plot->remaining());
  try {
    if (*analyze) return stokesrods::RunAnalyzeCommand(analyze_options);
    if (*sweep) {
      std::signal(SIGINT, OnSignal);
      std::signal(SIGTERM, OnSignal);
      sweep_options.interrupted = [] { return g_interrupted != 0; };
      return stokesrods::RunSweepCommand(sweep_options);
    }
    if (!output.empty()) overrides.push_back("run.output=\"" + output + "\"");
    const stokesrods::Config config = stokesrods::LoadConfig(config_path, overrides);
    if (*show) {
      const stokesrods::Model model = stokesrods::BuildModel(config);
      fmt::print("{}\n", stokesrods::ConfigToToml(config));
      fmt::print("# derived quantities (not configuration keys)\n# {}\n",
                 [&] {
                   std::string text = stokesrods::DerivedJson(config, model);
                   std::string out;
                   for (char c : text) out += c == '\n' ? std::string("\n# ") : std::string(1, c);
                   return out;
                 }());
      return 0;
    }
    std::signal(SIGINT, OnSignal);
    std::signal(SIGTERM, OnSignal);
    stokesrods::RunOptions options;
    options.resume = resume;
    options.interrupted = [] { return g_interrupted != 0; };
    options.stop_now = [] { return g_interrupted > 1; };
    options.progress = ShowProgress;
    const stokesrods::RunResult result = stokesrods::RunCase(config, options);
    switch (result.status) {
      case stokesrods::RunStatus::kCompleted:
        fmt::print(stderr, "[stokesrods] completed: {} steps, {} Newton iterations, {:.1f} s; outputs in {}\n",
                   result.steps, result.newton_iterations, result.wall_seconds, result.output_dir);
        return 0;
      case stokesrods::RunStatus::kFailed:
        fmt::print(stderr, "error: numerical failure: {}\n", result.message);
        return 3;
      case stokesrods::RunStatus::kInterrupted:
        fmt::print(stderr, "[stokesrods] {}; outputs flushed, checkpoint written in {}\n",
                   result.message, result.output_dir);
        return 130;
    }
  } catch (const stokesrods::ConfigError& e) {
    fmt::print(stderr, "error: invalid input: {}\n", e.what());
    return 2;
  } catch (const stokesrods::IoError& e) {
    fmt::print(stderr, "error: input/output: {}\n", e.what());
    return 4;
  } catch (const std::exception& e) {  // a bug: say so instead of aborting with a trace
    fmt::print(stderr, "error: internal error: {} (a bug in stokesrods: please report it with the "
                       "configuration)\n", e.what());
    return 1;
  }
  return 0;
}
