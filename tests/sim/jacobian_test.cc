// The assembled Newton Jacobian against finite differences of the assembled residual, with the
// frame transport from the start of the step re-run at every perturbed q (what Newton sees).
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include <Eigen/LU>

#include "common/model_from_toml.h"
#include "stokesrods/sim/integrator.h"

namespace stokesrods {
namespace {

using testing::ModelFromToml;

// Central differences of the whole residual r(q) (frames re-transported from the start of the
// step at every perturbed q), with identity rows and columns on the fixed DOFs as Newton has.
MatX NumericJacobian(const Model& model, const State& start, double h, const VecX& q,
                     double eps, Workspace* ws) {
  std::vector<RodFrames> frames;
  VecX rp, rm;
  MatX numeric(model.num_dofs, model.num_dofs);
  for (int k = 0; k < model.num_dofs; ++k) {
    VecX qp = q, qm = q;
    qp(k) += eps;
    qm(k) -= eps;
    Evaluate(model, start, h, qp, false, ws, &frames, &rp);
    Evaluate(model, start, h, qm, false, ws, &frames, &rm);
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
  Evaluate(model, start, h, q, true, &ws, &frames, &r0);
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

// The implicit RSS drag couples everything: check that the Woodbury solve inverts exactly
// J = B + Sᵀ 𝕄⁻¹ S / h, and that J is the derivative of the residual, on two helices in motion.
TEST(Jacobian, ImplicitNonlocalDragTwoHelices) {
  Model model = ModelFromToml(R"(
[run]
duration = 1.0
time_step = 0.01
[fluid]
model = "rss"
[contact]
enabled = false
[[rods]]
nodes = 15
axis_length = 0.1
helix_radius = 0.008
omega_bar = 300
[[rods]]
nodes = 15
axis_length = 0.1
helix_radius = 0.008
base = [0.0175, 0.0, 0.0]
omega_bar = 300
)");
  const double h = 0.01;
  State state = MakeRestState(model);
  Workspace ws(model);
  for (int k = 0; k < 20; ++k) ASSERT_TRUE(Step(model, h, &state, &ws).ok);
  PrepareStep(model, state, &ws);
  VecX q = state.q + h * state.velocity;
  DriveBoundaryConditions(model, h, &q);
  // Dense J from the banded parts and the mobility.
  std::vector<RodFrames> frames;
  VecX r0;
  Evaluate(model, state, h, q, true, &ws, &frames, &r0);
  const int n = model.num_dofs;
  MatX dense = MatX::Zero(n, n);
  for (std::size_t r = 0; r < model.rods.size(); ++r) {
    const int o = model.rods[r].dof_offset, m = model.rods[r].num_dofs();
    dense.block(o, o, m, m) = ws.jacobian[r].ToDense();
  }
  const MatX resistance = ws.hydro.mobility().partialPivLu().inverse();
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
  // J against finite differences of the whole residual (drag included).
  const MatX numeric = NumericJacobian(model, state, h, q, 1e-8, &ws);
  const double jacobian_error = (dense - numeric).norm() / numeric.norm();
  // The Woodbury solve against the dense LU.
  Evaluate(model, state, h, q, true, &ws, &frames, &r0);
  ASSERT_TRUE(ws.hydro.FactorizeNewtonSystem(model, h, &ws.jacobian));
  VecX x = r0;
  ws.hydro.SolveNewtonSystem(model, ws.jacobian, &x);
  const VecX reference = dense.partialPivLu().solve(r0);
  const double solve_error = (x - reference).norm() / reference.norm();
  std::printf("two helices: Jacobian vs FD %.3e, Woodbury vs dense LU %.3e\n", jacobian_error,
              solve_error);
  EXPECT_LT(jacobian_error, 1e-3);
  EXPECT_LT(solve_error, 1e-10);
}

}  // namespace
}  // namespace stokesrods
