// The elastic core against closed forms: Euler–Bernoulli cantilever, the elastica, torsion,
// Euler buckling, and the unloaded rest helix.
//
// Where the clamp is: with nodes 0 and 1 (and θ0) held, the first edge is inside the wall and the
// bending energy of node 1 covers the Voronoi cell that starts at the middle of edge 0. The
// discrete cantilever deflects as a continuous one clamped there: the tip deflection of the
// discrete beam is P Δl³ Σ_{k=1}^{n} k² / EI with n = N − 2, = P (L − Δl/2)³/(3EI) (1 + O(n⁻²)).
// So the tests build rods whose first edge straddles the wall: x0 = +Δl/2, x1 = −Δl/2 below it,
// and the beam of length L runs from z = 0 to z = −L.
#include <gtest/gtest.h>

#include <cmath>

#include <fmt/format.h>

#include "common/model_from_toml.h"
#include "stokesrods/sim/elastic_assembly.h"
#include "stokesrods/sim/integrator.h"

namespace stokesrods {
namespace {

using testing::ModelFromToml;

constexpr double kE = 10e6;                          // Pa
constexpr double kR0 = 1e-3;                         // m
constexpr double kEI = kE * kPi * 1e-12 / 4.0;       // N m²
constexpr double kGJ = kE / 3.0 * kPi * 1e-12 / 2.0; // ν = 0.5

// A straight rod along −z of beam length L below the wall at z = 0, N nodes, first edge
// straddling the wall; `extra` adds TOML lines to the [[rods]] table.
std::string ClampedRod(int n, double length, const std::string& extra, const std::string& run,
                       const std::string& solver = "") {
  const double dl = length / (n - 1.5);  // x0 at +dl/2, x_{N-1} at −L
  std::string points;
  for (int i = 0; i < n; ++i) points += fmt::format("[0.0, 0.0, {:.17g}], ", 0.5 * dl - i * dl);
  return fmt::format(R"(
[run]
{}
[fluid]
model = "none"
[contact]
enabled = false
[solver]
newton_tolerance = 1e-10
{}
[[rods]]
shape = "points"
points = [{}]
radius = {}
young_modulus = {}
poisson_ratio = 0.5
clamped_nodes = 2
{}
)",
                     run, solver, points, kR0, kE, extra);
}

Vec3 Tip(const Model& model, const State& state) {
  return state.q.segment<3>(NodeDof(model.rods[0].num_nodes() - 1));
}

// Static tip displacement of a clamped rod under a tip load.
Vec3 StaticTip(int n, double length, const Vec3& load) {
  const std::string loads = fmt::format("loads = [{{ node = {}, force = [{:.17g}, 0.0, {:.17g}] }}]",
                                        n - 1, load.x(), load.z());
  const Model model = ModelFromToml(ClampedRod(n, length, loads, "mode = \"static\""));
  State state = MakeRestState(model);
  Workspace ws(model);
  const StepReport report = SolveStatic(model, &state, &ws);
  EXPECT_TRUE(report.ok) << report.message;
  return Tip(model, state);
}

TEST(Cantilever, SmallTipLoadMatchesEulerBernoulli) {
  const double length = 0.2, load = 1e-6;  // deflection/L ≈ 0.2 %: linear regime
  const double expected = load * std::pow(length, 3) / (3.0 * kEI);
  for (int n : {31, 61}) {
    const Vec3 tip = StaticTip(n, length, Vec3(load, 0, 0));
    EXPECT_NEAR(tip.x() / expected, 1.0, 0.01) << "N = " << n;
  }
}

TEST(Cantilever, ConvergesAtSecondOrderInN) {
  const double length = 0.2, load = 1e-6;
  const double expected = load * std::pow(length, 3) / (3.0 * kEI);
  double previous = 0.0;
  for (int n : {11, 21, 41, 81}) {
    const double error = std::abs(StaticTip(n, length, Vec3(load, 0, 0)).x() / expected - 1.0);
    std::printf("cantilever N = %d: relative error of the tip deflection %.3e\n", n, error);
    if (previous > 0.0) {
      EXPECT_GT(previous / error, 3.0) << "N = " << n;  // ≈ 4 for O(N⁻²)
    }
    previous = error;
  }
}

// The elastica of a cantilever under a dead tip load P x̂ (rod along u = −z, θ measured from it
// towards x̂): EI θ'' = −P cos θ, θ(0) = 0, θ'(L) = 0; x = ∫ sin θ, u = ∫ cos θ. Solved by
// shooting on θ'(0) with classical RK4 (20000 steps) and bisection: independent of the rod code.
Vec2 ElasticaTip(double alpha /* P L² / EI */, double length) {
  const int steps = 20000;
  const double ds = 1.0 / steps;  // in s / L
  auto integrate = [&](double kappa0, Vec2* tip) {
    // y = (θ, θ', w, u) in units of L.
    Eigen::Vector4d y(0.0, kappa0, 0.0, 0.0);
    auto f = [&](const Eigen::Vector4d& s) {
      return Eigen::Vector4d(s(1), -alpha * std::cos(s(0)), std::sin(s(0)), std::cos(s(0)));
    };
    for (int i = 0; i < steps; ++i) {
      const Eigen::Vector4d k1 = f(y), k2 = f(y + 0.5 * ds * k1), k3 = f(y + 0.5 * ds * k2),
                            k4 = f(y + ds * k3);
      y += ds / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4);
    }
    if (tip) *tip = Vec2(y(2), y(3)) * length;
    return y(1);  // θ'(L): zero at the solution
  };
  double lo = 0.0, hi = alpha;  // θ'(0) ∈ (0, α]: θ'(L) > 0 at the top? bisect on the sign
  const double f_lo = integrate(lo, nullptr);
  for (int it = 0; it < 200; ++it) {
    const double mid = 0.5 * (lo + hi);
    if ((integrate(mid, nullptr) > 0.0) == (f_lo > 0.0)) lo = mid; else hi = mid;
  }
  Vec2 tip;
  integrate(0.5 * (lo + hi), &tip);
  return tip;
}

