#include "analyze_command.h"

#include <cmath>
#include <filesystem>
#include <map>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "stokesrods/io/analysis.h"
#include "stokesrods/io/config.h"
#include "stokesrods/io/sweep.h"
#include "stokesrods/io/writers.h"

namespace stokesrods {

namespace fs = std::filesystem;

namespace {

std::string Optional(const std::optional<double>& v) { return v ? fmt::format("{:.6g}", *v) : ""; }

nlohmann::json ToJson(const RunAnalysis& a) {
  auto opt = [](const auto& v) { return v ? nlohmann::json(*v) : nlohmann::json(); };
  return {{"status", a.status},
          {"t_bar_end", a.t_bar_end},
          {"omega_bar", a.omega_bar},
          {"first_crossing_t_bar", opt(a.first_crossing_t_bar)},
          {"crossed", opt(a.crossed)},
          {"final_delta_b_over_R", opt(a.final_delta_b_over_r)},
          {"min_distance", opt(a.min_distance)},
          {"max_tip_axis_distance_over_R_last_20pct", a.max_tip_axis_distance_over_r},
          {"buckled", a.buckled},
          {"final_length_bar", a.final_length_bar},
          {"propulsive_force_bar_mean_second_half", a.propulsive_force_bar_mean},
          {"propulsive_force_bar_final", a.propulsive_force_bar_final}};
}

// F̄p (second-half mean) of one flagellum by ω̄ (rounded to 1e-6), from a run or a sweep folder.
std::map<long long, double> SingleForces(const std::string& dir) {
  std::map<long long, double> by_omega;
  auto add = [&](const std::string& run) {
    const RunAnalysis a = AnalyzeRun(run);
    if (a.status == "completed") by_omega[std::llround(a.omega_bar * 1e6)] = a.propulsive_force_bar_mean;
  };
  if (fs::exists(fs::path(dir) / "sweep.json")) {
    for (const SweepCase& c : ReadSweepJson(dir).cases)
      if (fs::exists(fs::path(c.output_dir) / "summary.json")) add(c.output_dir);
  } else {
    add(dir);
  }
  return by_omega;
}

int AnalyzeSweep(const AnalyzeOptions& options) {
  const Sweep sweep = ReadSweepJson(options.dir);
  std::string line = options.line, criterion = options.criterion;
  if (line.empty()) line = sweep.refine ? sweep.refine->key : "rods.omega_bar";
  if (criterion.empty()) criterion = sweep.refine ? sweep.refine->criterion : "crossed";
  const std::map<long long, double> single = options.single.empty() ? std::map<long long, double>()
                                                                     : SingleForces(options.single);
  std::string csv = "case";
  for (const std::string& k : sweep.varied_keys) csv += ",\"" + k + "\"";
  csv += ",status,omega_bar,first_crossing_t_bar,crossed,final_delta_b_over_R,min_distance,"
         "max_tip_axis_distance_over_R,buckled,final_length_bar,propulsive_force_bar_mean,"
         "propulsive_force_bar_final,propulsive_force_ratio_to_single\n";
  std::vector<std::optional<bool>> outcomes(sweep.cases.size());
  for (std::size_t i = 0; i < sweep.cases.size(); ++i) {
    const SweepCase& c = sweep.cases[i];
    csv += c.name;
    for (const std::string& k : sweep.varied_keys) {
      std::string v;
      for (const auto& [key, text] : c.values)
        if (key == k) v = text;
      csv += ",\"" + v + "\"";
    }
    if (!fs::exists(fs::path(c.output_dir) / "summary.json")) {
      csv += ",pending" + std::string(12, ',') + "\n";
      continue;
    }
    const RunAnalysis a = AnalyzeRun(c.output_dir);
    if (a.status == "completed") outcomes[i] = Outcome(a, criterion);
    std::optional<double> ratio;
    const auto it = single.find(std::llround(a.omega_bar * 1e6));
    if (it != single.end()) ratio = a.propulsive_force_bar_mean / it->second;
    csv += fmt::format(",{},{:.6g},{},{},{},{},{:.4g},{},{:.6g},{:.6g},{:.6g},{}\n", a.status,
                       a.omega_bar, Optional(a.first_crossing_t_bar),
                       a.crossed ? (*a.crossed ? "1" : "0") : "", Optional(a.final_delta_b_over_r),
                       Optional(a.min_distance), a.max_tip_axis_distance_over_r, a.buckled ? 1 : 0,
                       a.final_length_bar, a.propulsive_force_bar_mean, a.propulsive_force_bar_final,
                       Optional(ratio));
  }
  WriteFileAtomically((fs::path(options.dir) / "analysis.csv").string(), csv);

  std::string critical = "line,below,above,estimate,monotone,points\n";
  fmt::print("{} along {} ({}: {}):\n", criterion == "buckled" ? "critical buckling" : "critical crossing",
             line, criterion, CriterionRule(criterion));
  for (const LineResult& l : CriticalAlongLines(sweep, line, outcomes)) {
    std::string fixed, points;
    for (const auto& [k, v] : l.fixed) fixed += (fixed.empty() ? "" : " ") + k + "=" + v;
    for (const auto& [v, yes] : l.points) points += fmt::format("{}{}:{}", points.empty() ? "" : " ", v, yes ? 1 : 0);
    const std::optional<double> estimate =
        l.below && l.above ? std::optional<double>(0.5 * (*l.below + *l.above)) : std::nullopt;
    critical += fmt::format("\"{}\",{},{},{},{},{}\n", fixed, Optional(l.below), Optional(l.above),
                            Optional(estimate), l.monotone ? 1 : 0, points);
    fmt::print("  {}: {}{}\n", fixed.empty() ? "(one line)" : fixed,
               l.below && l.above ? fmt::format("in ({:.6g}, {:.6g}]", *l.below, *l.above)
               : l.above          ? fmt::format("at or below {:.6g} (all yes)", *l.above)
                                  : fmt::format("above {:.6g} (all no)", l.points.empty() ? 0.0 : l.points.back().first),
               l.monotone ? "" : " (not monotone: a yes below a no)");
  }
  WriteFileAtomically((fs::path(options.dir) / "critical.csv").string(), critical);
  fmt::print("tables: {}, {}\n", (fs::path(options.dir) / "analysis.csv").string(),
             (fs::path(options.dir) / "critical.csv").string());
  return 0;
}

}  // namespace

int RunAnalyzeCommand(const AnalyzeOptions& options) {
  if (fs::exists(fs::path(options.dir) / "sweep.json")) return AnalyzeSweep(options);
  nlohmann::json j = ToJson(AnalyzeRun(options.dir));
  if (!options.single.empty()) {
    const auto single = SingleForces(options.single);
    const auto it = single.find(std::llround(j["omega_bar"].get<double>() * 1e6));
    if (it != single.end())
      j["propulsive_force_ratio_to_single"] = j["propulsive_force_bar_mean_second_half"].get<double>() / it->second;
  }
  WriteFileAtomically((fs::path(options.dir) / "analysis.json").string(), j.dump(2) + "\n");
  fmt::print("{}\n", j.dump(2));
  return 0;
}

}  // namespace stokesrods
