// The elastic forces alone (AddElasticForces without a Jacobian: per edge, by cross products)
// against the per-stencil path the Jacobian's assembly takes (elastic/bending.cc, twisting.cc).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "common/model_from_toml.h"
#include "stokesrods/sim/elastic_assembly.h"
#include "stokesrods/sim/integrator.h"
#include "stokesrods/sim/state.h"

namespace stokesrods {
namespace {

using testing::ModelFromToml;

constexpr char kHelix[] = R"(
[run]
duration = 1.0
time_step = 0.01
[fluid]
model = "none"
[contact]
enabled = false
[solver]
damping = 0.5
[[rods]]
nodes = 21
axis_length = 0.1
helix_radius = 0.008
omega_bar = 300
)";

TEST(ElasticAssembly, TheForcesAloneAreThoseOfThePerStencilPath) {
  // A driven helix after 30 steps (rest curvature and twist, frames transported, twisted), then
  // moved at random by up to a fifth of an edge and twisted by up to 0.5 rad per edge.
  const Model model = ModelFromToml(kHelix);
  State state = MakeRestState(model);
  Workspace ws(model);
  for (int k = 0; k < 30; ++k) ASSERT_TRUE(Step(model, 0.01, &state, &ws).ok);
  const RodModel& rod = model.rods[0];
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (const double size : {0.0, 1e-3, 0.2}) {
    VecX q = state.q;
    for (int k = 0; k < rod.num_dofs(); ++k)
      q(k) += size * u(rng) * (k % 4 == 3 ? 2.5 : rod.rest_edge_length.minCoeff());
    std::vector<RodFrames> frames;
    TransportFrames(model, q, state.rods, &frames);
    VecX reference = VecX::Zero(model.num_dofs), fast = VecX::Zero(model.num_dofs);
    BandedMatrix jacobian(rod.num_dofs(), 10);
    const double energy_reference = AddElasticForces(rod, q, frames[0], &reference, &jacobian);
    const double energy_fast = AddElasticForces(rod, q, frames[0], &fast, nullptr);
    // The forces on the nodes and the moments on the twist angles, each against its largest.
    for (const bool moments : {false, true}) {
      double scale = 0.0, error = 0.0;
      for (int k = 0; k < rod.num_dofs(); ++k) {
        if ((k % 4 == 3) != moments) continue;
        scale = std::max(scale, std::abs(reference(k)));
        error = std::max(error, std::abs(fast(k) - reference(k)));
      }
      std::printf("moved by %.0e edges: %s apart by %.2e of the largest (%.3e)\n", size,
                  moments ? "moments" : "forces", error / scale, scale);
      EXPECT_GT(scale, 0.0);
      EXPECT_LT(error, 1e-12 * scale) << (moments ? "moments" : "forces") << ", moved by " << size;
    }
    EXPECT_NEAR(energy_fast, energy_reference, 1e-12 * energy_reference);
  }
}

}  // namespace
}  // namespace stokesrods
