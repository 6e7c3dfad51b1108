#include "stokesrods/io/runner.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <optional>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "stokesrods/io/build_model.h"
#include "stokesrods/io/checkpoint.h"
#include "stokesrods/io/flow_field.h"
#include "stokesrods/io/simulation.h"
#include "stokesrods/io/writers.h"
#include "stokesrods/sim/integrator.h"
#include "stokesrods/sim/observables.h"

namespace stokesrods {

namespace fs = std::filesystem;

namespace {

const char* StatusName(RunStatus s) {
  return s == RunStatus::kCompleted ? "completed" : s == RunStatus::kFailed ? "failed" : "interrupted";
}

class Observer {
 public:
  /// `kept_rows` > 0 (--resume): the rows (and frames) of the earlier run that are kept.
  Observer(const Config& config, const Model& model, const RunPlan& plan, long kept_rows)
      : config_(config), model_(model), plan_(plan), columns_(TimeseriesColumns(model)),
        csv_(PrepareCsv((fs::path(plan.output_dir) / "timeseries.csv").string(), kept_rows),
             columns_, kept_rows > 0) {
    if (plan.frames) frames_.emplace(plan.output_dir, kept_rows, plan.frames_format);
  }

  void Record(const State& state, const Workspace& ws, const StepReport& report) {
    last_row_ = CalcTimeseriesRow(model_, state, ws, report);
    csv_.WriteRow(last_row_);
    WriteFrame(state, ws);
  }

  /// The last row written, at full precision (the checkpoint keeps it for a resume).
  const std::vector<double>& last_row() const { return last_row_; }

  /// A resume's last kept row, from the checkpoint at `path`: the summary of a run resumed at
  /// its last step is that of the run uninterrupted. A checkpoint before version 8 has none.
  void RestoreLastRow(const std::vector<double>& row, const std::string& path) {
    if (!row.empty() && row.size() != columns_.size())
      throw IoError(fmt::format("{}: cannot resume from this checkpoint: its time-series row has "
                                "{} values, this model writes {}", path, row.size(), columns_.size()));
    last_row_ = row;
  }

  /// The last row's value of `column` (NaN if there is no such column or no row yet).
  double LastValue(const std::string& column) const {
    for (std::size_t i = 0; i < columns_.size() && i < last_row_.size(); ++i)
      if (columns_[i] == column) return last_row_[i];
    return std::nan("");
  }

  void WriteFrame(const State& state, const Workspace& ws) {
    if (frames_) {
      // The rods' nodes' drag (the bodies' points follow them in ws.hydro_force).
      VecX hydro = ws.nonlocal_fluid ? VecX(ws.hydro_force.head(3 * model_.num_nodes)) : VecX();
      VecX contact = VecX::Zero(3 * model_.num_nodes);
      for (const RodModel& rod : model_.rods)
        for (int i = 0; i < rod.num_nodes(); ++i)
          contact.segment<3>(3 * (rod.node_offset + i)) =
              ws.contact_force.segment<3>(rod.dof_offset + NodeDof(i));
      const VecX body_forces = ws.nonlocal_fluid ? VecX(ws.hydro_force.segment(3 * model_.num_nodes, 3 * model_.num_body_points)) : VecX();
      frames_->Write(model_, state, {{"hydrodynamic_force", &hydro}, {"contact_force", &contact}},
                     &body_forces);
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
    s["step_reductions"] = result.step_reductions;
    s["wall_seconds"] = result.wall_seconds;
    if (IsNonlocal(model_.fluid.model))
      s["mobility_reuse"] = {{"updates", result.mobility_reuse.updates},
                             {"assemblies", result.mobility_reuse.assemblies},
                             {"largest_error", result.mobility_reuse.largest_error},
                             {"measurements", result.mobility_reuse.measurements}};
    s["krylov_products"] = result.krylov_products;
    s["preconditioner_builds"] = result.preconditioner_builds;
    s["version"] = STOKESRODS_VERSION;
    WriteFileAtomically((fs::path(plan_.output_dir) / "summary.json").string(), s.dump(2) + "\n");
  }

 private:
  static std::string PrepareCsv(const std::string& path, long kept_rows) {
    if (kept_rows > 0) TruncateCsv(path, kept_rows);
    return path;
  }

  const Config& config_;
  const Model& model_;
  const RunPlan& plan_;
  std::vector<std::string> columns_;
  CsvWriter csv_;
  std::optional<FrameWriter> frames_;
  std::vector<double> last_row_;
};


// The schedule of a dynamic run, in steps.
struct Schedule {
  const RunPlan& plan;

