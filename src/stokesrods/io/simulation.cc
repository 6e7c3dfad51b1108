#include "stokesrods/io/simulation.h"

#include <fmt/format.h>

#include "stokesrods/io/checkpoint.h"
#include "stokesrods/io/writers.h"

namespace stokesrods {

Simulation::Simulation(const Config& config)
    : config_(config),
      model_(BuildModel(config_)),
      plan_(MakeRunPlan(config_, model_)),
      state_(MakeRestState(model_)),
      ws_(model_) {
  last_report_.ok = true;
}

StepReport Simulation::Step() {
  last_report_ = stokesrods::Step(model_, plan_.time_step, &state_, &ws_);
  return last_report_;
}

StepReport Simulation::SolveStatic() {
  last_report_ = stokesrods::SolveStatic(model_, &state_, &ws_);
  return last_report_;
}

void Simulation::SetOmega(int r, double omega) { SetRodOmega(&model_.rods.at(r), omega); }

void Simulation::SetLoads(int r, std::vector<PointLoad> loads) {
  RodModel& rod = model_.rods.at(r);
  for (const PointLoad& load : loads)
    if (load.node < 0 || load.node >= rod.num_nodes())
      throw std::out_of_range(fmt::format("rod {} has no node {} (nodes 0 to {})", r + 1, load.node,
                                          rod.num_nodes() - 1));
  rod.loads = std::move(loads);
}

void Simulation::LoadCheckpoint(const std::string& path) {
  Checkpoint c = stokesrods::LoadCheckpoint(path, model_);
  if (c.time_step != plan_.time_step)
    throw IoError(fmt::format("{}: written with run.time_step = {:.17g} s, this simulation steps "
                              "{:.17g} s",
                              path, c.time_step, plan_.time_step));
  state_ = std::move(c.state);
  for (std::size_t r = 0; r < c.controls.size(); ++r) {  // none from a version 2 file
    SetRodOmega(&model_.rods[r], c.controls[r].omega);
    model_.rods[r].loads = std::move(c.controls[r].loads);
  }
  ForgetReuse(&ws_);
  RestoreHistory(c.history, &ws_);
}

void Simulation::SaveCheckpoint(const std::string& path) {
  // As a run does at its restart points: forgetting what is reused across steps makes the
  // continuation from here and from the loaded checkpoint the same, digit for digit.
  ForgetReuse(&ws_);
  stokesrods::SaveCheckpoint(path, model_, {state_, CaptureHistory(ws_), {}, plan_.time_step, {}, {}});
}

}  // namespace stokesrods
