// Contact of rods with the wall and the cell bodies (sim/obstacle_contact.h): a straight rod driven
// by gravity onto the wall or onto a sphere is never closer to it than its radius (within the
// contact tolerance); at rest on the wall the contact carries its weight; on a free sphere the
// contact's reaction enters the sphere's balance of force.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "stokesrods/io/simulation.h"
#include "stokesrods/sim/bodies.h"
#include "stokesrods/sim/obstacle_contact.h"

namespace stokesrods {
namespace {

// A horizontal free rod (11 nodes, 5 cm, r0 = 1 mm) at z = 4 mm under gravity g along −z.
std::string FallingRod(const std::string& obstacle, double g) {
  std::string points = "[";
  for (int i = 0; i <= 10; ++i)
    points += (i ? ", " : "") + std::string("[") + std::to_string(-0.025 + 0.005 * i) + ", 0.0, 0.004]";
  points += "]";
  return "[run]\nduration = 1.0\ntime_step = 0.01\nframes = false\n"
         "[fluid]\nsolver = \"direct\"\n[gravity]\nacceleration = [0.0, 0.0, " + std::to_string(-g) + "]\n"
         "[[rods]]\nshape = \"points\"\nnodes = 11\nclamped_nodes = 0\nradius = 1e-3\n"
         "young_modulus = 1e8\npoints = " + points + "\n" + obstacle;
}

// The gap between the rod's nodes and the obstacle, less r0: ≥ −tolerance r0 when resolved.
double SmallestGap(const Simulation& sim) {
  const Model& model = sim.model();
  double gap = 1e9;
  for (int i = 0; i < model.rods[0].num_nodes(); ++i) {
    const Vec3 x = sim.state().q.segment<3>(NodeDof(i));
    if (model.fluid.wall) gap = std::min(gap, model.fluid.wall->normal.dot(x - model.fluid.wall->point));
    for (std::size_t k = 0; k < model.bodies.size(); ++k)
      gap = std::min(gap, (x - sim.state().bodies[k].center).norm() - model.bodies[k].radius);
  }
  return gap - model.rods[0].radius;
}

// Steps the falling rod; checks the gap at every step and that it ends on the obstacle. Returns
// the z force the contact carries at the end over the weight (1 at rest).
double LandAndRest(const std::string& text, int steps) {
  Simulation sim(ParseConfig(text, "fall.toml"));
  double worst = 1e9;
  for (int k = 0; k < steps; ++k) {
    EXPECT_TRUE(sim.Step().ok) << sim.last_report().message;
    worst = std::min(worst, SmallestGap(sim));
  }
  const RodModel& rod = sim.model().rods[0];
  double mass = 0.0, support = 0.0;
  for (int i = 0; i < rod.num_nodes(); ++i) {
    mass += rod.mass(NodeDof(i));
    support += sim.workspace().contact_force(NodeDof(i) + 2);
  }
  const double g = -sim.model().gravity.z();
  std::printf("smallest gap − r0 = %.3e r0 over the run; contact force %.4e N vs weight %.4e N; "
              "last step %d contact rounds\n",
              worst / rod.radius, support, mass * g, sim.last_report().contact_rounds);
  EXPECT_GE(worst, -sim.model().newton.contact_tolerance * rod.radius);
  EXPECT_LT(SmallestGap(sim), 0.05 * rod.radius);  // it is on the obstacle
  return support / (mass * g);
}

TEST(ObstacleContact, ARodFallsOntoTheWallAndRests) {
  // At rest the wall carries the weight: the drag vanishes as the rod stops, but for the velocity
  // of the contact's own resolution, tolerance r0 / h = 1e-4 m/s: a drag of 4πμL/ln(L/r0) × that
  // = 2e-5 N, 7e-4 of the weight.
  const double ratio = LandAndRest(FallingRod("[wall]\npoint = [0.0, 0.0, 0.0]\n", 200.0), 100);
  EXPECT_NEAR(ratio, 1.0, 1e-3);
}

// On the sphere's top the rod's balance is unstable: it lands, then slides off over the surface
// (its middle 2 cm aside and still moving at 1 s), in contact all the while.
TEST(ObstacleContact, ARodFallsOntoAFixedSphereAndSlidesOverIt) {
  const double ratio = LandAndRest(
      FallingRod("[[bodies]]\nradius = 0.02\ncenter = [0.0, 0.0, -0.0175]\nsurface_points = 100\n", 200.0), 100);
  EXPECT_GT(ratio, 0.0);
}

// On a free sphere the rod pushes the sphere down: its balance holds the contact's reaction, so
// the fluid's force on it equals the contact force on the rod (both up), to the Newton tolerance.
TEST(ObstacleContact, OnAFreeSphereTheReactionIsBalancedByTheFluid) {
  Simulation sim(ParseConfig(
      FallingRod("[[bodies]]\nradius = 0.02\ncenter = [0.0, 0.0, -0.0175]\nsurface_points = 100\n"
                 "motion = \"free\"\n", 200.0), "free.toml"));
  double most = 0.0, worst = 0.0;
  for (int k = 0; k < 40; ++k) {
    const BodyPose start = sim.state().bodies[0];
    ASSERT_TRUE(sim.Step().ok) << sim.last_report().message;
    Vec3 on_rod = Vec3::Zero();
    for (int i = 0; i < sim.model().rods[0].num_nodes(); ++i)
      on_rod += sim.workspace().contact_force.segment<3>(NodeDof(i));
    const Vec3 fluid = BodyHydroLoad(sim.model(), 0, start, sim.workspace().hydro_force).head<3>();
    most = std::max(most, on_rod.norm());
    worst = std::max(worst, (fluid - on_rod).norm());
  }
  std::printf("free sphere: contact force up to %.3e N, |fluid on sphere − contact on rod| ≤ %.2e N\n",
              most, worst);
  EXPECT_GT(most, 0.0);  // the contact did engage
  EXPECT_LT(worst, 1e-6 * most);
  EXPECT_LT(sim.state().bodies[0].center.z(), -0.0175);  // pushed down
}

}  // namespace
}  // namespace stokesrods
