// The assembled Newton Jacobian against finite differences of the assembled residual, with the
// frame transport from the start of the step re-run at every perturbed q (what Newton sees); the
// elastic forces alone against those the Jacobian's assembly takes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include <Eigen/LU>

#include "common/model_from_toml.h"
#include "common/small_helices.h"
#include "stokesrods/sim/elastic_assembly.h"
#include "stokesrods/sim/hydro_coupling.h"
#include "stokesrods/sim/integrator.h"
#include "stokesrods/sim/state.h"

namespace stokesrods {
namespace {

using testing::ModelFromToml;

// The implicit drag as the exact solution of the no-slip equation, f(q) = −𝕄⁻¹ U(q) (dense LU),
// so that r_q(q, f(q)) is the reduced residual of q alone; zero without a nonlocal fluid.
VecX ExactDrag(const Model& model, const State& start, double h, const VecX& q,
               const Workspace& ws) {
  if (!ws.nonlocal_fluid || h == 0.0) return VecX::Zero(3 * model.num_nodes);
  VecX u;
  GatherNodeVelocities(model, q, start.q, h, &u);
  return -ws.hydro.mobility().matrix()->partialPivLu().solve(u);
}

// Central differences of the whole residual r(q) (frames re-transported from the start of the
// step at every perturbed q, the drag solved exactly at each), with identity rows and columns
// on the fixed DOFs as Newton has.
MatX NumericJacobian(const Model& model, const State& start, double h, const VecX& q,
                     double eps, Workspace* ws) {
  std::vector<RodFrames> frames;
  VecX rp, rm;
  MatX numeric(model.num_dofs, model.num_dofs);
  for (int k = 0; k < model.num_dofs; ++k) {
    VecX qp = q, qm = q;
    qp(k) += eps;
    qm(k) -= eps;
    Evaluate(model, start, h, qp, ExactDrag(model, start, h, qp, *ws), false, ws, &frames, &rp);
    Evaluate(model, start, h, qm, ExactDrag(model, start, h, qm, *ws), false, ws, &frames, &rm);
    numeric.col(k) = (rp - rm) / (2 * eps);
  }
  for (const RodModel& rod : model.rods)
    for (int k : rod.fixed_dofs) {
      numeric.col(rod.dof_offset + k).setZero();
      numeric(rod.dof_offset + k, rod.dof_offset + k) = 1.0;
    }
  return numeric;
}

// One rod: the assembled banded Jacobian against NumericJacobian, relative Frobenius error.
double JacobianError(const Model& model, const State& start, double h, const VecX& q) {
  Workspace ws(model);
  PrepareStep(model, start, &ws);
  std::vector<RodFrames> frames;
  VecX r0;
  Evaluate(model, start, h, q, ExactDrag(model, start, h, q, ws), true, &ws, &frames, &r0);
  const MatX analytic = ws.jacobian[0].ToDense();
  const MatX numeric = NumericJacobian(model, start, h, q,
                                       1e-7 * model.rods[0].rest_edge_length.minCoeff(), &ws);
  return (analytic - numeric).norm() / numeric.norm();
}

constexpr char kColumn[] = R"(
[run]
mode = "static"
[fluid]
model = "none"
[contact]
enabled = false
[[rods]]
shape = "straight"
nodes = 12
axis_length = 0.2
loads = [{ node = 11, force = [4.6e-8, 0.0, 4.6e-4] }]
)";

TEST(Jacobian, StaticStraightColumnUnderCompression) {
  const Model model = ModelFromToml(kColumn);
  const State start = MakeRestState(model);
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, 1.0);
  VecX q = start.q;
  for (int k = 0; k < model.num_dofs; ++k) q(k) += 1e-6 * n(rng);
  for (int k : model.rods[0].fixed_dofs) q(k) = start.q(k);
  EXPECT_LT(JacobianError(model, start, 0.0, start.q), 1e-6);
  EXPECT_LT(JacobianError(model, start, 0.0, q), 1e-6);
}

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

