// `stokesrods analyze RUN_OR_SWEEP_DIR`: the derived results of io/analysis.h for one run (printed,
// and analysis.json in its folder) or for every case of a sweep (analysis.csv) with the critical
// values along a line of it (critical.csv, printed).
#pragma once

#include <string>

namespace stokesrods {

struct AnalyzeOptions {
  std::string dir;
  std::string line;       ///< the key along which to find the critical value (default: the
                          ///< sweep's refine key, else rods.omega_bar)
  std::string criterion;  ///< "crossed" | "buckled" (default: the refine criterion, else crossed)
  std::string single;     ///< a run or sweep of one flagellum: F̄p relative to it at the same ω̄
};

/// Exit code (0; IoError and ConfigError propagate to main).
int RunAnalyzeCommand(const AnalyzeOptions& options);

}  // namespace stokesrods
