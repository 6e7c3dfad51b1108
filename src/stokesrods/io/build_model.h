// From a validated configuration to the constant Model and the plan of the run.
#pragma once

#include <string>

#include "stokesrods/io/config.h"
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
  bool frames = true;
};

/// Builds the model. Throws ConfigError for input that is well-typed but physically unusable
/// (rods overlapping at the start, a model not available, ...).
Model BuildModel(const Config& config);

/// The largest time step for which fluid.coupling = "explicit" is stable at the rest shape [s]
/// (the drag as forward Euler on the free nodes: h ≤ 2 Re λ/|λ|² over the eigenvalues λ of
/// M⁻¹ (𝕄⁻¹)_ff, about 2 m/c for node mass m and node drag coefficient c).
double ExplicitStepLimit(const Model& model);

RunPlan MakeRunPlan(const Config& config, const Model& model);

/// The derived quantities as a JSON object text: EI, GJ, EA per rod, time_scale, omega and
/// omega_bar per rod, node masses, ... (show-config and summary.json "derived").
std::string DerivedJson(const Config& config, const Model& model);

}  // namespace stokesrods
