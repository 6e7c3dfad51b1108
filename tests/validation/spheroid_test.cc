// A spheroidal cell body (`shape = "spheroid"`, SPEC "Additions"): a prolate spheroid with its axis
// tilted, prescribed to translate along and across its axis, feels Oberbeck's Stokes drag (closed
// forms as given by Chwang & Wu 1975), to the surface discretization's error; and a spheroid asks
// for contact.enabled = false and takes no rods (contact and clamps assume spheres).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "stokesrods/io/simulation.h"
#include "stokesrods/sim/bodies.h"

namespace stokesrods {
namespace {

constexpr double kA = 0.02, kB = 0.01;  // polar and equatorial semi-axes [m]
constexpr int kPoints = 800;

// The fluid's force on the spheroid in its first step at velocity `u` [N].
Vec3 DragForce(const Vec3& u) {
  const std::string text =
      "[run]\nduration = 0.01\ntime_step = 0.01\nframes = false\n[fluid]\nsolver = \"direct\"\n"
      "[contact]\nenabled = false\n[[bodies]]\nshape = \"spheroid\"\nradius = " +
      std::to_string(kB) + "\nhalf_length = " + std::to_string(kA) +
      "\naxis = [1.0, 0.0, 1.0]\nmotion = \"prescribed\"\nsurface_points = " +
      std::to_string(kPoints) + "\nvelocity = [" + std::to_string(u.x()) + ", " +
      std::to_string(u.y()) + ", " + std::to_string(u.z()) + "]\n";
  Simulation sim(ParseConfig(text, "spheroid.toml"));
  EXPECT_TRUE(sim.Step().ok) << sim.last_report().message;
  return BodyHydroLoad(sim.model(), 0, sim.workspace().body_step.geometry[0],
                       sim.workspace().hydro_force).head<3>();
}

// e = √(1 − b²/a²), L = ln((1 + e)/(1 − e)); along the axis F = 16πμ a e³ U / ((1 + e²) L − 2e),
// across it F = 32πμ a e³ U / (2e + (3e² − 1) L). The error bound is that of the fluid test
// (tests/fluid/rigid_body_test.cc, the same surfaces): 0.12 d/b, d = √(area/N).
TEST(Spheroid, ProlateSpheroidFeelsOberbecksDragAlongAndAcrossItsTiltedAxis) {
  const double e = std::sqrt(1.0 - kB * kB / (kA * kA)), log_term = std::log((1.0 + e) / (1.0 - e));
  const double mu = 1.0, speed = 0.01;
  const double axial = 16.0 * kPi * mu * kA * std::pow(e, 3) / ((1.0 + e * e) * log_term - 2.0 * e);
  const double transverse =
      32.0 * kPi * mu * kA * std::pow(e, 3) / (2.0 * e + (3.0 * e * e - 1.0) * log_term);
  const double area = 2.0 * kPi * kB * kB * (1.0 + kA / (kB * e) * std::asin(e));
  const double bound = 0.12 * std::sqrt(area / kPoints) / kB;
  const Vec3 axis = Vec3(1.0, 0.0, 1.0).normalized(), across = Vec3::UnitY();
  const Vec3 along_force = DragForce(speed * axis), across_force = DragForce(speed * across);
  const double along_error = -along_force.dot(axis) / (axial * speed) - 1.0;
  const double across_error = -across_force.dot(across) / (transverse * speed) - 1.0;
  std::printf("spheroid a/b = 2, N = %d: drag along the axis %.4e N (closed form %.4e, %+.2e), "
              "across %.4e N (%.4e, %+.2e); bound %.2e; off-direction parts %.1e, %.1e\n",
              kPoints, -along_force.dot(axis), axial * speed, along_error,
              -across_force.dot(across), transverse * speed, across_error, bound,
              (along_force - along_force.dot(axis) * axis).norm() / along_force.norm(),
              (across_force - across_force.dot(across) * across).norm() / across_force.norm());
  EXPECT_LT(std::abs(along_error), bound);
  EXPECT_LT(std::abs(across_error), bound);
  // Along a principal axis the drag is parallel to the motion (to the discretization).
  EXPECT_LT((along_force - along_force.dot(axis) * axis).norm(), bound * along_force.norm());
}

}  // namespace
}  // namespace stokesrods
