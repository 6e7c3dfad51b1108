// The small-helix cases of the solver tests: one or two helices of axis length 0.1 m and radius
// 8 mm (the second 17.5 mm from the first along x), contact off, as TOML text.
#pragma once

#include <string>

#include "common/cell_toml.h"

namespace stokesrods::testing {

/// `run_lines` and `fluid_lines` are added to [run] (after duration = 1.0) and [fluid].
inline std::string SmallHelicesToml(int rods, int nodes, double omega_bar,
                                    const std::string& fluid_lines,
                                    const std::string& run_lines = "") {
  std::string text = "[run]\nduration = 1.0\n" + run_lines + "\n[fluid]\n" + fluid_lines +
                     "\n[contact]\nenabled = false\n";
  for (int r = 0; r < rods; ++r)
    text += HelixToml(nodes, 0.0175 * r, "omega_bar = " + std::to_string(omega_bar));
  return text;
}

}  // namespace stokesrods::testing
