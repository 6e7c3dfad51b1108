// Built without MPI: a sweep runs on this machine only.
#include "sweep_command.h"

namespace stokesrods {

bool LaunchedByMpi() { return false; }

int RunSweepMpi(const SweepCommandOptions& options) {
  return ScheduleSweep(LoadSweep(options.file, options.output), options, nullptr);
}

}  // namespace stokesrods
