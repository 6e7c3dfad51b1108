// One simulation stepped by its caller: the configuration built into a model, the state and the
// scratch, and the controls a controller changes between steps (rotation rates, point loads).
// The run driver (runner.h) steps it and writes the outputs; the Python module steps it directly.
#pragma once

#include <string>
#include <vector>

#include "stokesrods/io/build_model.h"
#include "stokesrods/io/config.h"
#include "stokesrods/sim/integrator.h"
#include "stokesrods/sim/model.h"
#include "stokesrods/sim/state.h"

namespace stokesrods {

class Simulation {
 public:
  /// Builds the model and the rest state. Throws ConfigError.
  explicit Simulation(const Config& config);
  Simulation(const Simulation&) = delete;
  Simulation& operator=(const Simulation&) = delete;

  const Config& config() const { return config_; }
  const Model& model() const { return model_; }
  const RunPlan& plan() const { return plan_; }
  const State& state() const { return state_; }
  State& state() { return state_; }
  const Workspace& workspace() const { return ws_; }
  Workspace& workspace() { return ws_; }

  /// One step of plan().time_step. On failure the state is left as it was before the step.
  StepReport Step();
  /// The static equilibrium from the current state (run.mode = "static").
  StepReport SolveStatic();
  /// The report of the last Step or SolveStatic (contact summary, iterations).
  const StepReport& last_report() const { return last_report_; }

  /// Rod r (from 0): its imposed rotation rate about +ẑ [rad/s], from the next step on.
  void SetOmega(int r, double omega);
  /// Rod r (from 0): replaces its constant point loads, from the next step on.
  void SetLoads(int r, std::vector<PointLoad> loads);

  /// The state, the step history (BDF2, the drag's first guess) and the controls set by SetOmega
  /// and SetLoads to a checkpoint file, and back (io/checkpoint.h). Continuing
  /// after SaveCheckpoint and after LoadCheckpoint gives the same numbers. Throw IoError.
  void SaveCheckpoint(const std::string& path);
  void LoadCheckpoint(const std::string& path);

 private:
  Config config_;
  Model model_;
  RunPlan plan_;
  State state_;
  Workspace ws_;
  StepReport last_report_;
};

}  // namespace stokesrods