TEST(Cantilever, LargeDeflectionMatchesTheElastica) {
  const double length = 0.2;
  for (double alpha : {2.0, 5.0}) {  // tip rotations of about 0.6 and 1.0 rad
    const Vec2 reference = ElasticaTip(alpha, length);  // (x, depth below the wall)
    const Vec3 tip = StaticTip(61, length, Vec3(alpha * kEI / (length * length), 0, 0));
    std::printf("elastica alpha = %.1f: reference (%.6f, %.6f), rod (%.6f, %.6f)\n", alpha,
                reference(0), reference(1), tip.x(), -tip.z());
    EXPECT_NEAR(tip.x(), reference(0), 0.01 * length) << alpha;
    EXPECT_NEAR(-tip.z(), reference(1), 0.01 * length) << alpha;
    EXPECT_GT(reference(0), 0.3 * length);  // the case is really nonlinear
  }
}

TEST(Torsion, ReactionTorqueIsGJPhiOverL) {
  // θ lives on edges: holding θ0 = 0 and θ_{N−2} = Φ twists the length between the middles of
  // the first and the last edge, (N − 2) Δl.
  const int n = 41;
  const double length = 0.2;
  for (double phi : {0.1, 1.0}) {
    Model model = ModelFromToml(ClampedRod(n, length, "", "mode = \"static\""));
    RodModel& rod = model.rods[0];
    rod.fixed_dofs.push_back(TwistDof(n - 2));
    State state = MakeRestState(model);
    state.q(TwistDof(n - 2)) = phi;
    Workspace ws(model);
    const StepReport report = SolveStatic(model, &state, &ws);
    ASSERT_TRUE(report.ok) << report.message;
    const double dl = rod.rest_edge_length(0);
    const double twisted = (n - 2) * dl;
    const ClampLoad clamp = CalcClampLoad(model, state, ws, 0);
    // The elastic moment on θ0 is +GJΦ/ℓ about t⁰ = −ẑ: about +ẑ it is −GJΦ/ℓ.
    EXPECT_NEAR(clamp.torque_z / (-kGJ * phi / twisted), 1.0, 0.01) << phi;
    EXPECT_LT((Tip(model, state) - Vec3(0, 0, -length)).norm(), 1e-9);  // stays straight
  }
}

// Clamped–free column under a compressive dead load P (+ẑ, pushing the tip towards the clamp)
// with a lateral imperfection of 1e-4 P, released from straight with viscous damping: below
// P_cr = π² EI / (4 L²) it settles nearly straight, with the imperfection's deflection amplified
// by about 1/(1 − P/P_cr); above it the deflection grows until the column is buckled.
// (A static solve alone cannot tell: above P_cr Newton may land on the unstable straight branch.)
TEST(EulerBuckling, FivePercentAboveBucklesFivePercentBelowDoesNot) {
  const double length = 0.2;
  const double critical = kPi * kPi * kEI / (4.0 * length * length);
  const int n = 41;
  for (double ratio : {0.95, 1.05}) {
    const double p = ratio * critical;
    const std::string loads = fmt::format(
        "loads = [{{ node = {}, force = [{:.17g}, 0.0, {:.17g}] }}]", n - 1, 1e-4 * p, p);
    const Model model = ModelFromToml(ClampedRod(
        n, length, loads, "duration = 200.0\ntime_step = 0.02", "damping = 0.01"));
    State state = MakeRestState(model);
    Workspace ws(model);
    for (int k = 0; k < 10000; ++k) ASSERT_TRUE(Step(model, 0.02, &state, &ws).ok) << k;
    const double deflection = Tip(model, state).x() / length;
    std::printf("column P/Pcr = %.2f: lateral tip deflection after 200 s %.4e L\n", ratio, deflection);
    if (ratio < 1.0) {
      const double amplified = 1e-4 * p * std::pow(length, 2) / (3.0 * kEI) / (1.0 - ratio);
      EXPECT_NEAR(deflection / amplified, 1.0, 0.05);
    } else {
      EXPECT_GT(deflection, 0.1);
    }
  }
}