TEST(Jacobian, RotatingHelixInMotion) {
  // A deformed, twisted, moving state: 50 steps of the driven helix; then the Jacobian at a
  // trial point of the next step (with the frames transported from the start of the step).
  const Model model = ModelFromToml(kHelix);
  State state = MakeRestState(model);
  Workspace ws(model);
  for (int k = 0; k < 50; ++k) ASSERT_TRUE(Step(model, 0.01, &state, &ws).ok);
  VecX q = state.q + 0.01 * state.velocity;
  DriveBoundaryConditions(model, 0.01, &q);
  std::printf("at the start of the step %.3e, at the predictor %.3e\n",
              JacobianError(model, state, 0.01, state.q), JacobianError(model, state, 0.01, q));
  EXPECT_LT(JacobianError(model, state, 0.01, state.q), 1e-6);
}

// AddElasticForces (by edges: each edge's terms once, the stencils' bending and twisting several
// at a time in vector lanes, elastic/stencil_lanes.h) against AddElasticForcesPerStencil (the
// energies of elastic/, which tests/elastic/ checks against finite differences): forces, moments
// and the Jacobian, with the Jacobian and without, on each instruction set (the widest the CPU
// has, AVX2, one stencil at a time; a path the CPU lacks falls back to the next) and on rods
// whose stencils fill the lanes in whole batches and not (19, 9 and 3 stencils: batches of 8 and
// 4 lanes with 3, 1 and 3 left over).
void CompareByEdgesWithStencilByStencil(int nodes, StencilPath path) {
  std::string toml = kHelix;
  toml.replace(toml.find("nodes = 21"), 10, "nodes = " + std::to_string(nodes));
  SCOPED_TRACE(::testing::Message() << nodes << " nodes, path " << static_cast<int>(path));
  // The driven helix after 30 steps (rest curvature and twist, frames transported, twisted),
  // then moved at random by up to a fifth of an edge and twisted by up to 0.5 rad per edge.
  const Model model = ModelFromToml(toml);
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
    VecX reference = VecX::Zero(model.num_dofs), with = reference, without = reference;
    BandedMatrix jacobian_reference(rod.num_dofs(), 10), jacobian(rod.num_dofs(), 10);
    const double energy_reference =
        AddElasticForcesPerStencil(rod, q, frames[0], &reference, &jacobian_reference);
    const double energy_with = AddElasticForces(rod, q, frames[0], &with, &jacobian, path);
    const double energy_without = AddElasticForces(rod, q, frames[0], &without, nullptr, path);
    // The forces on the nodes and the moments on the twist angles, each against its largest.
    for (const bool moments : {false, true}) {
      double scale = 0.0, error = 0.0;
      for (int k = 0; k < rod.num_dofs(); ++k) {
        if ((k % 4 == 3) != moments) continue;
        scale = std::max(scale, std::abs(reference(k)));
        error = std::max({error, std::abs(with(k) - reference(k)),
                          std::abs(without(k) - reference(k))});
      }
      std::printf("moved by %.0e edges: %s apart by %.2e of the largest (%.3e)\n", size,
                  moments ? "moments" : "forces", error / scale, scale);
      EXPECT_GT(scale, 0.0);
      EXPECT_LT(error, 1e-12 * scale) << (moments ? "moments" : "forces") << ", moved by " << size;
    }
    const MatX dense_reference = jacobian_reference.ToDense();
    const double jacobian_error =
        (jacobian.ToDense() - dense_reference).norm() / dense_reference.norm();
    // Bending and twisting alone (the stretching terms, EA ≫ EI/l², would hide them).
    RodModel soft = rod;
    soft.axial_stiffness = 0.0;
    BandedMatrix soft_reference(rod.num_dofs(), 10), soft_jacobian(rod.num_dofs(), 10);
    VecX scratch = VecX::Zero(model.num_dofs);
    AddElasticForcesPerStencil(soft, q, frames[0], &scratch, &soft_reference);
    AddElasticForces(soft, q, frames[0], &scratch, &soft_jacobian, path);
    const MatX soft_dense = soft_reference.ToDense();
    const double soft_error = (soft_jacobian.ToDense() - soft_dense).cwiseAbs().maxCoeff() /
                              soft_dense.cwiseAbs().maxCoeff();
    std::printf("moved by %.0e edges: Jacobians apart by %.2e (relative Frobenius), without "
                "stretching by %.2e of the largest entry\n", size, jacobian_error, soft_error);
    EXPECT_LT(jacobian_error, 1e-12) << "moved by " << size;
    EXPECT_LT(soft_error, 1e-12) << "moved by " << size;
    EXPECT_NEAR(energy_with, energy_reference, 1e-12 * energy_reference);
    EXPECT_NEAR(energy_without, energy_reference, 1e-12 * energy_reference);
  }
}

