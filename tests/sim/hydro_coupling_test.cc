// The kept Krylov preconditioner of the capacitance follows the rods' rotation
// (sim/hydro_coupling.h). A rigid turn of the whole configuration turns 𝕄 and the elastic
// blocks alike: the turned system is C₁ = Q C₀ Qᵀ, Q the turn on every node. So the
// preconditioner P₀ built for C₀ (the LU of the dense C, or the matrix-free operator's blocks and
// coarse level, which are built from the same geometry), kept and applied as Q P₀ Qᵀ,
// preconditions the turned system exactly as it did C₀ (the same GMRES products, the turned
// solution), while applied as built it needs more products for the same solution.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>
#include <string>

#include "common/model_from_toml.h"
#include "common/small_helices.h"
#include "stokesrods/sim/hydro_coupling.h"
#include "stokesrods/sim/integrator.h"

namespace stokesrods {
namespace {

// The state turned rigidly by `turn` about the origin: positions, velocities, frames.
State Turned(const Model& model, const Mat3& turn, const State& s) {
  State t = s;
  for (const RodModel& rod : model.rods)
    for (int i = 0; i < rod.num_nodes(); ++i) {
      const int k = rod.dof_offset + NodeDof(i);
      t.q.segment<3>(k) = turn * s.q.segment<3>(k);
      t.velocity.segment<3>(k) = turn * s.velocity.segment<3>(k);
    }
  for (RodFrames& rod : t.rods) {
    for (RefFrame& f : rod.frames) f = {turn * f.d1, turn * f.d2};
    for (Vec3& tangent : rod.tangents) tangent = turn * tangent;
  }
  return t;
}

// A DOF vector with its node positions turned (twist angles as they are).
VecX TurnedDofs(const Model& model, const Mat3& turn, const VecX& x) {
  VecX t = x;
  for (const RodModel& rod : model.rods)
    for (int i = 0; i < rod.num_nodes(); ++i)
      t.segment<3>(rod.dof_offset + NodeDof(i)) = turn * x.segment<3>(rod.dof_offset + NodeDof(i));
  return t;
}

VecX TurnedNodes(const Mat3& turn, const VecX& x) {
  VecX t = x;
  for (Eigen::Index i = 0; i < x.size() / 3; ++i) t.segment<3>(3 * i) = turn * x.segment<3>(3 * i);
  return t;
}

struct TurnOutcome {
  int products_before = 0;  // the solve right after the preconditioner was built
  int products_after = 0;   // the turned system's, with the preconditioner kept
  double solution_error = 0.0;  // |δf₁ − Q δf₀| / |δf₀|
  bool coarse_kept = false;     // after the turned system's factorization
};

// `aged`: the preconditioner is past its age limit (40 steps) at the turn, so the turned system's
// factorization rebuilds it, its coarse level kept or not as fluid.krylov_coarse_rebuild_period
// = `coarse_period` says (0: by its cost, 1 for two helices).
TurnOutcome SolveBeforeAndAfterATurn(const std::string& mobility, bool rotate, double angle,
                                     bool aged = false, int coarse_period = 0) {
  std::string fluid = "model = \"rss\"\nmobility = \"" + mobility + "\"\nsolver = \"krylov\"\n";
  if (mobility == "matrix_free")
    fluid += "far_field_tolerance = 1e-10\nfast_sum_tolerance = 1e-10\n";
  fluid += "krylov_tolerance = 1e-10\nmobility_reuse_tolerance = 0\n";
  fluid += "krylov_rotate_preconditioner = " + std::string(rotate ? "true" : "false") + "\n";
  fluid += "krylov_coarse_rebuild_period = " + std::to_string(coarse_period);
  const Model model =
      testing::ModelFromToml(testing::SmallHelicesToml(2, 17, 300, fluid, "time_step = 0.01"));
  const double h = 0.01;
  State start = MakeRestState(model);
  {
    Workspace stepping(model);
    for (int k = 0; k < 5; ++k) EXPECT_TRUE(Step(model, h, &start, &stepping).ok);  // bent
  }
  // Right-hand sides: any r_q (zero on the fixed DOFs) and r_u.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  VecX r_q = VecX::NullaryExpr(model.num_dofs, [&] { return uniform(rng); });
  for (const RodModel& rod : model.rods)
    for (int k : rod.fixed_dofs) r_q(rod.dof_offset + k) = 0.0;
  r_q *= model.force_scale;
  const VecX r_u = 1e-3 * VecX::NullaryExpr(3 * model.num_nodes, [&] { return uniform(rng); });
  const VecX drag = VecX::Zero(3 * model.num_nodes);

  // Solves with 𝕄 and B at `state`; the first solve builds the preconditioner, the second keeps
  // it (one step old, same h, the first solve fast).
  Workspace ws(model);
  auto solve = [&](const State& state, const VecX& rq, const VecX& ru, VecX* df) {
    PrepareStep(model, state, &ws);
    std::vector<RodFrames> frames;
    VecX residual;
    Evaluate(model, state, h, state.q, drag, true, &ws, &frames, &residual);
    EXPECT_TRUE(ws.hydro.FactorizeNewtonSystem(model, h, &ws.jacobian));
    VecX dq, du;
    return ws.hydro.SolveNewtonSystem(model, ws.jacobian, h, rq, ru, &dq, df, &du)
        .krylov_iterations;
  };
  TurnOutcome out;
  VecX df0, df1;
  const long builds = ws.hydro.preconditioner_builds();
  out.products_before = solve(start, r_q, r_u, &df0);
  if (aged)
    for (int k = 0; k < 40; ++k) PrepareStep(model, start, &ws);
  const Mat3 turn = Eigen::AngleAxisd(angle, Vec3(0.3, -0.2, 1.0).normalized()).toRotationMatrix();
  out.products_after = solve(Turned(model, turn, start), TurnedDofs(model, turn, r_q),
                             TurnedNodes(turn, r_u), &df1);
  EXPECT_EQ(ws.hydro.preconditioner_builds(), builds + (aged ? 2 : 1))
      << "the preconditioner was rebuilt, or not, unexpectedly";
  out.coarse_kept = ws.hydro.coarse_kept();
  out.solution_error = (df1 - TurnedNodes(turn, df0)).norm() / df0.norm();
  return out;
}

// Two helices: dense 𝕄 (the LU of C), and matrix-free (its far field summed directly, in double
// precision: a turn changes the single-precision sums' rounding, 4e-7 of the solution at the
// default tolerances; and the FMM's boxes would not turn).
TEST(HydroCoupling, KeptPreconditionerFollowsARigidTurn) {
  for (const std::string mobility : {"dense", "matrix_free"})
  for (double angle : {0.1, 0.5}) {
    const TurnOutcome rotated = SolveBeforeAndAfterATurn(mobility, true, angle);
    const TurnOutcome as_built = SolveBeforeAndAfterATurn(mobility, false, angle);
    std::printf("%s, turn of %.1f rad: GMRES products %d then %d (rotated), %d then %d (as "
                "built); solution against the turned one %.2e, %.2e\n",
                mobility.c_str(), angle, rotated.products_before, rotated.products_after, as_built.products_before,
                as_built.products_after, rotated.solution_error, as_built.solution_error);
    // Q P₀ Qᵀ C₁ = Q P₀ C₀ Qᵀ: the same Krylov iteration, turned (round-off apart).
    EXPECT_LE(rotated.products_after, rotated.products_before);
    EXPECT_GE(as_built.products_after, as_built.products_before + 2);
    // Both solve the turned system to the GMRES tolerance (1e-10 of the right-hand side).
    EXPECT_LT(rotated.solution_error, 1e-8);
    EXPECT_LT(as_built.solution_error, 1e-8);
  }
}

// The coarse level kept across a rebuild of the blocks (period 2) and applied in its own frame,
// turned by each rod's rotation since its build: after a rigid turn of the whole configuration
// it is the coarse level a build there gives, turned (Q E⁻¹ Qᵀ), so the turned system takes the
// same GMRES products as with the coarse level rebuilt (period 1) and the same solution. Applied
// unturned it takes 10 and 17 products instead of 7 (checked by removing its rotation).
TEST(HydroCoupling, KeptCoarseLevelFollowsARigidTurn) {
  for (double angle : {0.1, 0.5}) {
    const TurnOutcome kept = SolveBeforeAndAfterATurn("matrix_free", true, angle, true, 2);
    const TurnOutcome rebuilt = SolveBeforeAndAfterATurn("matrix_free", true, angle, true, 1);
    std::printf(
        "turn of %.1f rad, then a rebuild: GMRES products %d (coarse level kept), %d "
        "(rebuilt); solution against the turned one %.2e, %.2e\n",
        angle, kept.products_after, rebuilt.products_after, kept.solution_error,
        rebuilt.solution_error);
    EXPECT_TRUE(kept.coarse_kept);
    EXPECT_FALSE(rebuilt.coarse_kept);
    EXPECT_EQ(kept.products_after, rebuilt.products_after);
    EXPECT_LT(kept.solution_error, 1e-8);
    EXPECT_LT(rebuilt.solution_error, 1e-8);
  }
}

TEST(HydroCoupling, CoarseRebuildPeriodGrowsWithTheCoarseLevelsCost) {
  // E of 24 unknowns per rod of 65 nodes: every rebuild up to a hundred helices, then as √(R²).
  EXPECT_EQ(CoarseRebuildPeriod(24 * 10, 650), 1);
  EXPECT_EQ(CoarseRebuildPeriod(24 * 100, 6500), 1);
  EXPECT_EQ(CoarseRebuildPeriod(24 * 200, 13000), 2);
  EXPECT_EQ(CoarseRebuildPeriod(24 * 400, 26000), 4);
  EXPECT_EQ(CoarseRebuildPeriod(0, 6500), 1);  // no coarse level
}

}  // namespace
}  // namespace stokesrods