// A straight rod hanging under its own weight: the edge below node j carries the weight of the
// nodes below it, so with lumped masses the tip drops by exactly ρ g L'²/(2E), L' = (N − 2)Δl the
// length below the clamped first edge; the clamp load (eq. 25) is the total weight.
TEST(Gravity, HangingRodStretchesByRhoGLSquaredOver2E) {
  const Model model = ModelFromToml(R"(
[run]
mode = "static"
[fluid]
model = "none"
[contact]
enabled = false
[gravity]
acceleration = [0.0, 0.0, -9.81]
[solver]
newton_tolerance = 1e-12
[[rods]]
shape = "straight"
nodes = 41
axis_length = 0.2
young_modulus = 1e5
)");
  State state = MakeRestState(model);
  Workspace ws(model);
  ASSERT_TRUE(SolveStatic(model, &state, &ws).ok);
  const RodModel& rod = model.rods[0];
  const double below = (rod.num_nodes() - 2) * rod.rest_edge_length(0);
  const double expected = 1000.0 * 9.81 * below * below / (2.0 * 1e5);
  const double drop = -0.2 - Tip(model, state).z();
  EXPECT_NEAR(drop / expected, 1.0, 1e-3) << drop << " vs " << expected;
  double weight = 0.0;
  for (int i = 0; i < rod.num_nodes(); ++i) weight += rod.mass(NodeDof(i)) * 9.81;
  const ClampLoad clamp = CalcClampLoad(model, state, ws, 0);
  EXPECT_NEAR(clamp.force.z() / -weight, 1.0, 1e-9);
  EXPECT_NEAR(clamp.force.head<2>().norm(), 0.0, 1e-12 * weight);
}

constexpr char kRestHelix[] = R"(
[run]
duration = 1.0
time_step = 1e-3
[fluid]
model = "none"
[contact]
enabled = false
[[rods]]
shape = "helix"
nodes = 65
)";

TEST(RestHelix, HasZeroElasticForceAndStaysPutFor1000Steps) {
  const Model model = ModelFromToml(kRestHelix);
  State state = MakeRestState(model);
  VecX force = VecX::Zero(model.num_dofs);
  AddElasticForces(model.rods[0], state.q, state.rods[0], &force, nullptr);
  EXPECT_LT(force.cwiseAbs().maxCoeff(), 1e-12 * model.force_scale);
  const VecX q0 = state.q;
  Workspace ws(model);
  for (int k = 0; k < 1000; ++k) ASSERT_TRUE(Step(model, 1e-3, &state, &ws).ok) << k;
  EXPECT_LT((state.q - q0).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(Frames, StayOrthonormalOverManySteps) {
  // A helix driven in rotation with light damping: frames transported 2000 times.
  Model model = ModelFromToml(std::string(kRestHelix) + "omega = 3.0\n");
  model.damping = 0.5;
  Workspace ws(model);
  State state = MakeRestState(model);
  for (int k = 0; k < 2000; ++k) ASSERT_TRUE(Step(model, 1e-3, &state, &ws).ok) << k;
  double worst = 0.0;
  for (std::size_t j = 0; j < state.rods[0].frames.size(); ++j) {
    const RefFrame& f = state.rods[0].frames[j];
    const Vec3& t = state.rods[0].tangents[j];
    Mat3 m;
    m << f.d1, f.d2, t;
    worst = std::max(worst, (m.transpose() * m - Mat3::Identity()).cwiseAbs().maxCoeff());
    const Vec3 x0 = state.q.segment<3>(NodeDof(static_cast<int>(j)));
    const Vec3 x1 = state.q.segment<3>(NodeDof(static_cast<int>(j) + 1));
    EXPECT_NEAR(t.dot((x1 - x0).normalized()), 1.0, 1e-12);
  }
  EXPECT_LT(worst, 1e-12);
  // The drive turned θ0 by −ω t (t⁰ = −ẑ).
  EXPECT_NEAR(state.q(TwistDof(0)), -3.0 * 2.0, 1e-9);
}

}  // namespace
}  // namespace stokesrods
