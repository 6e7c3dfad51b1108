// TOML pieces of the small helix and swimming-cell cases shared by the tests (as
// common/small_helices.h): a helix of axis length 0.1 m and radius 8 mm, a sphere, and the
// swimming cell (a free sphere holding two such helices) beside a fixed sphere.
#pragma once

#include <string>

namespace stokesrods::testing {

/// A `[[rods]]` entry: the small helix with `nodes`, its base at (base_x, 0, 0), and `extra`
/// lines (omega_bar, pitch, body, ...).
inline std::string HelixToml(int nodes, double base_x, const std::string& extra = "") {
  return "[[rods]]\nnodes = " + std::to_string(nodes) +
         "\naxis_length = 0.1\nhelix_radius = 0.008\nbase = [" + std::to_string(base_x) +
         ", 0.0, 0.0]\n" + extra + "\n";
}

/// A `[[bodies]]` sphere of `radius` at `center` ("[x, y, z]") with `surface_points`.
inline std::string SphereToml(double radius, const std::string& center, const std::string& motion,
                              int surface_points) {
  return "[[bodies]]\nradius = " + std::to_string(radius) + "\ncenter = " + center +
         "\nmotion = \"" + motion + "\"\nsurface_points = " + std::to_string(surface_points) + "\n";
}

struct CellCase {
  int nodes = 33;             ///< per helix
  int cell_points = 200;      ///< the free sphere's (radius 25 mm, the helices' bases on it)
  int fixed_points = 150;     ///< the fixed sphere's beside it (radius 15 mm)
  double omega_bar = 320.0;   ///< the motors' speed (0: none)
};

/// The swimming cell: [run] (duration 1 s), [fluid] (RSS plus `fluid_lines`), a free sphere
/// holding two helices (pitch 0.05 m, the second 30 mm along x) and a fixed sphere.
inline std::string SwimmingCellToml(const CellCase& c, const std::string& fluid_lines = "") {
  const std::string motor =
      "pitch = 0.05\nbody = 1" +
      (c.omega_bar != 0.0 ? "\nomega_bar = " + std::to_string(c.omega_bar) : std::string());
  return "[run]\nduration = 1.0\n[fluid]\nmodel = \"rss\"\n" + fluid_lines + "\n" +
         SphereToml(0.025, "[0.015, 0.0, 0.02]", "free", c.cell_points) +
         SphereToml(0.015, "[0.08, 0.0, -0.05]", "fixed", c.fixed_points) +
         HelixToml(c.nodes, 0.0, motor) + HelixToml(c.nodes, 0.03, motor);
}

}  // namespace stokesrods::testing
