// The driver of one run: owns the loop over steps, the observers (CSV, frames, checkpoints,
// summary) and the policy on failure. Used by the command line and the Python module.
#pragma once

#include <functional>
#include <string>

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
  std::function<bool()> interrupted;                ///< polled every step (e.g. SIGINT seen)
  std::function<void(const RunProgress&)> progress; ///< called about every 0.2 s of wall time
};

struct RunResult {
  RunStatus status = RunStatus::kCompleted;
  std::string message;
  std::string output_dir;
  long steps = 0;
  long newton_iterations = 0;
  double wall_seconds = 0.0;
};

/// Runs the configured case and writes its outputs. Throws ConfigError (bad input) and IoError
/// (cannot write); a numerical failure is a result with status kFailed, the last good state saved.
RunResult RunCase(const Config& config, const RunOptions& options = {});

}  // namespace stokesrods
