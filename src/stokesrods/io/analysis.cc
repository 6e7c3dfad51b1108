#include "stokesrods/io/analysis.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "stokesrods/io/config.h"
#include "stokesrods/io/writers.h"
#include "stokesrods/sim/observables.h"

namespace stokesrods {

namespace fs = std::filesystem;

std::map<std::string, std::vector<double>> ReadTimeseries(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw IoError(path + ": cannot read");
  std::string line;
  std::getline(in, line);
  std::vector<std::string> names;
  std::stringstream header(line);
  for (std::string name; std::getline(header, name, ',');) names.push_back(name);
  std::map<std::string, std::vector<double>> columns;
  while (std::getline(in, line)) {
    std::stringstream row(line);
    std::size_t i = 0;
    for (std::string cell; std::getline(row, cell, ',') && i < names.size(); ++i)
      columns[names[i]].push_back(cell.empty() ? std::nan("") : std::strtod(cell.c_str(), nullptr));
  }
  return columns;
}

namespace {

const std::vector<double>& Column(const std::map<std::string, std::vector<double>>& ts,
                                  const std::string& name, const std::string& path) {
  const auto it = ts.find(name);
  if (it == ts.end() || it->second.empty()) throw IoError(fmt::format("{}: no column {}", path, name));
  return it->second;
}

// The first t̄ at which y ≤ 0, linearly interpolated between rows.
std::optional<double> FirstNonPositive(const std::vector<double>& t, const std::vector<double>& y) {
  for (std::size_t i = 0; i < y.size(); ++i) {
    if (!(y[i] <= 0.0)) continue;
    if (i == 0) return t[0];
    return t[i - 1] + (t[i] - t[i - 1]) * y[i - 1] / (y[i - 1] - y[i]);
  }
  return std::nullopt;
}

}  // namespace

RunAnalysis AnalyzeRun(const std::string& run_dir) {
  const std::string ts_path = (fs::path(run_dir) / "timeseries.csv").string();
  const auto ts = ReadTimeseries(ts_path);
  RunAnalysis a;
  std::ifstream in(fs::path(run_dir) / "summary.json");
  const nlohmann::json summary = in ? nlohmann::json::parse(in, nullptr, false) : nlohmann::json();
  double helix_radius = 0.01;
  if (summary.is_object()) {
    a.status = summary.value("status", "");
    if (summary.contains("derived") && summary["derived"].contains("omega_bar"))
      a.omega_bar = summary["derived"]["omega_bar"].at(0).get<double>();
    helix_radius = summary["config"]["rods"].at(0).value("helix_radius", helix_radius);
  }
  const std::vector<double>& t_bar = Column(ts, "t_bar", ts_path);
  const std::size_t n = t_bar.size();
  a.t_bar_end = t_bar.back();
  if (ts.count("delta_b") != 0) {
    const std::vector<double>& db = Column(ts, "delta_b", ts_path);
    a.first_crossing_t_bar = FirstNonPositive(t_bar, db);
    a.crossed = db.back() <= 0.0;
    a.final_delta_b_over_r = Column(ts, "delta_b_over_R", ts_path).back();
    const std::vector<double>& d = Column(ts, "min_distance", ts_path);
    a.min_distance = *std::min_element(d.begin(), d.end());
  }
  const std::vector<double>& tip = Column(ts, "rod1_tip_axis_distance", ts_path);
  for (std::size_t i = 0; i < n; ++i)
    if (t_bar[i] >= 0.8 * a.t_bar_end)
      a.max_tip_axis_distance_over_r = std::max(a.max_tip_axis_distance_over_r, tip[i] / helix_radius);
  a.buckled = a.max_tip_axis_distance_over_r > kBuckledTipAxisDistanceOverR;
  a.final_length_bar = Column(ts, "rod1_length_bar", ts_path).back();
  const std::vector<double>& fp = Column(ts, "propulsive_force_bar", ts_path);
  double sum = 0.0;
  int count = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (t_bar[i] >= 0.5 * a.t_bar_end) sum += fp[i], ++count;
  a.propulsive_force_bar_mean = count > 0 ? sum / count : fp.back();
  a.propulsive_force_bar_final = fp.back();
  return a;
}

std::optional<bool> Outcome(const RunAnalysis& a, const std::string& criterion) {
  if (criterion == "crossed") return a.crossed;
  if (criterion == "ever_crossed")
    return a.crossed ? std::optional<bool>(a.first_crossing_t_bar.has_value()) : std::nullopt;
  if (criterion == "buckled") return a.buckled;
  return std::nullopt;
}

const std::vector<std::string>& OutcomeCriteria() {
  static const std::vector<std::string> kCriteria = {"crossed", "ever_crossed", "buckled"};
  return kCriteria;
}

std::string CriterionRule(const std::string& criterion) {
  if (criterion == "crossed") return "delta_b <= 0 at the end of the run";
  if (criterion == "ever_crossed") return "delta_b <= 0 at some output row";
  return "tip > 2R off the clamp's vertical in the last 20 %";
}

std::vector<LineResult> CriticalAlongLines(const Sweep& sweep, const std::string& key,
                                           const std::vector<std::optional<bool>>& outcomes) {
  std::map<std::pair<std::string, std::vector<std::pair<std::string, std::string>>>, LineResult> lines;
  for (std::size_t i = 0; i < sweep.cases.size(); ++i) {
    const SweepCase& c = sweep.cases[i];
    LineResult probe;
    probe.prefix = c.prefix;
    std::optional<double> value;
    for (const auto& [k, text] : c.values) {
      if (k == key) value = std::strtod(text.c_str(), nullptr);
      else probe.fixed.emplace_back(k, text);
    }
    if (!value || i >= outcomes.size() || !outcomes[i]) continue;
    LineResult& line = lines.try_emplace({c.prefix, probe.fixed}, probe).first->second;
    line.points.emplace_back(*value, *outcomes[i]);
  }
  std::vector<LineResult> results;
  for (auto& [id, line] : lines) {
    std::sort(line.points.begin(), line.points.end());
    // The switch: the lowest value from which every larger value is "yes".
    std::size_t first_yes = line.points.size();
    while (first_yes > 0 && line.points[first_yes - 1].second) --first_yes;
    if (first_yes < line.points.size()) line.above = line.points[first_yes].first;
    if (first_yes > 0) line.below = line.points[first_yes - 1].first;
    for (std::size_t i = 0; i < first_yes; ++i)
      if (line.points[i].second) line.monotone = false;
    results.push_back(std::move(line));
  }
  return results;
}

namespace {

// The case of `sweep` on the line of `prefix` and `fixed` (the other varied keys) with `key` at
// `text`, built like the line's grid case (its [set] and [[adjust]]); none: no case on that line.
std::optional<SweepCase> CaseOnLine(const Sweep& sweep, const std::string& key,
                                    const std::string& prefix,
                                    const std::vector<std::pair<std::string, std::string>>& fixed,
                                    const std::string& text) {
  for (const SweepCase& c : sweep.cases) {
    if (c.prefix != prefix) continue;
    std::vector<std::pair<std::string, std::string>> others;
    for (const auto& kv : c.values)
      if (kv.first != key) others.push_back(kv);
    if (others != fixed) continue;
    std::vector<std::pair<std::string, std::string>> values = c.values;
    for (auto& kv : values)
      if (kv.first == key) kv.second = text;
    return MakeSweepCase(sweep, c.prefix, std::move(values));
  }
  return std::nullopt;
}

}  // namespace

std::vector<SweepCase> RefinementCases(const Sweep& sweep, const std::string& key,
                                       const std::vector<LineResult>& lines, double resolution) {
  std::set<std::string> existing;
  for (const SweepCase& c : sweep.cases) existing.insert(c.name);
  std::vector<SweepCase> added;
  for (const LineResult& line : lines) {
    if (!line.below || !line.above || *line.above - *line.below <= resolution) continue;
    std::optional<SweepCase> mid = CaseOnLine(sweep, key, line.prefix, line.fixed,
                                              fmt::format("{}", 0.5 * (*line.below + *line.above)));
    if (mid && existing.insert(mid->name).second) added.push_back(std::move(*mid));
  }
  return added;
}

std::vector<SweepCase> KnownRefinementCases(const Sweep& sweep) {
  if (!sweep.refine || !fs::exists(fs::path(sweep.output) / "sweep.json")) return {};
  const std::string& key = sweep.refine->key;
  Sweep before;
  try {
    before = ReadSweepJson(sweep.output);
  } catch (const IoError&) {
    return {};  // unreadable: nothing is known (the sweep rewrites it)
  }
  std::set<std::string> names;
  for (const SweepCase& c : sweep.cases) names.insert(c.name);
  std::vector<SweepCase> known;
  for (const SweepCase& old : before.cases) {
    std::vector<std::pair<std::string, std::string>> fixed;
    const std::string* text = nullptr;
    for (const auto& kv : old.values) {
      if (kv.first == key) text = &kv.second;
      else fixed.push_back(kv);
    }
    if (text == nullptr || names.count(old.name) != 0) continue;
    std::optional<SweepCase> c = CaseOnLine(sweep, key, old.prefix, fixed, *text);
    if (!c || c->name != old.name) continue;  // no longer on a line of this sweep
    try {
      const std::string status = ReadCaseRecord(sweep, *c).status;
      if (status != "completed" && status != "failed") continue;  // the refine pass adds it
    } catch (const ConfigError&) {
      continue;  // its values no longer make a valid configuration
    }
    names.insert(c->name);
    known.push_back(std::move(*c));
  }
  return known;
}

}  // namespace stokesrods
