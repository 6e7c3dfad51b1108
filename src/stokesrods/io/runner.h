// The driver of one run: owns the loop over steps, the observers (CSV, frames, checkpoints,
// summary) and the policy on failure. Used by the command line and the Python module.
#pragma once

#include <functional>
#include <string>

#include "stokesrods/fluid/mobility_reuse.h"

#include "stokesrods/io/config.h"

namespace stokesrods {

enum class RunStatus { kCompleted, kFailed, kInterrupted };

struct RunProgress {
  double time = 0.0;      ///< simulated [s]
  double duration = 0.0;  ///< to simulate [s]
  double wall_seconds = 0.0;
  long steps = 0;
};

struct RunOptions {
  bool resume = false;                              ///< continue from the last checkpoint
  /// Polled every step (e.g. SIGINT seen): the run goes on to the next restart point (at most 60
  /// steps), writes a checkpoint there and stops, so that --resume continues it exactly.
  std::function<bool()> interrupted;
  /// Polled every step (e.g. a second SIGINT): stop after the current step; checkpoint.bin keeps
  /// the last restart point.
  std::function<bool()> stop_now;
  std::function<void(const RunProgress&)> progress; ///< called about every 0.2 s of wall time
};

/// Restart points: after every kRestartSteps-th step and every checkpoint step a run forgets the
/// factors it reuses across steps (sim/integrator.h ForgetReuse), so that a run resumed there
/// continues bit for bit. A multiple of the Krylov preconditioner's own largest age (40): no extra
/// rebuilds of it. The dense 𝕄's reuse history is not forgotten but kept in the checkpoint (until
/// 2026-11-25 it was dropped here, and rebuilding it took a few assemblies: restart points were
/// put 60 instead of 20 steps apart for it); the matrix-free operator chooses its near/far split
/// again (fluid/mobility_operator.h), which costs a second Update there. 120 steps apart since
/// 2026-11-25 (60 before): an interrupt waits up to 120 steps.
constexpr long kRestartSteps = 120;

struct RunResult {
  RunStatus status = RunStatus::kCompleted;
  std::string message;
  std::string output_dir;
  long steps = 0;
  long newton_iterations = 0;
  long step_reductions = 0;  ///< steps retried at h/2 (solver.max_step_halvings)
  double wall_seconds = 0.0;
  /// The dense 𝕄's reuse across steps (fluid.mobility_reuse_tolerance), counted like
  /// wall_seconds over this process's steps only (a resumed run counts from its restart).
  MobilityReuseStats mobility_reuse;
  /// GMRES products (fluid.solver = "krylov"), counted like wall_seconds.
  long krylov_products = 0;
  long preconditioner_builds = 0;  ///< of C's Krylov preconditioner, or its LU (direct)
};

/// Runs the configured case and writes its outputs. Throws ConfigError (bad input) and IoError
/// (cannot write); a numerical failure is a result with status kFailed, the last good state saved.
RunResult RunCase(const Config& config, const RunOptions& options = {});

}  // namespace stokesrods
