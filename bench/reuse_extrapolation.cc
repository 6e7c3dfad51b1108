// How far the dense 𝕄 can be extrapolated (fluid/mobility_reuse.h): paper Fig. 1 at h = 1 ms is
// stepped W steps from rest, then 𝕄 is assembled at each of the next 61 steps, and the linear and
// quadratic extrapolations from histories d steps apart (the last at step 20 of those) are
// compared with the assembled 𝕄 j steps later, in the relative Frobenius norm.
//
//   reuse_extrapolation [W]      (default 300)
//
// Prints one line per (d, j): the linear error (through steps 20 − d, 20) and the quadratic one
// (through 20 − 2d, 20 − d, 20), or "-" where the history does not fit.
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "stokesrods/fluid/hydrodynamics.h"
#include "stokesrods/io/build_model.h"
#include "stokesrods/io/config.h"
#include "stokesrods/sim/hydro_coupling.h"
#include "stokesrods/sim/integrator.h"

int main(int argc, char** argv) {
  using namespace stokesrods;
  const int warmup = argc > 1 ? std::atoi(argv[1]) : 300;
  const Config config = ParseConfig(R"(
[run]
duration = 1.0
time_step = 1e-3
[fluid]
model = "rss"
[contact]
enabled = true
[[rods]]
omega_bar = 320
[[rods]]
omega_bar = 320
base = [0.03, 0.0, 0.0]
)", "reuse_extrapolation.toml");
  const Model model = BuildModel(config);
  const double h = MakeRunPlan(config, model).time_step;
  State state = MakeRestState(model);
  Workspace ws(model);
  std::vector<MatX> m;
  for (int k = 0; k < warmup + 61; ++k) {
    if (!Step(model, h, &state, &ws).ok) {
      std::fprintf(stderr, "step %d failed\n", k + 1);
      return 3;
    }
    if (k < warmup) continue;
    std::vector<Matrix3X> positions(model.rods.size());
    for (std::size_t r = 0; r < model.rods.size(); ++r)
      positions[r] = RodPositions(model, static_cast<int>(r), state.q);
    AssembleMobility(model.fluid, MakeHydroRods(model, positions), &m.emplace_back());
  }
  const int b = 20;  // the last assembly of the history
  std::printf("t = %.3f s at the history's last assembly\n", (warmup + b + 1) * h);
  for (const int d : {1, 4, 8, 16}) {
    for (const int j : {4, 8, 12, 16, 20, 30, 40}) {
      const MatX& exact = m[static_cast<std::size_t>(b + j)];
      const double s = static_cast<double>(j) / d;
      const MatX slope = m[b] - m[static_cast<std::size_t>(b - d)];
      const MatX linear = m[b] + s * slope;
      std::printf("d = %2d  j = %2d  linear %.2e", d, j, (linear - exact).norm() / exact.norm());
      if (b - 2 * d >= 0) {
        const MatX second = slope - (m[static_cast<std::size_t>(b - d)] - m[static_cast<std::size_t>(b - 2 * d)]);
        const MatX quadratic = linear + 0.5 * s * (s + 1.0) * second;
        std::printf("  quadratic %.2e\n", (quadratic - exact).norm() / exact.norm());
      } else {
        std::printf("  quadratic -\n");
      }
    }
  }
  return 0;
}
