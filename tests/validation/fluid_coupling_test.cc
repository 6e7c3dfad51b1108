// The coupling of the drag into the time step: the explicit scheme (paper Algorithm 1) and the
// implicit one agree where both are stable; the explicit one is refused past its limit.
#include <gtest/gtest.h>

#include <cmath>

#include "common/model_from_toml.h"
#include "stokesrods/io/build_model.h"
#include "stokesrods/sim/integrator.h"

namespace stokesrods {
namespace {

using testing::ModelFromToml;

constexpr char kHelix[] = R"(
[run]
duration = 0.3
time_step = 1e-4
[fluid]
model = "rss"
[contact]
enabled = false
[[rods]]
shape = "helix"
nodes = 33
omega_bar = 533
)";

Matrix3X Simulate(const std::string& coupling, double h, double duration) {
  Model m = ModelFromToml(kHelix);
  m.coupling = coupling == "explicit" ? FluidCoupling::kExplicit : FluidCoupling::kImplicit;
  State state = MakeRestState(m);
  Workspace ws(m);
  const long steps = std::lround(duration / h);
  for (long k = 0; k < steps; ++k) {
    const StepReport r = Step(m, h, &state, &ws);
    EXPECT_TRUE(r.ok) << r.message;
    if (!r.ok) break;
  }
  return RodPositions(m, 0, state.q);
}

TEST(FluidCoupling, ExplicitAndImplicitAgreeWhereBothAreStable) {
  // 0.3 s of the paper's helix (N = 33) at ω̄ = 533: the tip moves by about 1 cm.
  const Matrix3X exp = Simulate("explicit", 1e-4, 0.3);
  const Matrix3X imp = Simulate("implicit", 1e-4, 0.3);
  const Matrix3X rest = ModelFromToml(kHelix).rods[0].rest_positions;
  const double moved = (imp - rest).colwise().norm().maxCoeff();
  const double differ = (exp - imp).colwise().norm().maxCoeff();
  std::printf("largest node displacement %.4e m, explicit − implicit %.4e m\n", moved, differ);
  EXPECT_GT(moved, 1e-3);
  EXPECT_LT(differ, 1e-3 * moved);  // observed 8.6e-5: both are first order in h, they differ by O(h)
}

TEST(FluidCoupling, ExplicitIsRefusedPastItsLimitWithTheLargestStableStep) {
  const Model m = ModelFromToml(kHelix);
  const double limit = ExplicitStepLimit(m);
  // About 2 m/c: node mass ρπr0²Δl over a drag coefficient of order 4πμΔl/ln(L/r0).
  EXPECT_GT(limit, 1e-4);
  EXPECT_LT(limit, 2e-3);
  try {
    BuildModel(ParseConfig(kHelix, "case.toml",
                           {"fluid.coupling=explicit", "run.time_step=2e-3"}));
    FAIL() << "an explicit step past the limit was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("case.toml: run.time_step: fluid.coupling = \"explicit\" "
                                         "is stable only for a time step up to"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace stokesrods
