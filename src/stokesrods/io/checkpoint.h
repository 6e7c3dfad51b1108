// checkpoint.bin: everything a run needs to continue exactly as if it had never stopped.
//
// Contents: the State (t, step, q, q̇, frames, reference twists), the StepHistory (BDF2's
// previous q, q̇ and h, the drag's first guess), the run's counters, and what identifies the
// model it belongs to. The factors and preconditioners a run reuses across steps are not saved:
// the run forgets them at every restart point (sim/integrator.h ForgetReuse), so a resumed run,
// which starts without them, rebuilds the same ones at the same step (docs/reliability.md). The
// dense 𝕄's reuse is kept instead: the checkpoint holds where its last two assemblies were taken,
// and the resumed run assembles them again (fluid/mobility_reuse.h).
//
// Since version 3 it also holds the controls a caller may change between steps (each rod's
// rotation rate and point loads; Simulation::SetOmega, SetLoads), which the model fingerprint
// leaves out. A run from the command line takes them from its configuration; the Python
// Simulation restores them. Version 4 adds the drags of the two steps before (the implicit
// drag's extrapolated first guess, sim/integrator.cc PredictDrag). Version 2 and 3 files still
// read; resumed from them, the first steps start from a less extrapolated guess, which changes
// the result within the Newton tolerance only. Version 5 adds the bodies' poses at t_{k−1} (BDF2
// with free bodies); resumed from an older file, BDF2 with free bodies takes one implicit Euler
// step first. Version 6 adds the dense 𝕄's reuse history; resumed from an older file, the reuse
// starts over (a few more assemblies; the result changes within the reuse's tolerance). Version 7
// adds the reuse's skipped measurements (fluid/mobility_reuse.h, SKIPPING); from version 6 the
// reuse measures at the next assembly (the same 𝕄 at every step while it assembles at each).
//
// Format (little-endian, version 7): "SRCKPT\0\0", uint32 version, the payload, then the FNV-1a
// 64-bit hash of everything before it. Written atomically (temporary file, then rename); a
// damaged, truncated, foreign or other-version file is refused with an IoError naming it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "stokesrods/sim/integrator.h"
#include "stokesrods/sim/model.h"
#include "stokesrods/sim/state.h"

namespace stokesrods {

/// What a run has accumulated that its outputs report (summary.json) besides the State.
struct RunCounters {
  long newton_iterations = 0;
  double max_penetration = 0.0;  ///< [m]
  long step_reductions = 0;      ///< steps retried at h/2
};

/// A rod's controls as they were when the checkpoint was written.
struct RodControls {
  double omega = 0.0;  ///< rotation rate about +ẑ [rad/s]
  std::vector<PointLoad> loads;
};

struct Checkpoint {
  State state;
  StepHistory history;
  RunCounters counters;
  double time_step = 0.0;  ///< [s] the run's h (a resume must use the same)
  /// Per rod; empty when read from a version 2 file. Saving writes the model's own controls.
  std::vector<RodControls> controls;
  /// The last row of timeseries.csv at full precision (the CSV holds 12 digits): a run resumed
  /// at its last step writes the same summary.json. Empty before version 8.
  std::vector<double> last_row;
};

/// A hash of what a checkpoint must match: the DOF layout, rest shapes, masses and stiffnesses.
std::uint64_t ModelFingerprint(const Model& model);

void SaveCheckpoint(const std::string& path, const Model& model, const Checkpoint& checkpoint);

/// Throws IoError when the file cannot be read, is damaged (checksum), has another format
/// version, or belongs to another model.
Checkpoint LoadCheckpoint(const std::string& path, const Model& model);

}  // namespace stokesrods
