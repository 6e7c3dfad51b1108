#include "stokesrods/io/runner.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "stokesrods/io/build_model.h"
#include "stokesrods/io/flow_field.h"
#include "stokesrods/io/writers.h"
#include "stokesrods/sim/integrator.h"
#include "stokesrods/sim/observables.h"

namespace stokesrods {

namespace fs = std::filesystem;

namespace {

const char* StatusName(RunStatus s) {
  return s == RunStatus::kCompleted ? "completed" : s == RunStatus::kFailed ? "failed" : "interrupted";
}

// Keeps the rows of an existing timeseries.csv up to time t (for --resume); false if none.
bool TruncateTimeseries(const std::string& path, double t) {
  std::ifstream in(path);
  if (!in) return false;
  std::string line, kept;
  std::getline(in, line);
  kept = line + "\n";
  while (std::getline(in, line)) {
    if (std::stod(line.substr(0, line.find(','))) > t * (1.0 + 1e-12)) break;
    kept += line + "\n";
  }
  WriteFileAtomically(path, kept);
  return true;
}

class Observer {
 public:
  Observer(const Config& config, const Model& model, const RunPlan& plan, bool append)
      : config_(config), model_(model), plan_(plan), columns_(TimeseriesColumns(model)),
        csv_((fs::path(plan.output_dir) / "timeseries.csv").string(), columns_, append) {
    if (plan.frames) frames_.emplace(plan.output_dir);
  }

  void Record(const State& state, const Workspace& ws, const StepReport& report) {
    last_row_ = CalcTimeseriesRow(model_, state, ws, report);
    csv_.WriteRow(last_row_);
    if (frames_) {
      VecX hydro = ws.nonlocal_fluid ? ws.hydro_force : VecX();
      VecX contact = VecX::Zero(3 * model_.num_nodes);
      for (const RodModel& rod : model_.rods)
        for (int i = 0; i < rod.num_nodes(); ++i)
          contact.segment<3>(3 * (rod.node_offset + i)) =
              ws.contact_force.segment<3>(rod.dof_offset + NodeDof(i));
      frames_->Write(model_, state, {{"hydrodynamic_force", &hydro}, {"contact_force", &contact}});
    }
  }

  void WriteSummary(RunStatus status, const std::string& message, const RunResult& result,
                    double max_penetration) const {
    nlohmann::json s;
    s["status"] = StatusName(status);
    s["message"] = message;
    s["config"] = nlohmann::json::parse(ConfigToJson(config_));
    s["derived"] = nlohmann::json::parse(DerivedJson(config_, model_));
    nlohmann::json final_row = nlohmann::json::object();
    for (std::size_t i = 0; i < last_row_.size(); ++i)
      final_row[columns_[i]] = std::isfinite(last_row_[i]) ? nlohmann::json(last_row_[i]) : nlohmann::json();
    s["final"] = final_row;
    s["max_penetration"] = max_penetration;
    s["steps"] = result.steps;
    s["newton_iterations"] = result.newton_iterations;
    s["wall_seconds"] = result.wall_seconds;
    s["version"] = STOKESRODS_VERSION;
    WriteFileAtomically((fs::path(plan_.output_dir) / "summary.json").string(), s.dump(2) + "\n");
  }

 private:
  const Config& config_;
  const Model& model_;
  const RunPlan& plan_;
  std::vector<std::string> columns_;
  CsvWriter csv_;
  std::optional<FrameWriter> frames_;
  std::vector<double> last_row_;
};

}  // namespace

RunResult RunCase(const Config& config, const RunOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  auto wall = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  const Model model = BuildModel(config);
  const RunPlan plan = MakeRunPlan(config, model);
  std::error_code ec;
  fs::create_directories(plan.output_dir, ec);
  if (ec) throw IoError(fmt::format("{}: cannot create the output directory: {}", plan.output_dir, ec.message()));
  const std::string checkpoint = (fs::path(plan.output_dir) / "checkpoint.bin").string();

  State state = MakeRestState(model);
  bool append = false;
  if (options.resume) {
    if (!fs::exists(checkpoint))
      throw IoError(fmt::format("{}: no checkpoint to resume from", checkpoint));
    state = LoadCheckpoint(checkpoint, model);
    append = TruncateTimeseries((fs::path(plan.output_dir) / "timeseries.csv").string(), state.time);
  }
  Workspace ws(model);
  Observer observer(config, model, plan, append);
  RunResult result;
  result.output_dir = plan.output_dir;
  double max_penetration = 0.0;
  StepReport report;
  report.ok = true;

  if (plan.static_mode) {
    report = SolveStatic(model, &state, &ws);
    result.newton_iterations = report.newton_iterations;
    result.wall_seconds = wall();
    result.status = report.ok ? RunStatus::kCompleted : RunStatus::kFailed;
    result.message = report.message;
    observer.Record(state, ws, report);
    observer.WriteSummary(result.status, result.message, result, report.contact.max_penetration);
    return result;
  }

  const double h = plan.time_step;
  const long total_steps = std::lround(std::ceil(plan.duration / h - 1e-9));
  const long output_every = std::max(1L, std::lround(plan.output_interval / h));
  const long checkpoint_every = std::max(1L, std::lround(plan.checkpoint_interval / h));
  if (!append) {
    report.contact = model.contact ? MeasureContacts(model, state.q) : ContactSummary{};
    // Forces of the rest state for the first row: one static evaluation is not needed, the rest
    // state has zero elastic force and no velocity.
    observer.Record(state, ws, report);
  }
  // Flow planes: at the first step that reaches each requested time.
  std::vector<double> flow_times = config.flow_field.times;
  std::sort(flow_times.begin(), flow_times.end());
  std::size_t next_flow = 0;
  while (next_flow < flow_times.size() && flow_times[next_flow] < state.time - 0.5 * h) ++next_flow;
  auto write_flow = [&] {
    while (next_flow < flow_times.size() && flow_times[next_flow] <= state.time + 0.5 * h) {
      WriteFlowField(model, state, config.flow_field, plan.output_dir, static_cast<int>(next_flow));
      ++next_flow;
    }
  };
  write_flow();
  double last_progress = -1.0;
  while (state.step < total_steps) {
    if (options.interrupted && options.interrupted()) {
      result.status = RunStatus::kInterrupted;
      result.message = fmt::format("interrupted at t = {:.6g} s", state.time);
      break;
    }
    report = Step(model, h, &state, &ws);
    result.newton_iterations += report.newton_iterations;
    if (!report.ok) {
      result.status = RunStatus::kFailed;
      result.message = report.message + "; the last good state is in " + checkpoint;
      break;
    }
    ++result.steps;
    max_penetration = std::max(max_penetration, report.contact.max_penetration);
    if (state.step % output_every == 0 || state.step == total_steps) observer.Record(state, ws, report);
    if (state.step % checkpoint_every == 0) SaveCheckpoint(checkpoint, state);
    write_flow();
    if (options.progress && wall() - last_progress >= 0.2) {
      last_progress = wall();
      options.progress({state.time, plan.duration, last_progress, state.step});
    }
  }
  SaveCheckpoint(checkpoint, state);
  result.steps = state.step;
  result.wall_seconds = wall();
  if (options.progress) options.progress({state.time, plan.duration, result.wall_seconds, state.step});
  observer.WriteSummary(result.status, result.message, result, max_penetration);
  return result;
}

}  // namespace stokesrods