  bool Records(long step) const { return step % plan.output_every == 0 || step == plan.total_steps; }
  bool IsCheckpointStep(long step) const { return step % plan.checkpoint_every == 0; }
  bool IsRestartPoint(long step) const { return step % kRestartSteps == 0 || IsCheckpointStep(step); }
  /// Rows of timeseries.csv (and frames) an uninterrupted run has written once it is at `step`.
  long RowsThrough(long step) const {
    return 1 + step / plan.output_every +
           (step == plan.total_steps && step % plan.output_every != 0 ? 1 : 0);
  }
};

// One step of h; when it fails, retried as two steps of h/2, each again up to `halvings` deep
// (solver.max_step_halvings; the driver's policy on failure). The state then reads as one step
// of h; the next step, at h again, starts as implicit Euler. On failure the state and the
// history are those before the step (the last good state).
StepReport StepWithHalving(const Model& model, double h, int halvings, State* state,
                           Workspace* ws, long* reductions) {
  StepReport report = Step(model, h, state, ws);
  if (report.ok || halvings == 0) return report;
  const State before = *state;
  const StepHistory history = CaptureHistory(*ws);
  ++*reductions;
  StepReport half = StepWithHalving(model, 0.5 * h, halvings - 1, state, ws, reductions);
  const int first_iterations = half.newton_iterations;
  if (half.ok) half = StepWithHalving(model, 0.5 * h, halvings - 1, state, ws, reductions);
  half.newton_iterations += first_iterations + report.newton_iterations;
  if (!half.ok) {
    *state = before;
    RestoreHistory(history, ws);
    return half;
  }
  state->step = before.step + 1;
  state->time = before.time + h;
  return half;
}

// Resume: the checkpoint into the state, the workspace and the counters; returns the rows kept.
long Resume(const Config& config, const Model& model, const RunPlan& plan,
            const std::string& path, State* state, Workspace* ws, RunCounters* counters,
            std::vector<double>* last_row) {
  if (plan.static_mode) throw ConfigError(config.file, "run.mode", "--resume needs a dynamic run");
  if (!fs::exists(path)) throw IoError(fmt::format("{}: no checkpoint to resume from", path));
  Checkpoint c = LoadCheckpoint(path, model);
  if (c.time_step != plan.time_step)
    throw ConfigError(config.file, "run.time_step",
                      fmt::format("{} was written with run.time_step = {:.17g} s; resume with the "
                                  "same (got {:.17g} s) or start a new run",
                                  path, c.time_step, plan.time_step));
  if (c.state.step > plan.total_steps)
    throw ConfigError(config.file, config.run.duration ? "run.duration" : "run.t_bar_end",
                      fmt::format("{} is at t = {:.6g} s, past the end of this run ({:.6g} s)",
                                  path, c.state.time, plan.duration));
  *state = std::move(c.state);
  RestoreHistory(c.history, ws);
  *counters = c.counters;
  *last_row = std::move(c.last_row);
  return Schedule{plan}.RowsThrough(state->step);
}

}  // namespace

RunResult RunCase(const Config& config, const RunOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  auto wall = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  Simulation sim(config);
  const Model& model = sim.model();
  const RunPlan& plan = sim.plan();
  std::error_code ec;
  fs::create_directories(plan.output_dir, ec);
  if (ec) throw IoError(fmt::format("{}: cannot create the output directory: {}", plan.output_dir, ec.message()));
  const std::string checkpoint = (fs::path(plan.output_dir) / "checkpoint.bin").string();

  State& state = sim.state();
  Workspace& ws = sim.workspace();
  RunCounters counters;
  std::vector<double> kept_last_row;
  const long kept_rows = options.resume ? Resume(config, model, plan, checkpoint, &state, &ws,
                                                 &counters, &kept_last_row)
                                        : 0;
  Observer observer(config, model, plan, kept_rows);
  observer.RestoreLastRow(kept_last_row, checkpoint);
  RunResult result;
  result.output_dir = plan.output_dir;
  StepReport report;
  report.ok = true;

  if (plan.static_mode) {
    report = sim.SolveStatic();
    result.newton_iterations = report.newton_iterations;
    result.wall_seconds = wall();
    result.status = report.ok ? RunStatus::kCompleted : RunStatus::kFailed;
    result.message = report.message;
    observer.Record(state, ws, report);
    observer.WriteSummary(result.status, result.message, result, report.contact.max_penetration);
    return result;
  }

  const double h = plan.time_step;
  const Schedule schedule{plan};
  long saved_step = -1;
  auto save_checkpoint = [&] {
    SaveCheckpoint(checkpoint, model, {state, CaptureHistory(ws), counters, h, {}, observer.last_row()});
    saved_step = state.step;
  };
  if (kept_rows == 0) {
    report.contact = model.contact ? MeasureContacts(model, state.q) : ContactSummary{};
    // Forces of the rest state for the first row: one static evaluation is not needed, the rest
    // state has zero elastic force and no velocity.
    observer.Record(state, ws, report);
  }
  // Flow planes: at the first step that reaches each requested time.
  std::vector<double> flow_times = config.flow_field.times;
  std::sort(flow_times.begin(), flow_times.end());
  std::size_t next_flow = 0;  // on resume: past those the steps up to the checkpoint wrote
  while (kept_rows > 0 && next_flow < flow_times.size() && flow_times[next_flow] <= state.time + 0.5 * h)
    ++next_flow;
  auto write_flow = [&] {
    while (next_flow < flow_times.size() && flow_times[next_flow] <= state.time + 0.5 * h) {
      WriteFlowField(model, state, config.flow_field, plan.output_dir, static_cast<int>(next_flow));
      ++next_flow;
    }
  };
  if (kept_rows == 0) {
    write_flow();
    save_checkpoint();  // step 0 is a restart point: a run always has a checkpoint
  }
  // The stop on buckling (run.stop_tip_axis_distance), from the last row: checked after each
  // recorded step, and on resume (a run resumed where it stopped stops there again).
  auto buckled = [&]() -> std::optional<std::string> {
    const double tip = observer.LastValue("rod1_tip_axis_distance");
    if (!(plan.stop_tip_axis_distance > 0.0 && tip > plan.stop_tip_axis_distance)) return std::nullopt;
    return fmt::format(
        "stopped at t_bar = {:.6g}: rod 1 buckled (its last node {:.3g} R off its clamp's vertical)",
        observer.LastValue("t_bar"), kBuckledTipAxisDistanceOverR * tip / plan.stop_tip_axis_distance);
  };
  double last_progress = -1.0, last_checkpoint = 0.0;
  bool stopping = false;
  if (kept_rows > 0)
    if (std::optional<std::string> stop = buckled()) result.message = *stop;
  while (state.step < plan.total_steps && result.message.empty()) {
    stopping = stopping || (options.interrupted && options.interrupted());
    const bool stop_now = options.stop_now && options.stop_now();
    if ((stopping && schedule.IsRestartPoint(state.step)) || stop_now) {
      if (!stop_now && saved_step != state.step) save_checkpoint();
      result.status = RunStatus::kInterrupted;
      result.message = fmt::format("interrupted at t = {:.6g} s", state.time);
      break;
    }
    report = StepWithHalving(model, h, plan.max_step_halvings, &state, &ws,
                             &counters.step_reductions);
    counters.newton_iterations += report.newton_iterations;
    if (!report.ok) {
      result.status = RunStatus::kFailed;
      result.message = report.message + "; the last good state is in " + checkpoint +
                       (plan.frames ? " and the last frame" : "");
      observer.WriteFrame(state, ws);
      save_checkpoint();
      break;
    }
    counters.max_penetration = std::max(counters.max_penetration, report.contact.max_penetration);
    if (schedule.Records(state.step)) {
      observer.Record(state, ws, report);
      if (std::optional<std::string> stop = buckled()) {
        result.message = *stop;
        save_checkpoint();
        break;
      }
    }
    write_flow();
    if (schedule.IsRestartPoint(state.step)) {
      ForgetReuse(&ws);
      const bool due = plan.checkpoint_wall_interval > 0.0
                           ? wall() - last_checkpoint >= plan.checkpoint_wall_interval
                           : schedule.IsCheckpointStep(state.step);
      if (due || state.step == plan.total_steps) {
        save_checkpoint();
        last_checkpoint = wall();
      }
    }
    if (options.progress && wall() - last_progress >= 0.2) {
      last_progress = wall();
      options.progress({state.time, plan.duration, last_progress, state.step});
    }
  }
  // A run that ends off the restart points keeps the last one as its checkpoint (a longer run
  // resumed from it continues exactly); its final state is in the last row and frame.
  result.steps = state.step;
  result.newton_iterations = counters.newton_iterations;
  result.step_reductions = counters.step_reductions;
  result.wall_seconds = wall();
  if (ws.nonlocal_fluid) {
    result.mobility_reuse = ws.hydro.mobility().reuse_stats();
    result.krylov_products = ws.hydro.krylov_iterations();
    result.preconditioner_builds = ws.hydro.preconditioner_builds();
  }
  if (options.progress) options.progress({state.time, plan.duration, result.wall_seconds, state.step});
  observer.WriteSummary(result.status, result.message, result, counters.max_penetration);
  return result;
}

}  // namespace stokesrods
