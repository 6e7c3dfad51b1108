// checkpoint.bin: everything a run needs to continue exactly as if it had never stopped.
//
// Contents: the State (t, step, q, q̇, frames, reference twists), the StepHistory (BDF2's
// previous q, q̇ and h, the drag's first guess), the run's counters, and what identifies the
// model it belongs to. The factors and preconditioners a run reuses across steps are not saved:
// the run forgets them at every restart point (sim/integrator.h ForgetReuse), so a resumed run,
// which starts without them, rebuilds the same ones at the same step (docs/reliability.md).
//
// Format (little-endian, version 2): "SRCKPT\0\0", uint32 version, the payload, then the FNV-1a
// 64-bit hash of everything before it. Written atomically (temporary file, then rename); a
// damaged, truncated, foreign or other-version file is refused with an IoError naming it.
#pragma once

#include <cstdint>
#include <string>

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

struct Checkpoint {
  State state;
  StepHistory history;
  RunCounters counters;
  double time_step = 0.0;  ///< [s] the run's h (a resume must use the same)
};

/// A hash of what a checkpoint must match: the DOF layout, rest shapes, masses and stiffnesses.
std::uint64_t ModelFingerprint(const Model& model);

void SaveCheckpoint(const std::string& path, const Model& model, const Checkpoint& checkpoint);

/// Throws IoError when the file cannot be read, is damaged (checksum), has another format
/// version, or belongs to another model.
Checkpoint LoadCheckpoint(const std::string& path, const Model& model);

}  // namespace stokesrods
