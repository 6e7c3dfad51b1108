// Cell bodies and a wall through the whole run path (configuration → model → steps → timeseries
// columns): a prescribed sphere's Stokes drag and torque, its no-slip surface in the flow, a rod
// dragged along by a passing sphere, and a rotating helix held beside a wall.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "common/checkpoint_resume.h"
#include "stokesrods/fluid/rigid_body.h"
#include "stokesrods/io/build_bodies.h"
#include "stokesrods/io/runner.h"
#include "stokesrods/io/simulation.h"
#include "stokesrods/rod/frames.h"
#include "stokesrods/sim/bodies.h"
#include "stokesrods/sim/observables.h"
#include "common/scratch_dir.h"

namespace stokesrods {
namespace {

constexpr double kMu = 1.0;
constexpr double kA = 0.02;  // sphere radius [m]

// The value of timeseries column `name` in the row of the simulation's current state.
double Column(const Simulation& sim, const std::string& name) {
  const std::vector<std::string> names = TimeseriesColumns(sim.model());
  const std::vector<double> row =
      CalcTimeseriesRow(sim.model(), sim.state(), sim.workspace(), sim.last_report());
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return row[i];
  ADD_FAILURE() << "no column " << name;
  return 0.0;
}

std::string SphereOnly(const std::string& motion, const std::string& solver) {
  return "[run]\nduration = 0.05\ntime_step = 0.01\nframes = false\n"
         "[fluid]\nviscosity = 1.0\nsolver = \"" + solver + "\"\n"
         "[[bodies]]\nradius = 0.02\ncenter = [0.1, 0.0, 0.0]\nmotion = \"prescribed\"\n" + motion;
}

// The sphere's own resistance (fluid/rigid_body.h) at the same surface: what the run must give.
Mat6 SphereResistance(int points) {
  return RigidResistance(SphereSurface(Vec3::Zero(), kA, points, kBodyBlobOverSpacing),
                         Vec3::Zero(), kMu);
}

TEST(BodiesValidation, APrescribedSphereFeelsStokesDragThroughTheRun) {
  const Vec3 u(1e-3, -2e-3, 0.5e-3);
  for (const char* solver : {"direct", "krylov"}) {
    Simulation sim(ParseConfig(SphereOnly("velocity = [1e-3, -2e-3, 0.5e-3]\n", solver), "sphere.toml"));
    for (int k = 0; k < 5; ++k) ASSERT_TRUE(sim.Step().ok);
    const Vec3 force(Column(sim, "body1_force_x"), Column(sim, "body1_force_y"),
                     Column(sim, "body1_force_z"));
    const Vec3 reference = -SphereResistance(400).topLeftCorner<3, 3>() * u;
    const Vec3 stokes = -6.0 * kPi * kMu * kA * u;
    std::printf("%s: F = (%.6e, %.6e, %.6e) N; resistance matrix: %.2e relative; Stokes: %.3f %%\n",
                solver, force.x(), force.y(), force.z(), (force - reference).norm() / reference.norm(),
                100.0 * (force.norm() / stokes.norm() - 1.0));
    // The same surface solved alone (to the solver's tolerance) and Stokes's law to the surface's
    // discretization error (1.4 % low at 400 points, tests/fluid/rigid_body_test.cc).
    EXPECT_LT((force - reference).norm(), (std::string(solver) == "direct" ? 1e-10 : 1e-5) * reference.norm());
    EXPECT_LT((force - stokes).norm(), 0.02 * stokes.norm());
    EXPECT_GT((force - stokes).norm(), 1e-3 * stokes.norm());  // the discretization error is there
    // The centre moved with U over the 5 steps.
    EXPECT_NEAR(Column(sim, "body1_x"), 0.1 + 0.05 * u.x(), 1e-15);
    EXPECT_NEAR(Column(sim, "body1_y"), 0.05 * u.y(), 1e-15);
  }
}

TEST(BodiesValidation, APrescribedRotatingSphereFeelsStokesTorque) {
  const Vec3 omega(0.0, 0.3, 0.1);
  Simulation sim(ParseConfig(SphereOnly("angular_velocity = [0.0, 0.3, 0.1]\n", "direct"), "sphere.toml"));
  for (int k = 0; k < 3; ++k) ASSERT_TRUE(sim.Step().ok);
  const Model& model = sim.model();
  // The torque about the centre at the geometry of the last step's solve (its start).
  BodyPose start = sim.state().bodies[0];  // the pose at the start of the last step
  start.rotation = Eigen::AngleAxisd((sim.state().time - 0.01) * omega.norm(), omega.normalized())
                       .toRotationMatrix();
  const Vec6 load = BodyHydroLoad(model, 0, start, sim.workspace().hydro_force);
  const Vec3 stokes = -8.0 * kPi * kMu * std::pow(kA, 3) * omega;
  std::printf("T = (%.6e, %.6e, %.6e) N m, Stokes %.3f %%; |F| = %.2e N\n", load(3), load(4), load(5),
              100.0 * (load.tail<3>().norm() / stokes.norm() - 1.0), load.head<3>().norm());
  EXPECT_LT((load.tail<3>() - stokes).norm(), 0.02 * stokes.norm());
  EXPECT_LT(load.head<3>().norm(), 0.02 * 6.0 * kPi * kMu * kA * kA * omega.norm());
  EXPECT_NEAR(Column(sim, "body1_omega_y"), 0.3, 0.0);
}

// A straight rod hanging beside a sphere that moves past it: the sphere drags the fluid and the
// rod's free end follows (+x), and the rod's presence raises the sphere's drag.
TEST(BodiesValidation, ASphereMovingPastARodDragsItAlong) {
  const std::string text =
      "[run]\nduration = 0.1\ntime_step = 0.01\nframes = false\n"
      "[fluid]\nsolver = \"direct\"\n"
      "[[rods]]\nshape = \"straight\"\nnodes = 21\naxis_length = 0.1\nradius = 1e-3\n"
      "young_modulus = 1e5\n"
      "[[bodies]]\nradius = 0.02\ncenter = [0.0, 0.03, -0.07]\nmotion = \"prescribed\"\n"
      "velocity = [0.01, 0.0, 0.0]\n";
  Simulation sim(ParseConfig(text, "pass.toml"));
  for (int k = 0; k < 10; ++k) ASSERT_TRUE(sim.Step().ok);
  const double tip_x = Column(sim, "rod1_end_x");
  const double drag = Column(sim, "body1_force_x");
  const double alone = -SphereResistance(400)(0, 0) * 0.01;
  std::printf("rod tip x = %.4e m; sphere drag %.6e N (alone %.6e N)\n", tip_x, drag, alone);
  EXPECT_GT(tip_x, 0.0);
  EXPECT_LT(drag, alone);  // more negative: the rod is in the way
}

// Two spheres: body 1 free, body 2 prescribed to move past it. The free sphere is carried along
// force- and torque-free; against the two spheres' 12 × 12 resistance computed directly from
// their surface Stokeslets (fluid/rigid_body.h): F1 = R11 V1 + R12 V2 = 0 gives V1.
class FreeSphere : public ::testing::TestWithParam<const char*> {};

TEST_P(FreeSphere, IsCarriedByAPrescribedOne) {
  const std::string text =
      "[run]\nduration = 0.02\ntime_step = 0.01\nframes = false\n[fluid]\nsolver = \"" +
      std::string(GetParam()) + "\"\n"
      "[[bodies]]\nradius = 0.02\ncenter = [0.0, 0.0, 0.0]\nmotion = \"free\"\nsurface_points = 200\n"
      "[[bodies]]\nradius = 0.015\ncenter = [0.02, 0.045, 0.01]\nmotion = \"prescribed\"\n"
      "velocity = [0.01, 0.0, 0.0]\nangular_velocity = [0.0, 0.0, 0.5]\nsurface_points = 200\n";
  Simulation sim(ParseConfig(text, "two.toml"));
  ASSERT_TRUE(sim.Step().ok);
  const VecX& f = sim.workspace().hydro_force;
  const Vec6 v1 = BodyVelocity(sim.model(), 0, f);
  // Reference, at the poses of the step's start (the initial ones).
  const BodySurface a = SphereSurface(Vec3(0, 0, 0), 0.02, 200, kBodyBlobOverSpacing);
  const BodySurface b = SphereSurface(Vec3(0.02, 0.045, 0.01), 0.015, 200, kBodyBlobOverSpacing);
  const MatX m = AssembleMobilityWithBodies(sim.model().fluid, {}, {a, b});
  MatX g = MatX::Zero(m.rows(), 12);
  for (int j = 0; j < 400; ++j) {
    const bool first = j < 200;
    const Vec3 x = first ? Vec3(a.points.col(j)) : Vec3(b.points.col(j - 200));
    const Vec3 r = x - (first ? Vec3(0, 0, 0) : Vec3(0.02, 0.045, 0.01));
    for (int c = 0; c < 3; ++c) {
      g.block<3, 1>(3 * j, (first ? 0 : 6) + c) = Vec3::Unit(c);
      g.block<3, 1>(3 * j, (first ? 0 : 6) + 3 + c) = Vec3::Unit(c).cross(r);
    }
  }
  const MatX resistance = g.transpose() * m.partialPivLu().solve(g);
  Vec6 v2;
  v2 << 0.01, 0.0, 0.0, 0.0, 0.0, 0.5;
  const Vec6 reference = -resistance.topLeftCorner<6, 6>().partialPivLu().solve(
      resistance.topRightCorner<6, 6>() * v2);
  const Vec6 load1 = BodyHydroLoad(sim.model(), 0, BodyPose{}, f);
  const Vec6 load2 = BodyHydroLoad(sim.model(), 1, BodyPose{Vec3(0.02, 0.045, 0.01), Mat3::Identity()}, f);
  std::printf("free sphere: U = (%.5e, %.5e, %.5e) m/s, Omega = (%.5e, %.5e, %.5e) rad/s; "
              "reference differs by %.1e; its load %.1e N, %.1e N m (the other's %.1e N)\n",
              v1(0), v1(1), v1(2), v1(3), v1(4), v1(5), (v1 - reference).norm() / reference.norm(),
              load1.head<3>().norm(), load1.tail<3>().norm(), load2.head<3>().norm());
  // Direct: to round-off; Krylov: to its tolerance (1e-6 relative, the Newton test on top).
  const double tolerance = std::string(GetParam()) == "direct" ? 1e-10 : 1e-5;
  EXPECT_LT((v1 - reference).norm(), tolerance * reference.norm());
  EXPECT_GT(v1(0), 0.0);  // carried along
  // Force and torque balance of the free body.
  EXPECT_LT(load1.head<3>().norm(), tolerance * load2.head<3>().norm());
  EXPECT_LT(load1.tail<3>().norm(), tolerance * load2.head<3>().norm() * 0.02);
  // Its centre moved with U over the step; the columns report it.
  EXPECT_NEAR(Column(sim, "body1_x"), 0.01 * v1(0), 1e-15);
  EXPECT_NEAR(Column(sim, "body1_omega_z"), v1(5), 1e-15);
}

// A helix on a prescribed body that translates and turns about a tilted axis, its motor turning
// at ω relative to the body: the clamped nodes stay fixed in the body's frame and the first
// edge's material frame is the body's rotation of the initial one, turned by the motor's angle
// about the edge (SPEC: "the rod's clamped nodes are fixed in body K's frame; the motor turns the
// first twist angle at ω relative to that body").
TEST(BodiesValidation, AClampOnAMovingBodyMovesWithIt) {
  const std::string text =
      "[run]\nduration = 0.3\ntime_step = 0.01\nframes = false\n[fluid]\nsolver = \"direct\"\n"
      "[[bodies]]\nradius = 0.02\ncenter = [0.0, 0.0, 0.02]\nmotion = \"prescribed\"\n"
      "velocity = [0.002, -0.001, 0.003]\nangular_velocity = [0.3, -0.2, 0.4]\nsurface_points = 100\n"
      "[[rods]]\nnodes = 33\naxis_length = 0.1\nhelix_radius = 0.008\nbody = 1\nomega = 2.0\n";
  Simulation sim(ParseConfig(text, "moving.toml"));
  const Model& model = sim.model();
  const RodModel& rod = model.rods[0];
  const Vec3 c0(0.0, 0.0, 0.02);
  const Vec3 x0 = sim.state().q.segment<3>(NodeDof(0)), x1 = sim.state().q.segment<3>(NodeDof(1));
  Vec3 m1_start, m2_start;
  MaterialFrame(sim.state().rods[0].frames[0], sim.state().q(TwistDof(0)), &m1_start, &m2_start);
  const int steps = 30;
  for (int k = 0; k < steps; ++k) ASSERT_TRUE(sim.Step().ok) << sim.last_report().message;
  const double t = sim.state().time;
  const Vec3 omega(0.3, -0.2, 0.4);
  const Mat3 turn = Eigen::AngleAxisd(t * omega.norm(), omega.normalized()).toRotationMatrix();
  const Vec3 c = c0 + t * Vec3(0.002, -0.001, 0.003);
  EXPECT_LT((sim.state().q.segment<3>(NodeDof(0)) - (c + turn * (x0 - c0))).norm(), 1e-14);
  EXPECT_LT((sim.state().q.segment<3>(NodeDof(1)) - (c + turn * (x1 - c0))).norm(), 1e-14);
  Vec3 m1, m2;
  MaterialFrame(sim.state().rods[0].frames[0], sim.state().q(TwistDof(0)), &m1, &m2);
  const Vec3 edge = (sim.state().q.segment<3>(NodeDof(1)) - sim.state().q.segment<3>(NodeDof(0))).normalized();
  const Vec3 expected = Eigen::AngleAxisd(steps * 0.01 * rod.twist_rate, edge) * (turn * m1_start);
  std::printf("material frame of the clamped edge after %.2f s: off by %.1e\n", t, (m1 - expected).norm());
  EXPECT_LT((m1 - expected).norm(), 1e-10);
  EXPECT_GT(std::abs(steps * 0.01 * rod.twist_rate), 0.5);  // the motor did turn
}

INSTANTIATE_TEST_SUITE_P(Solvers, FreeSphere, ::testing::Values("direct", "krylov"));

constexpr char kPass[] =
    "[run]\nduration = 0.1\ntime_step = 0.01\noutput_interval = 0.05\ncheckpoint_interval = 0.05\n"
    "[[rods]]\nshape = \"straight\"\nnodes = 21\naxis_length = 0.1\nradius = 1e-3\n"
    "young_modulus = 1e5\n"
    "[[bodies]]\nradius = 0.02\ncenter = [0.0, 0.03, -0.07]\nmotion = \"prescribed\"\n"
    "velocity = [0.01, 0.0, 0.0]\nangular_velocity = [0.0, 0.0, 2.0]\nsurface_points = 100\n";

// A checkpoint holds the drag of the bodies' points too: continuing from it is bit-identical.
TEST(BodiesValidation, ACheckpointResumesBitIdentically) {
  const ResumedPair p = RunAndResume(kPass, 4, 4);
  const Simulation &a = *p.uninterrupted, &b = *p.resumed;
  EXPECT_EQ(a.state().q, b.state().q);
  EXPECT_EQ(a.workspace().hydro_force, b.workspace().hydro_force);
  EXPECT_EQ(Column(a, "body1_force_x"), Column(b, "body1_force_x"));
}

// The run writes the bodies' frames beside the rods' (bodies.pvd, frames/bodies_NNNNN.vtp).
TEST(BodiesValidation, TheRunWritesBodyFrames) {
  const std::string dir = testing::ScratchPath("stokesrods_bodies_frames").string();
  Config config = ParseConfig(kPass, "pass.toml");
  config.run.output = dir;
  const RunResult result = RunCase(config);
  ASSERT_EQ(result.status, RunStatus::kCompleted) << result.message;
  std::stringstream pvd, vtp;
  pvd << std::ifstream(dir + "/bodies.pvd").rdbuf();
  vtp << std::ifstream(dir + "/frames/bodies_00002.vtp").rdbuf();
  std::filesystem::remove_all(dir);
  EXPECT_NE(pvd.str().find("frames/bodies_00002.vtp"), std::string::npos);
  EXPECT_NE(vtp.str().find("NumberOfPoints=\"100\""), std::string::npos);
  EXPECT_NE(vtp.str().find("Name=\"hydrodynamic_force\""), std::string::npos);
}

}  // namespace
}  // namespace stokesrods
