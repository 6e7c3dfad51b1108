// Contact of the cell bodies with the wall and with each other (sim/body_contact.h): a free sphere
// pushed onto the wall by its own force stops at the contact distance and the contact carries the
// force; two free spheres pushed together never interpenetrate and end at rest in contact; every
// step, each body's fluid load, own load and contact reaction balance, and the contacts' reactions
// cancel in pairs.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "stokesrods/io/simulation.h"
#include "stokesrods/sim/bodies.h"

namespace stokesrods {
namespace {

constexpr double kRadius = 0.01;  // a [m]
// The force that moves a lone sphere at 1 cm/s: 6πμaU with μ = 1 Pa·s [N].
const double kForce = 6.0 * kPi * kRadius * 0.01;

std::string Body(const Vec3& center, const Vec3& force) {
  auto vec = [](const Vec3& v) {
    return "[" + std::to_string(v.x()) + ", " + std::to_string(v.y()) + ", " + std::to_string(v.z()) + "]";
  };
  return "[[bodies]]\nradius = " + std::to_string(kRadius) + "\ncenter = " + vec(center) +
         "\nmotion = \"free\"\nsurface_points = 100\nforce = " + vec(force) + "\n";
}

std::string RunTable(double duration, double h) {
  return "[run]\nduration = " + std::to_string(duration) + "\ntime_step = " + std::to_string(h) +
         "\nframes = false\n[fluid]\nsolver = \"direct\"\n";
}

// Each free body's balance at the last step: fluid load (at the pose where 𝕄 was taken) + own load
// + contact reaction (ws.body_load holds the last two), relative to the own load's size.
double WorstImbalance(const Simulation& sim) {
  const Model& model = sim.model();
  const Workspace& ws = sim.workspace();
  double worst = 0.0;
  for (int k = 0; k < static_cast<int>(model.bodies.size()); ++k) {
    const BodyModel& body = model.bodies[static_cast<std::size_t>(k)];
    const Vec6 fluid = BodyHydroLoad(model, k, ws.body_step.geometry[static_cast<std::size_t>(k)],
                                     ws.hydro_force);
    const Vec6 total = fluid + ws.body_load.segment<6>(6 * body.free_index);
    worst = std::max({worst, total.head<3>().norm() / kForce,
                      total.tail<3>().norm() / (kForce * kRadius)});
  }
  return worst;
}

// The contact's reaction on free body k at the last step: body_load less its own load [N].
Vec3 ContactReaction(const Simulation& sim, int k) {
  const BodyModel& body = sim.model().bodies[static_cast<std::size_t>(k)];
  return sim.workspace().body_load.segment<3>(6 * body.free_index) - body.force;
}

// A sphere 5 mm above the wall (z = 0), pushed down at 1 cm/s (far from the wall; far slower near
// it, where the blobs' images resist) for 4 s: it reaches the wall after about 2 s and rests there.
struct Settled {
  double lowest = 1e9;         ///< the lowest gap over the run, centre height − a [m]
  double mean_support = 0.0;   ///< the contact's z force over the last 60 steps, mean [N]
  double mean_velocity = 0.0;  ///< the body's U_z over them, mean [m/s]
  double worst_balance = 0.0;  ///< WorstImbalance over the run
  int touching_steps = 0;
};

Settled Settle(double contact_tolerance) {
  const std::string text = RunTable(4.0, 0.02) + "[contact]\ntolerance = " +
                           std::to_string(contact_tolerance) + "\n[wall]\npoint = [0.0, 0.0, 0.0]\n" +
                           Body(Vec3(0, 0, 1.5 * kRadius), Vec3(0, 0, -kForce));
  Simulation sim(ParseConfig(text, "settle.toml"));
  Settled s;
  for (int k = 0; k < 200; ++k) {
    EXPECT_TRUE(sim.Step().ok) << sim.last_report().message;
    s.lowest = std::min(s.lowest, sim.state().bodies[0].center.z() - kRadius);
    s.worst_balance = std::max(s.worst_balance, WorstImbalance(sim));
    if (sim.last_report().contact_rounds > 1) ++s.touching_steps;
    if (k < 140) continue;
    s.mean_support += ContactReaction(sim, 0).z() / 60.0;
    s.mean_velocity += BodyVelocity(sim.model(), 0, sim.workspace().hydro_force)(2) / 60.0;
  }
  std::printf("contact.tolerance %.0e: lowest gap %.3e a; %d of 200 steps with a contact; over the "
              "last 60 the contact carries %.6e N against the load %.6e N (%.2e more), mean U_z "
              "%.2e m/s; worst imbalance %.1e of the load\n",
              contact_tolerance, s.lowest / kRadius, s.touching_steps, s.mean_support, kForce,
              s.mean_support / kForce - 1.0, s.mean_velocity, s.worst_balance);
  return s;
}

// At rest on the wall the sphere sinks by 3.5e-4 a per step before the contact acts. With
// contact.tolerance = 1e-4 below that, the contact acts at every step and holds it: U_z = 0 to
// round-off, the contact carrying the load up to what the surface lattice's asymmetry adds (the
// sphere slides and turns slowly, 2e-5 of the speed scale; measured). With 1e-3 the contact acts
// every third step (a sawtooth within the tolerance) and carries the load only on average, to a
// few per cent: the blobs' wall resistance differs along the sawtooth (printed, not asserted).
TEST(BodyContact, ASphereSettlingOnTheWallStopsThereAndTheContactCarriesItsLoad) {
  for (const double tolerance : {1e-3, 1e-4}) {
    const Settled s = Settle(tolerance);
    EXPECT_GE(s.lowest, -tolerance * kRadius);  // never deeper than the contact tolerance
    EXPECT_LT(s.lowest, 0.01 * kRadius);        // and it did reach the wall
    EXPECT_GT(s.touching_steps, 10);
    EXPECT_LT(s.worst_balance, 1e-6);           // the loads balance at every step
    EXPECT_LT(std::abs(s.mean_velocity), 1e-3 * 0.01);  // a thousandth of the free speed
    if (tolerance < 3.5e-4) {
      EXPECT_NEAR(s.mean_support, kForce, 1e-4 * kForce);
    }
  }
}

// Two spheres 1 cm apart (surface to surface), pushed towards each other at 1 cm/s each, for 2 s.
TEST(BodyContact, TwoFreeSpheresPushedTogetherDoNotInterpenetrate) {
  const std::string text = RunTable(2.0, 0.02) + Body(Vec3(-1.5 * kRadius, 0, 0), Vec3(kForce, 0, 0)) +
                           Body(Vec3(1.5 * kRadius, 0, 0), Vec3(-kForce, 0, 0));
  Simulation sim(ParseConfig(text, "squeeze.toml"));
  const double tolerance = sim.model().newton.contact_tolerance;
  double closest = 1e9, worst_balance = 0.0, worst_pair = 0.0;
  for (int k = 0; k < 100; ++k) {
    ASSERT_TRUE(sim.Step().ok) << sim.last_report().message;
    const auto& b = sim.state().bodies;
    closest = std::min(closest, (b[1].center - b[0].center).norm() - 2.0 * kRadius);
    worst_balance = std::max(worst_balance, WorstImbalance(sim));
    worst_pair = std::max(worst_pair, (ContactReaction(sim, 0) + ContactReaction(sim, 1)).norm() / kForce);
  }
  const Vec3 push = ContactReaction(sim, 0);
  const VecX& f = sim.workspace().hydro_force;
  const double approach = BodyVelocity(sim.model(), 0, f)(0) - BodyVelocity(sim.model(), 1, f)(0);
  std::printf("closest gap %.3e a; at the end the contact pushes body 1 by (%.6e, %.2e, %.2e) N "
              "against its load %.6e N, approach speed %.1e m/s; worst imbalance %.1e, contact "
              "reactions cancel to %.1e of the load\n",
              closest / kRadius, push.x(), push.y(), push.z(), kForce, approach, worst_balance,
              worst_pair);
  EXPECT_GE(closest, -2.0 * tolerance * kRadius);  // contact distance 2a, tolerance × 2a
  EXPECT_LT(closest, 0.01 * kRadius);
  // At rest along the line of centres; the pair slides and turns slowly (the two lattices are
  // not mirror images: 2e-7 m/s, 7e-6 rad/s measured), which the contact's x force shows at 2e-5.
  EXPECT_LT(std::abs(approach), 1e-9);
  EXPECT_NEAR(push.x(), -kForce, 1e-4 * kForce);
  EXPECT_LT(worst_balance, 1e-6);
  EXPECT_LT(worst_pair, 1e-12);
}

}  // namespace
}  // namespace stokesrods
