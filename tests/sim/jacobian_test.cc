// The assembled Newton Jacobian against finite differences of the assembled residual, with the
// frame transport from the start of the step re-run at every perturbed q (what Newton sees).
#include <gtest/gtest.h>

#include <random>

#include "common/model_from_toml.h"
#include "stokesrods/sim/integrator.h"

namespace stokesrods {
namespace {

using testing::ModelFromToml;

double JacobianError(const Model& model, const State& start, double h, const VecX& q) {
  Workspace ws(model);
  std::vector<RodFrames> frames;
  VecX r0, rp, rm;
  Evaluate(model, start, h, q, true, &ws, &frames, &r0);
  const MatX analytic = ws.jacobian[0].ToDense();
  MatX numeric(model.num_dofs, model.num_dofs);
  const double eps = 1e-7 * model.rods[0].rest_edge_length.minCoeff();
  for (int k = 0; k < model.num_dofs; ++k) {
    VecX qp = q, qm = q;
    qp(k) += eps;
    qm(k) -= eps;
    Evaluate(model, start, h, qp, false, &ws, &frames, &rp);
    Evaluate(model, start, h, qm, false, &ws, &frames, &rm);
    numeric.col(k) = (rp - rm) / (2 * eps);
  }
  for (int k : model.rods[0].fixed_dofs) numeric.col(k).setZero(), numeric(k, k) = 1.0;
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

}  // namespace
}  // namespace stokesrods