TEST(ElasticAssembly, ByEdgesAsStencilByStencil) {
  for (const StencilPath path : {StencilPath::kWidest, StencilPath::kAvx2, StencilPath::kPortable})
    for (const int nodes : {21, 11, 5}) CompareByEdgesWithStencilByStencil(nodes, path);
}

// The implicit RSS drag couples everything. With f eliminated exactly (f = −𝕄⁻¹U), Newton's
// matrix on q alone is J = B + Sᵀ 𝕄⁻¹ S / h: check that J is the derivative of the reduced
// residual, that the saddle solve (δq, δf) gives δq = −J⁻¹ r (dense LU of J as the reference)
// for each mobility and capacitance solver, and that du tracks r_u along (δq, δf).
void CheckImplicitNonlocalDrag(const std::string& fluid_options, double solve_tolerance) {
  Model model = ModelFromToml(testing::SmallHelicesToml(
      2, 15, 300, "model = \"rss\"\n" + fluid_options, "time_step = 0.01"));
  const double h = 0.01;
  State state = MakeRestState(model);
  Workspace ws(model);
  for (int k = 0; k < 20; ++k) ASSERT_TRUE(Step(model, h, &state, &ws).ok);
  PrepareStep(model, state, &ws);
  VecX q = state.q + h * state.velocity;
  DriveBoundaryConditions(model, h, &q);
  // The dense mobility at the start of the step, assembled directly (the reference).
  std::vector<Matrix3X> positions;
  for (int r = 0; r < 2; ++r) positions.push_back(RodPositions(model, r, state.q));
  MatX mobility;
  AssembleMobility(model.fluid, MakeHydroRods(model, positions), &mobility);
  VecX u;
  GatherNodeVelocities(model, q, state.q, h, &u);
  const VecX drag = -mobility.partialPivLu().solve(u);
  // Dense J from the banded parts and the mobility.
  std::vector<RodFrames> frames;
  VecX r0;
  Evaluate(model, state, h, q, drag, true, &ws, &frames, &r0);
  const int n = model.num_dofs;
  MatX dense = MatX::Zero(n, n);
  for (std::size_t r = 0; r < model.rods.size(); ++r) {
    const int o = model.rods[r].dof_offset, m = model.rods[r].num_dofs();
    dense.block(o, o, m, m) = ws.jacobian[r].ToDense();
  }
  const MatX resistance = mobility.partialPivLu().inverse();
  std::vector<int> position_dof(3 * model.num_nodes, -1);
  for (const RodModel& rod : model.rods)
    for (int i = 0; i < rod.num_nodes(); ++i)
      for (int c = 0; c < 3; ++c)
        if (!std::binary_search(rod.fixed_dofs.begin(), rod.fixed_dofs.end(), NodeDof(i) + c))
          position_dof[3 * (rod.node_offset + i) + c] = rod.dof_offset + NodeDof(i) + c;
  for (int a = 0; a < 3 * model.num_nodes; ++a)
    for (int b = 0; b < 3 * model.num_nodes; ++b)
      if (position_dof[a] >= 0 && position_dof[b] >= 0)
        dense(position_dof[a], position_dof[b]) += resistance(a, b) / h;
  if (ws.hydro.mobility().matrix() != nullptr) {
    // J against finite differences of the reduced residual (drag solved exactly at each q).
    const MatX numeric = NumericJacobian(model, state, h, q, 1e-8, &ws);
    const double jacobian_error = (dense - numeric).norm() / numeric.norm();
    std::printf("two helices: Jacobian vs FD %.3e\n", jacobian_error);
    EXPECT_LT(jacobian_error, 1e-3);
  }
  // The saddle solve with r_u = 0 at the exact drag against the dense LU of J.
  Evaluate(model, state, h, q, drag, true, &ws, &frames, &r0);
  ASSERT_TRUE(ws.hydro.FactorizeNewtonSystem(model, h, &ws.jacobian));
  VecX dq, df, du;
  const VecX no_slip = VecX::Zero(3 * model.num_nodes);
  ws.hydro.SolveNewtonSystem(model, ws.jacobian, h, r0, no_slip, &dq, &df, &du);
  const VecX reference = -dense.partialPivLu().solve(r0);
  const double solve_error = (dq - reference).norm() / reference.norm();
  // From half the drag (r_u = U/2 ≠ 0): one Newton step zeroes r_u, and r_u + du tracks it.
  const VecX half = 0.5 * drag;
  VecX r_u0, r_u1;
  Evaluate(model, state, h, q, half, false, &ws, &frames, &r0);
  ws.hydro.VelocityResidual(model, q, state.q, h, half, &r_u0);
  ws.hydro.SolveNewtonSystem(model, ws.jacobian, h, r0, r_u0, &dq, &df, &du);
  ws.hydro.VelocityResidual(model, q + dq, state.q, h, half + df, &r_u1);
  const double tracking_error = (r_u0 + du - r_u1).norm() / r_u0.norm();
  const double no_slip_error = r_u1.norm() / r_u0.norm();
  std::printf("two helices (%s): saddle solve vs dense LU %.3e, r_u tracking %.3e, r_u after one "
              "step %.3e of before\n", fluid_options.c_str(), solve_error, tracking_error,
              no_slip_error);
  EXPECT_LT(solve_error, solve_tolerance);
  EXPECT_LT(tracking_error, 1e-10);
  EXPECT_LT(no_slip_error, 10 * solve_tolerance);
}

// The dense 𝕄 without reuse: its products in double, as the reference's (from a reuse tolerance
// of 1e-4 on they take 𝕄 rounded to single precision, fluid/mobility_reuse.h).
TEST(Jacobian, ImplicitNonlocalDragTwoHelicesDirect) {
  CheckImplicitNonlocalDrag(
      "mobility = \"dense\"\nsolver = \"direct\"\nmobility_reuse_tolerance = 0", 1e-10);
}

TEST(Jacobian, ImplicitNonlocalDragTwoHelicesKrylov) {
  CheckImplicitNonlocalDrag("mobility = \"dense\"\nsolver = \"krylov\"\nkrylov_tolerance = 1e-12\n"
                            "mobility_reuse_tolerance = 0", 1e-9);
}

// The matrix-free 𝕄 at a far-field tolerance of 1e-10 against the dense reference.
TEST(Jacobian, ImplicitNonlocalDragTwoHelicesMatrixFree) {
  CheckImplicitNonlocalDrag(
      "mobility = \"matrix_free\"\nfar_field_tolerance = 1e-10\nfast_sum_tolerance = 1e-10\n"
      "krylov_tolerance = 1e-12", 1e-8);
}

}  // namespace
}  // namespace stokesrods
