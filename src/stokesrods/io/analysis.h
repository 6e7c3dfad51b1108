// Derived results of runs and sweeps (SPEC `stokesrods analyze`): the first crossing time, whether
// a helix buckled, the propulsive force, and critical values (ω̄_c, ω̄_b) along a line of a sweep.
// Computed from timeseries.csv and summary.json; nothing here prints.
//
// Rules (docs/validation.md states them next to the results):
//  - crossed: Δb ≤ 0 at the end of the run (paper Fig. 7c3 marks the final shape); the first
//    crossing time is the first t̄ at which Δb ≤ 0, linearly interpolated between output rows.
//  - ever_crossed: Δb ≤ 0 at some output row (a first crossing time exists): a tight bundle's tips
//    can turn back to Δb > 0 at the end after crossing (paper Fig. 9 at large pitch).
//  - buckled: rod 1's last node farther than 2R from the vertical through its clamp at some output
//    row of the last 20 % of the run (a helical rod keeps it at R; its axis tilts when it buckles).
//  - F̄p: propulsive_force_bar averaged over the second half of the run (time average of the output
//    rows), and its final value.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "stokesrods/io/sweep.h"

namespace stokesrods {

/// timeseries.csv as columns. Throws IoError when the file cannot be read.
std::map<std::string, std::vector<double>> ReadTimeseries(const std::string& path);

struct RunAnalysis {
  std::string status;                        ///< summary.json status ("" if none)
  double t_bar_end = 0.0;
  double omega_bar = 0.0;                    ///< rod 1's
  std::optional<double> first_crossing_t_bar;  ///< none: never Δb ≤ 0 (or one rod)
  std::optional<bool> crossed;               ///< Δb ≤ 0 at the end (two or more rods)
  std::optional<double> final_delta_b_over_r;
  std::optional<double> min_distance;        ///< smallest over the run [m]
  double max_tip_axis_distance_over_r = 0.0;  ///< largest over the last 20 % of the run
  bool buckled = false;
  double final_length_bar = 0.0;             ///< rod 1's l̄
  double propulsive_force_bar_mean = 0.0;    ///< over the second half of the run
  double propulsive_force_bar_final = 0.0;
};

/// The analysis of one run folder. Throws IoError when its files are missing.
RunAnalysis AnalyzeRun(const std::string& run_dir);

/// A yes/no outcome per case along a line: "crossed", "ever_crossed" or "buckled" (none: the
/// criterion does not apply, e.g. crossing with one rod).
std::optional<bool> Outcome(const RunAnalysis& a, const std::string& criterion);

/// The criteria Outcome knows, and each one's rule in words (for messages and tables).
const std::vector<std::string>& OutcomeCriteria();
std::string CriterionRule(const std::string& criterion);

/// The critical value of `key` on one line of a sweep (the other varied keys fixed): the outcome
/// switches from no (below) to yes (at and above) between `below` and `above`.
struct LineResult {
  std::string prefix;  ///< the line's explicit case name ("" if none)
  std::vector<std::pair<std::string, std::string>> fixed;  ///< the other varied keys
  std::optional<double> below, above;  ///< bracket; one side missing: all yes / all no
  bool monotone = true;                ///< false: a yes below a no on this line
  std::vector<std::pair<double, bool>> points;  ///< (value, outcome), sorted
};

/// Groups the cases of a sweep into lines along `key` and brackets the switch of the outcome.
/// outcomes[i] belongs to sweep.cases[i] (none: not finished).
std::vector<LineResult> CriticalAlongLines(const Sweep& sweep, const std::string& key,
                                           const std::vector<std::optional<bool>>& outcomes);

/// The middle of each line's bracket that is wider than `resolution`, as a new case of the sweep
/// (the line's fixed values, `key` at the midpoint). Cases that already exist are not repeated.
std::vector<SweepCase> RefinementCases(const Sweep& sweep, const std::string& key,
                                       const std::vector<LineResult>& lines, double resolution);

/// The refinement cases an earlier run of this sweep left (listed in <output>/sweep.json) that are
/// still on one of its lines (a grid case's values but `refine.key`'s, same name) and finished
/// (completed or failed) with the settings they have now. The sweep lists them from its start, so
/// an interrupted rerun keeps them in sweep.json, which is what `analyze` reads. None without
/// [refine].
std::vector<SweepCase> KnownRefinementCases(const Sweep& sweep);

}  // namespace stokesrods
