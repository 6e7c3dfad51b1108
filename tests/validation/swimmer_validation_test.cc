// The free-swimming cell (issue 11): a helix clamped to a free sphere, its motor turning it against
// the sphere; sphere and helix together force- and torque-free (sim/clamp_border.h).
//   - every step balances momentum: the fluid's total force and torque on sphere and helix equal
//     the helix's inertia, to the Newton tolerance;
//   - a stiff, nearly rigid helix swims as the rigid swimmer of the same surfaces
//     (RigidSwimmerVelocity, a 6 × 6 resistance calculation independent of the time stepping);
//   - a checkpoint resumes bit-identically.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "common/checkpoint_resume.h"
#include "stokesrods/fluid/rigid_body.h"
#include "stokesrods/io/build_bodies.h"
#include "stokesrods/io/simulation.h"
#include "stokesrods/sim/bodies.h"
#include "stokesrods/sim/hydro_coupling.h"

namespace stokesrods {
namespace {

// A sphere of radius 2 cm holding a 2-turn helix (l0 = 0.1 m, R = 8 mm) at its lowest point.
// `density` [kg/m³]: the rod's inertia (the rigid swimmer has none).
std::string Swimmer(const std::string& solver, double young_modulus, double omega, double h,
                    int steps, double density = 1000.0, const std::string& integrator = "euler") {
  return "[run]\nintegrator = \"" + integrator + "\"\nduration = " + std::to_string(h * steps) + "\ntime_step = " + std::to_string(h) +
         "\nframes = false\noutput_interval = " + std::to_string(h * steps) +
         "\ncheckpoint_interval = " + std::to_string(h * steps) +
         "\n[fluid]\nsolver = \"" + solver + "\"\n"
         "[[bodies]]\nradius = 0.02\ncenter = [0.0, 0.0, 0.02]\nmotion = \"free\"\n"
         "surface_points = 100\n"
         "[[rods]]\nnodes = 25\naxis_length = 0.1\npitch = 0.05\nhelix_radius = 0.008\nbody = 1\n"
         "density = " + std::to_string(density) + "\nyoung_modulus = " + std::to_string(young_modulus) +
         "\nomega = " + std::to_string(omega) + "\n";
}

struct Balance {
  double force = 0, torque = 0;       ///< |Σ fluid − inertia| [N], [N·m]
  double body_force = 0;              ///< |fluid force on the body| [N], the scale
  double tolerance = 0;               ///< what the Newton residual may leave per entry [N]
};

// The momentum balance of the last step, solved in implicit Euler's form (sim/integrator.h: q̃, ṽ
// and h_e of the step in ws.step_start and ws.body_step; implicit Euler: q_k, q̇_k, h; BDF2: the
// blends and 2h/3): the body's fluid load at the pose where 𝕄 was taken, the rods' inertia
// M(q − q̃ − h_e ṽ)/h_e² at the step's end, torques about that pose's centre.
Balance MeasureBalance(const Simulation& sim) {
  const Model& model = sim.model();
  const State& now = sim.state();
  const Workspace& ws = sim.workspace();
  const VecX& f = ws.hydro_force;
  const BodyPose& pose = ws.body_step.geometry[0];
  const double h = ws.body_step.he;
  const Vec3 c = pose.center;
  const Vec6 body = BodyHydroLoad(model, 0, pose, f);  // torque about c
  Vec3 force = body.head<3>(), torque = body.tail<3>();
  const RodModel& rod = model.rods[0];
  const VecX accel =
      rod.mass.cwiseProduct(now.q - ws.step_start.q - h * ws.step_start.velocity) / (h * h);
  for (int i = 0; i < rod.num_nodes(); ++i) {
    const Vec3 x = now.q.segment<3>(NodeDof(i)) - c;
    const Vec3 net = f.segment<3>(3 * i) - accel.segment<3>(NodeDof(i));
    force += net;
    torque += x.cross(net);
    if (i + 1 < rod.num_nodes())  // the twist's inertia, a moment about the edge
      torque -= accel(TwistDof(i)) * (now.q.segment<3>(NodeDof(i + 1)) - now.q.segment<3>(NodeDof(i))).normalized();
  }
  Balance b;
  b.force = force.norm();
  b.torque = torque.norm();
  b.body_force = body.head<3>().norm();
  b.tolerance = model.newton.tolerance *
                std::max(model.force_scale, sim.workspace().force.cwiseAbs().maxCoeff());
  return b;
}

// (fluid.solver, run.integrator)
class FreeSwimmer : public ::testing::TestWithParam<std::pair<const char*, const char*>> {};

// Each step's Newton solve leaves at most `tolerance` per residual entry (rods' DOFs, the body's
// force and torque / a); summed over the 3N + 3 force entries, |Σ F| ≤ 3(N + 1) tolerance, and
// the torques' arms are at most the helix's extent from the centre (0.15 m) — or the entries
// would not have converged.
TEST_P(FreeSwimmer, BalancesForceAndTorqueAtEveryStep) {
  const auto [solver, integrator] = GetParam();
  Simulation sim(
      ParseConfig(Swimmer(solver, 1e7, 4.0, 0.01, 10, 1000.0, integrator), "swim.toml"));
  const int n = sim.model().rods[0].num_nodes();
  double worst_force = 0, worst_torque = 0, scale = 0, tolerance = 0;
  for (int k = 0; k < 10; ++k) {
    ASSERT_TRUE(sim.Step().ok) << sim.last_report().message;
    const Balance b = MeasureBalance(sim);
    worst_force = std::max(worst_force, b.force / b.tolerance);
    worst_torque = std::max(worst_torque, b.torque / (b.tolerance * 0.15));
    scale = std::max(scale, b.body_force);
    tolerance = b.tolerance;
  }
  const Vec6 v = BodyVelocity(sim.model(), 0, sim.workspace().hydro_force);
  std::printf("%s, %s: imbalance ≤ %.2e (force) / %.2e (torque) Newton tolerances (%.1e N); body's "
              "fluid force %.2e N; U = (%.3e, %.3e, %.3e) m/s, Omega_z = %.3e rad/s\n",
              solver, integrator, worst_force, worst_torque, tolerance, scale, v(0), v(1), v(2), v(5));
  EXPECT_LT(worst_force, 3.0 * (n + 1));
  EXPECT_LT(worst_torque, 3.0 * (n + 1));
  EXPECT_GT(scale, 1e3 * tolerance);  // the body does carry the rod's load
  EXPECT_LT(v(5) * sim.model().rods[0].omega, 0.0) << "the body counter-rotates";
}

INSTANTIATE_TEST_SUITE_P(SolversAndIntegrators, FreeSwimmer,
                         ::testing::Values(std::make_pair("direct", "euler"),
                                           std::make_pair("krylov", "euler"),
                                           std::make_pair("direct", "bdf2"),
                                           std::make_pair("krylov", "bdf2")));

// Δ = V − V_rigid of the last step: V of the step against the rigid swimmer at the geometry
// `at` (the sphere's surface at its pose, the helix at its nodes, the motor about the first edge
// through the clamp at the rod's θ0 rate).
Vec6 RigidSwimmerError(const Simulation& sim, const State& at, Vec6* reference) {
  const Model& model = sim.model();
  std::vector<Matrix3X> positions = {RodPositions(model, 0, at.q)};
  const BodySurface body = BodySurfaces(model, at.bodies)[0];
  const Vec3 x0 = positions[0].col(0), axis = (positions[0].col(1) - x0).normalized();
  *reference = RigidSwimmerVelocity(model.fluid, MakeHydroRods(model, positions), body,
                                    at.bodies[0].center, axis, x0, model.rods[0].twist_rate);
  return BodyVelocity(model, 0, sim.workspace().hydro_force) - *reference;
}

// Runs the stiff swimmer to t = 0.4 s (a steady state: the twist and bending relax within
// milliseconds at this stiffness) and returns Δ of its last step. The rod's density is 1 kg/m³:
// at 1000 its centripetal inertia ρAω²R is 1.6e-3 of the drag ζωR and shifts V by 1e-3 of |U|
// (measured: Δ then tends to that, not to 0, as h → 0); at 1 it is 1.6e-6. Implicit Euler's V
// is that of the step's start geometry (where 𝕄 is taken); BDF2's V is the velocity at the
// step's end, compared with the rigid swimmer there.
Vec6 StiffSwimmerError(double young_modulus, double h, Vec6* reference,
                       const std::string& integrator = "euler") {
  const int steps = static_cast<int>(std::lround(0.4 / h));
  Simulation sim(ParseConfig(Swimmer("direct", young_modulus, 1.0, h, steps, 1.0, integrator),
                             "rigid.toml"));
  State before;
  for (int k = 0; k < steps; ++k) {
    before = sim.state();
    EXPECT_TRUE(sim.Step().ok) << sim.last_report().message;
  }
  return RigidSwimmerError(sim, integrator == "bdf2" ? sim.state() : before, reference);
}

// Implicit Euler moves the helix along chords: its node velocities differ from the rigid
// rotation's by O(hω) (a radial part hω/2 of ω × r), so Δ is first order in h. Halving h must
// halve Δ, and the extrapolation 2Δ(h/2) − Δ(h) leaves the O(h²) and the helix's elastic
// deflection (μωL⁴/EI = 1.3e-2; E × 10 changed nothing measurable): a tenth of Δ(h) at most.
// Δ(h) itself is below hω|V| (the O(hω) term with a coefficient of order one).
TEST(FreeSwimmerRigid, SwimsAsTheRigidSwimmerOfTheSameSurfaces) {
  Vec6 ref_h, ref_half;
  const Vec6 coarse = StiffSwimmerError(1e10, 0.02, &ref_h);
  const Vec6 fine = StiffSwimmerError(1e10, 0.01, &ref_half);
  const Vec6 extrapolated = 2.0 * fine - coarse;
  std::printf("rigid swimmer: U_z = %.5e m/s, Omega_z = %.5e rad/s; relative error of U, Omega: "
              "h = 0.02 s: %.2e, %.2e; h = 0.01 s: %.2e, %.2e; extrapolated %.2e, %.2e\n",
              ref_half(2), ref_half(5), coarse.head<3>().norm() / ref_h.head<3>().norm(),
              coarse.tail<3>().norm() / ref_h.tail<3>().norm(),
              fine.head<3>().norm() / ref_half.head<3>().norm(),
              fine.tail<3>().norm() / ref_half.tail<3>().norm(),
              extrapolated.head<3>().norm() / ref_half.head<3>().norm(),
              extrapolated.tail<3>().norm() / ref_half.tail<3>().norm());
  for (int part = 0; part < 2; ++part) {
    const double e_h = coarse.segment<3>(3 * part).norm(), e_half = fine.segment<3>(3 * part).norm();
    EXPECT_GT(e_half, 0.35 * e_h);
    EXPECT_LT(e_half, 0.65 * e_h);
    EXPECT_LT(extrapolated.segment<3>(3 * part).norm(), 0.1 * e_h);
    EXPECT_LT(e_h, 0.02 * ref_h.segment<3>(3 * part).norm());  // hω = 0.02
  }
}

// BDF2 with the free body (sim/bodies.h: BodyStep): Δ must fall as h², the ratio of successive
// errors 4 at halved h; measured at h = 20, 10, 5 ms.
TEST(FreeSwimmerRigid, Bdf2ConvergesToTheRigidSwimmerAtSecondOrder) {
  Vec6 ref[3];
  double error[3][2];
  const double hs[3] = {0.02, 0.01, 0.005};
  for (int i = 0; i < 3; ++i) {
    const Vec6 d = StiffSwimmerError(1e10, hs[i], &ref[i], "bdf2");
    for (int part = 0; part < 2; ++part)
      error[i][part] = d.segment<3>(3 * part).norm() / ref[i].segment<3>(3 * part).norm();
    std::printf("BDF2 h = %.3f s: relative error of U %.3e, of Omega %.3e\n", hs[i], error[i][0],
                error[i][1]);
  }
  for (int part = 0; part < 2; ++part) {
    const double p1 = std::log2(error[0][part] / error[1][part]);
    const double p2 = std::log2(error[1][part] / error[2][part]);
    std::printf("observed orders of %s: %.2f, %.2f\n", part == 0 ? "U" : "Omega", p1, p2);
    EXPECT_GT(p1, 1.6);  // the error ratio 4 ± 1 at each halving
    EXPECT_LT(p1, 2.3);
    EXPECT_GT(p2, 1.6);
    EXPECT_LT(p2, 2.3);
  }
}

// A checkpoint of a swimming cell holds the body's pose and V, and for BDF2 its previous pose:
// the resumed run is bit-identical.
TEST(FreeSwimmerRigid, ACheckpointResumesBitIdentically) {
  for (const char* integrator : {"euler", "bdf2"}) {
    SCOPED_TRACE(integrator);
    const ResumedPair p = RunAndResume(Swimmer("krylov", 1e7, 4.0, 0.01, 8, 1000.0, integrator), 4, 4);
    const Simulation &a = *p.uninterrupted, &b = *p.resumed;
    EXPECT_EQ(a.state().q, b.state().q);
    EXPECT_EQ(a.state().bodies[0].center, b.state().bodies[0].center);
    EXPECT_EQ(a.state().bodies[0].rotation, b.state().bodies[0].rotation);
    EXPECT_EQ(a.workspace().hydro_force, b.workspace().hydro_force);
  }
}

}  // namespace
}  // namespace stokesrods
