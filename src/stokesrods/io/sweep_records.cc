// Sweep records: the state of a case from its folder (what a rerun skips), the record of a run that
// just ended, and sweep.csv (io/sweep.h).
#include <filesystem>
#include <fstream>
#include <set>

#include <fmt/format.h>

#include "stokesrods/io/config.h"
#include "stokesrods/io/config_compare.h"
#include "stokesrods/io/sweep.h"
#include "stokesrods/io/writers.h"

namespace stokesrods {

namespace fs = std::filesystem;

CaseRecord MakeCaseRecord(int exit_code, int signal, double wall_seconds,
                          const std::string& summary_text) {
  CaseRecord r;
  r.exit_code = signal != 0 ? 128 + signal : exit_code;
  r.wall_seconds = wall_seconds;
  nlohmann::json summary;
  if (!summary_text.empty()) summary = nlohmann::json::parse(summary_text, nullptr, false);
  if (summary.is_object()) {
    r.message = summary.value("message", "");
    if (summary.contains("final") && summary["final"].is_object()) r.final_values = summary["final"];
  }
  if (signal != 0) {
    r.status = "crashed";
    r.message = fmt::format("killed by signal {}", signal);
  } else if (exit_code == 0) {
    r.status = "completed";
  } else if (exit_code == 3) {
    r.status = "failed";
  } else if (exit_code == 130) {
    r.status = "interrupted";
  } else if (exit_code == 2 || exit_code == 4) {
    r.status = "error";
    if (r.message.empty()) r.message = fmt::format("exit code {}; see run.log", exit_code);
  } else {
    r.status = "crashed";
    r.message = fmt::format("exit code {}; see run.log", exit_code);
  }
  return r;
}

CaseRecord ReadCaseRecord(const Sweep& sweep, const SweepCase& c) {
  CaseRecord pending;
  std::ifstream in(fs::path(c.output_dir) / "summary.json");
  if (!in) return pending;
  const nlohmann::json summary = nlohmann::json::parse(in, nullptr, false);
  if (!summary.is_object() || !summary.contains("config")) return pending;
  std::vector<std::string> overrides = c.overrides;
  overrides.push_back(OutputOverride(c.output_dir));
  const nlohmann::json now = nlohmann::json::parse(ConfigToJson(LoadConfig(sweep.base, overrides)));
  if (!SameRunSettings(summary["config"], now)) return pending;  // another configuration: rerun
  const std::string status = summary.value("status", "");
  const int code = status == "completed" ? 0 : status == "failed" ? 3 : 130;
  CaseRecord r = MakeCaseRecord(code, 0, summary.value("wall_seconds", 0.0), summary.dump());
  if (status == "interrupted") {
    r.resumable = fs::exists(fs::path(c.output_dir) / "checkpoint.bin");
    if (!r.resumable) return pending;
  }
  return r;
}

namespace {

std::string CsvField(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char ch : text) quoted += ch == '"' ? std::string("\"\"") : std::string(1, ch == '\n' ? ' ' : ch);
  return quoted + "\"";
}

std::string CsvNumber(const nlohmann::json& v) {
  if (v.is_number()) return fmt::format("{:.17g}", v.get<double>());
  return v.is_null() ? std::string() : CsvField(v.dump());
}

}  // namespace

void WriteSweepCsv(const Sweep& sweep, const std::vector<CaseRecord>& records) {
  std::vector<std::string> final_columns;
  std::set<std::string> seen;
  for (const CaseRecord& r : records)
    for (const auto& [key, value] : r.final_values.items())
      if (seen.insert(key).second) final_columns.push_back(key);
  std::string text = "case";
  for (const std::string& k : sweep.varied_keys) text += "," + CsvField(k);
  text += ",status,exit_code,wall_seconds,rank,message";
  for (const std::string& k : final_columns) text += "," + CsvField(k);
  text += "\n";
  for (std::size_t i = 0; i < sweep.cases.size(); ++i) {
    const SweepCase& c = sweep.cases[i];
    const CaseRecord& r = records[i];
    text += CsvField(c.name);
    for (const std::string& k : sweep.varied_keys) {
      std::string value;
      for (const auto& [key, t] : c.values)
        if (key == k) value = t;
      text += "," + CsvField(value);
    }
    text += fmt::format(",{},{},{:.3f},{},{}", r.status, r.exit_code, r.wall_seconds, r.rank,
                        CsvField(r.message));
    for (const std::string& k : final_columns)
      text += "," + (r.final_values.contains(k) ? CsvNumber(r.final_values[k]) : std::string());
    text += "\n";
  }
  std::error_code ec;
  fs::create_directories(sweep.output, ec);
  WriteFileAtomically((fs::path(sweep.output) / "sweep.csv").string(), text);
}

}  // namespace stokesrods
