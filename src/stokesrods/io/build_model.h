// From a validated configuration to the constant Model and the plan of the run.
#pragma once

#include <string>

#include "stokesrods/io/config.h"
#include "stokesrods/io/vtk_arrays.h"
#include "stokesrods/sim/model.h"

namespace stokesrods {

/// What the driver needs besides the model, with every default resolved.
struct RunPlan {
  std::string name;
  std::string output_dir;
  bool static_mode = false;
  double duration = 0.0;             ///< [s]
  double time_step = 0.0;            ///< [s]
  double output_interval = 0.0;      ///< [s]
  double checkpoint_interval = 0.0;  ///< [s]
  double checkpoint_wall_interval = 0.0;  ///< [s] of wall time (0: every checkpoint_interval)
  int max_step_halvings = 0;         ///< a failed step is retried as two of h/2, this deep
  /// > 0 (run.stop_when_buckled): stop once rod 1's last node is farther than this from the
  /// vertical through its clamp [m]
  double stop_tip_axis_distance = 0.0;
  bool frames = true;
  VtkFormat frames_format = VtkFormat::kAscii;  ///< run.frames_format
  // The same in steps of time_step (dynamic runs).
  long total_steps = 0;
  long output_every = 1;
  long checkpoint_every = 1;
};

/// The most steps a run may take (a larger count is a typo in time_step or duration).
constexpr double kMaxSteps = 1e12;

/// Builds the model. Throws ConfigError for input that is well-typed but physically unusable
/// (rods overlapping at the start, a model not available, ...).
Model BuildModel(const Config& config);

/// Sets the rod's imposed rotation rate ω about +ẑ [rad/s] (rod.omega and the twist rate of θ0).
void SetRodOmega(RodModel* rod, double omega);

/// The largest time step for which fluid.coupling = "explicit" is stable at the rest shape [s]
/// (the drag as forward Euler on the free nodes: h ≤ 2 Re λ/|λ|² over the eigenvalues λ of
/// M⁻¹ (𝕄⁻¹)_ff, about 2 m/c for node mass m and node drag coefficient c).
double ExplicitStepLimit(const Model& model);

/// Throws ConfigError for a dynamic run whose step count overflows or is zero, whose time step
/// exceeds the duration or the output or checkpoint interval.
RunPlan MakeRunPlan(const Config& config, const Model& model);

/// The derived quantities as a JSON object text: EI, GJ, EA per rod, time_scale, omega and
/// omega_bar per rod, node masses, ... (show-config and summary.json "derived").
std::string DerivedJson(const Config& config, const Model& model);

}  // namespace stokesrods
