// The columns of timeseries.csv (SPEC "Outputs") computed from a state.
#pragma once

#include <string>
#include <vector>

#include "stokesrods/sim/integrator.h"
#include "stokesrods/sim/model.h"
#include "stokesrods/sim/state.h"

namespace stokesrods {

/// Normalization of the paper (eq. 24, 26) from rod 1: EI, μ and l0 (1 s and 1 N without rods).
struct Scales {
  double time = 1.0;   ///< μ l0⁴ / EI [s]
  double force = 1.0;  ///< EI / l0² [N]
};
Scales CalcScales(const Model& model);

/// Column names, in SPEC order, then the extra columns:
/// rod{k}_tip_axis_distance (distance of the last node from the vertical line through node 0:
/// shows a buckled helix whose axis tilts even when its length does not change),
/// max_penetration (this step), newton_iterations (this step).
std::vector<std::string> TimeseriesColumns(const Model& model);

/// A helix has buckled when its tip is off its clamp's vertical by more than this × its helix
/// radius R (a helical rod keeps it at R; its axis tilts when it buckles): analyze's rule
/// (io/analysis.h) and run.stop_when_buckled.
constexpr double kBuckledTipAxisDistanceOverR = 2.0;

/// One row for the state after `report` (ws holds the forces of that step).
std::vector<double> CalcTimeseriesRow(const Model& model, const State& state, const Workspace& ws,
                                      const StepReport& report);

}  // namespace stokesrods
