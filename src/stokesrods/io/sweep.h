// Parameter sweeps (SPEC "Sweep file"): the sweep file, its expansion into cases, the state of each
// case on disk (what a rerun skips) and sweep.csv. Running the cases (processes, MPI ranks) is the
// command line's business (apps/stokesrods/sweep_command.cc); nothing here prints or spawns.
//
//   base = "bundling.toml"      # configuration to vary, relative to the sweep file
//   output = "out/phase"        # one folder per case, plus sweep.csv (relative to the working dir)
//   [set]                       # overrides applied to every case (extension)
//   "run.time_step" = 0.04
//   [vary]                      # Cartesian product of the lists
//   "rods.omega_bar" = [43, 107]
//   [[cases]]                   # explicit cases (extension); the product is taken for each case
//   "rods.2.base" = [0.04, 0.0, 0.0]
//   name = "dt4"                # optional folder-name prefix of the case
//   [[adjust]]                  # keys for the matching cases only (extension), e.g. to retry
//   where = { "rods.omega_bar" = 107 }   # a failed case without touching the others
//   "solver.max_step_halvings" = 4
//   [refine]                    # bisection along a line after the grid (extension)
//   key = "rods.omega_bar"
//   criterion = "crossed"       # or "buckled"
//   resolution = 10.0
#pragma once

#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace stokesrods {

struct SweepCase {
  std::string prefix;  ///< the explicit case's `name` ("" if none)
  std::string name;  ///< folder name under the sweep's output, unique, stable under list edits
  /// The varied keys of this case and their values as TOML text, in sweep.csv's column order.
  std::vector<std::pair<std::string, std::string>> values;
  std::vector<std::string> overrides;  ///< "key=value" (set, case, vary), as for --set
  std::string output_dir;              ///< <sweep output>/<name>
};

/// [refine]: bisect `key` between the cases where `criterion` ("crossed" | "ever_crossed" |
/// "buckled", see io/analysis.h) switches from no to yes, until the bracket is at most `resolution` wide.
struct RefineSpec {
  std::string key;
  std::string criterion;
  double resolution = 0.0;
};

/// [[adjust]]: keys set in the cases whose varied values match every entry of `where` (numbers
/// compare as numbers: 550 matches 550.0). They do not enter the folder name, so an adjusted case
/// keeps its folder, and its old summary (another configuration) no longer counts: it runs again.
struct SweepAdjust {
  std::vector<std::pair<std::string, std::string>> where;  ///< varied key, value as TOML text
  std::vector<std::string> overrides;                       ///< "key=value", applied after [set]
};

struct Sweep {
  std::string file;                      ///< the sweep file (for messages)
  std::string base;                      ///< the base configuration's path
  std::string output;                    ///< the sweep's folder
  std::vector<std::string> varied_keys;  ///< sweep.csv's key columns
  std::vector<std::string> fixed_overrides;  ///< [set]
  std::vector<SweepAdjust> adjustments;      ///< [[adjust]], in file order (a later one wins)
  std::optional<RefineSpec> refine;
  std::vector<SweepCase> cases;
};

/// The case with these values (key, TOML text) of the varied keys, after the sweep's [set] and the
/// [[adjust]] entries it matches.
SweepCase MakeSweepCase(const Sweep& sweep, const std::string& prefix,
                        std::vector<std::pair<std::string, std::string>> values);

/// A case as JSON and back (MPI messages, sweep.json).
nlohmann::json CaseToJson(const SweepCase& c);
SweepCase CaseFromJson(const nlohmann::json& j);

/// <output>/sweep.json: the expanded sweep (every case with its folder and overrides, the refine
/// cases included), what `stokesrods analyze` reads. Written atomically.
void WriteSweepJson(const Sweep& sweep);
/// Reads <dir>/sweep.json. Throws IoError.
Sweep ReadSweepJson(const std::string& dir);

/// Reads a sweep file and expands it; every case is checked against the base configuration (a key
/// that does not exist, a bad value). `output` non-empty replaces the file's. Throws ConfigError
/// naming the sweep file, the key and the problem.
Sweep LoadSweep(const std::string& path, const std::string& output = "");

/// The same from TOML text; `dir` is where `base` is resolved from.
Sweep ParseSweep(const std::string& toml_text, const std::string& file, const std::string& dir,
                 const std::string& output = "");

/// What is known about one case: read from its folder, or filled in by the scheduler.
struct CaseRecord {
  /// "pending" | "completed" | "failed" (numerical, exit 3) | "interrupted" | "crashed" (killed
  /// by a signal, or an exit code the run never gives) | "error" (bad input or I/O, exit 2 or 4)
  std::string status = "pending";
  std::string message;
  int exit_code = 0;
  double wall_seconds = 0.0;
  int rank = 0;  ///< the MPI rank that ran it (0 without MPI)
  nlohmann::json final_values = nlohmann::json::object();  ///< summary.json "final"
  bool resumable = false;  ///< interrupted with a checkpoint: rerun with --resume
};

/// The case's state from its folder: "completed" or "failed" when its summary.json says so and
/// was made from the configuration the case has now (SameRunSettings, io/config_compare.h: keys
/// added to the program since the run count when at their defaults); "interrupted" (resumable) when
/// it has a checkpoint and a summary saying so; otherwise "pending" (never run, crashed, or run
/// from a different configuration).
CaseRecord ReadCaseRecord(const Sweep& sweep, const SweepCase& c);

/// The record of a case whose run exited with `exit_code` (or was killed by `signal` ≠ 0), after
/// `wall_seconds`; `summary_text` is its summary.json if any ("" if none).
CaseRecord MakeCaseRecord(int exit_code, int signal, double wall_seconds,
                          const std::string& summary_text);

/// The --set that puts a case's run in `dir` (run.output as TOML text).
std::string OutputOverride(const std::string& dir);

/// The command-line arguments (after the program) that run case `c`.
std::vector<std::string> CaseArguments(const Sweep& sweep, const SweepCase& c, bool resume);

/// sweep.csv: case, the varied keys, status, exit_code, wall_seconds, rank, message, then every `final`
/// column seen in any case (in first-seen order). Written atomically.
void WriteSweepCsv(const Sweep& sweep, const std::vector<CaseRecord>& records);

}  // namespace stokesrods
