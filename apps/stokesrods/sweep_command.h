// `stokesrods sweep SWEEP.toml`: runs the cases of a sweep, each as a separate `stokesrods run`
// process (a crash takes down only its case), --jobs at a time on this machine and, under
// `mpirun -n K`, also on ranks 1..K-1, which ask rank 0 for the next case when they finish one
// (dynamic load balancing). Rank 0 keeps sweep.csv up to date after every case.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "stokesrods/io/sweep.h"

namespace stokesrods {

struct SweepCommandOptions {
  std::string file;
  std::string output;         ///< replaces the sweep file's `output` when not empty
  int jobs = 1;               ///< cases at a time in this process (rank 0 under MPI)
  int threads = 1;            ///< OMP_NUM_THREADS of each case
  bool retry_failed = false;  ///< rerun cases that failed numerically (they are skipped otherwise)
  std::function<bool()> interrupted;
};

/// One case finished somewhere: its index and its record.
struct FinishedCase {
  int worker = 0;
  int index = 0;
  CaseRecord record;
};

/// The other MPI ranks as seen from rank 0 (sweep_mpi.cc); absent without MPI.
class RemoteWorkers {
 public:
  virtual ~RemoteWorkers() = default;
  virtual int Count() const = 0;
  /// Case `index` (c) to a worker in [0, Count()); -1: no more cases.
  virtual void Assign(int worker, int index, const SweepCase& c) = 0;
  virtual std::optional<FinishedCase> Poll() = 0;       ///< a finished case, if any arrived
  virtual void StopAll() = 0;                           ///< no more cases
};

/// Runs one case to its end in a child process, forwarding an interrupt to it.
CaseRecord RunCaseProcess(const Sweep& sweep, const SweepCase& c, bool resume, int threads,
                          const std::function<bool()>& interrupted);

/// Rank 0 (or the only process): schedules every case; returns the exit code.
int ScheduleSweep(Sweep sweep, const SweepCommandOptions& options, RemoteWorkers* remote);

/// The command: MPI when launched by mpirun and built with it, else one machine. Exit code.
int RunSweepCommand(const SweepCommandOptions& options);

/// MPI (sweep_mpi.cc; without MPI: a stub). Whether this process was started by mpirun.
bool LaunchedByMpi();
/// Under MPI: rank 0 schedules with the other ranks as remote workers; the others serve cases.
int RunSweepMpi(const SweepCommandOptions& options);

}  // namespace stokesrods
