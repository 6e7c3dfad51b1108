// Contact between rods (paper section 2.3): two straight rods pushed into each other by point
// loads never come closer than 2 r0 (1 − 1e-3), and the contact forces are equal and opposite.
#include <gtest/gtest.h>

#include "common/model_from_toml.h"
#include "stokesrods/sim/contact_forces.h"
#include "stokesrods/sim/integrator.h"

namespace stokesrods {
namespace {

using testing::ModelFromToml;

// Rod 1 hangs along −z from the origin; rod 2 lies along +y at the height z = −0.1 m, 4 mm to the
// side (clamped at its left end). Loads push rod 1's tip to +x and rod 2's free end to −x: they
// cross at right angles and press on each other. Damping makes it settle.
constexpr char kCrossing[] = R"(
[run]
duration = 30.0
time_step = 0.01
[fluid]
model = "none"
[contact]
enabled = true
tolerance = 1e-3
[solver]
damping = 0.05
[[rods]]
shape = "straight"
nodes = 41
axis_length = 0.2
loads = [{ node = 40, force = [2e-4, 0.0, 0.0] }]
[[rods]]
shape = "points"
points = [[0.004, -0.1, -0.1], [0.004, -0.095, -0.1], [0.004, -0.09, -0.1], [0.004, -0.085, -0.1],
          [0.004, -0.08, -0.1], [0.004, -0.075, -0.1], [0.004, -0.07, -0.1], [0.004, -0.065, -0.1],
          [0.004, -0.06, -0.1], [0.004, -0.055, -0.1], [0.004, -0.05, -0.1], [0.004, -0.045, -0.1],
          [0.004, -0.04, -0.1], [0.004, -0.035, -0.1], [0.004, -0.03, -0.1], [0.004, -0.025, -0.1],
          [0.004, -0.02, -0.1], [0.004, -0.015, -0.1], [0.004, -0.01, -0.1], [0.004, -0.005, -0.1],
          [0.004, 0.0, -0.1], [0.004, 0.005, -0.1], [0.004, 0.01, -0.1], [0.004, 0.015, -0.1],
          [0.004, 0.02, -0.1], [0.004, 0.025, -0.1], [0.004, 0.03, -0.1], [0.004, 0.035, -0.1],
          [0.004, 0.04, -0.1], [0.004, 0.045, -0.1], [0.004, 0.05, -0.1]]
loads = [{ node = 30, force = [-2e-4, 0.0, 0.0] }]
)";

TEST(Contact, RodsPushedTogetherStayApartWithEqualAndOppositeForces) {
  const Model model = ModelFromToml(kCrossing);
  State state = MakeRestState(model);
  Workspace ws(model);
  const double contact_distance = 2.0 * 1e-3;
  double closest = 1.0;
  int steps_in_contact = 0;
  for (int k = 0; k < 3000; ++k) {
    const StepReport report = Step(model, 0.01, &state, &ws);
    ASSERT_TRUE(report.ok) << report.message;
    closest = std::min(closest, MinDistanceBetweenRods(model, state.q));
    if (report.contact_pairs > 0) ++steps_in_contact;
  }
  std::printf("closest approach %.6e m (contact distance %.1e m), %d steps with contact forces\n",
              closest, contact_distance, steps_in_contact);
  EXPECT_GT(steps_in_contact, 100);  // they really were pressed together
  EXPECT_GE(closest, contact_distance * (1.0 - 1e-3));
  EXPECT_LT(closest, contact_distance * 1.01);  // and they touch at the end

  // Equal and opposite: the contact forces on each rod sum to opposite vectors, and at rest each
  // balances the load that presses its rod into the other... through the rod's clamp as well, so
  // only the sign and the equality are asserted, plus that they are not negligible.
  Vec3 on1 = Vec3::Zero(), on2 = Vec3::Zero();
  for (int i = 0; i < model.rods[0].num_nodes(); ++i) on1 += ws.contact_force.segment<3>(NodeDof(i));
  for (int i = 0; i < model.rods[1].num_nodes(); ++i)
    on2 += ws.contact_force.segment<3>(model.rods[1].dof_offset + NodeDof(i));
  std::printf("contact force on rod 1 (%.4e, %.4e, %.4e) N, on rod 2 (%.4e, %.4e, %.4e) N\n",
              on1.x(), on1.y(), on1.z(), on2.x(), on2.y(), on2.z());
  EXPECT_GT(on1.norm(), 1e-5);
  EXPECT_LT((on1 + on2).norm(), 1e-9 * on1.norm() + 1e-15);
  EXPECT_LT(on1.x(), 0.0);  // rod 1 is pushed back towards −x
}

}  // namespace
}  // namespace stokesrods
