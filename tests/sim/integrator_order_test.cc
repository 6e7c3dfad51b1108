// Order of accuracy in time: implicit Euler is first order, BDF2 second order. A helix in RSS
// fluid driven from rest (implicit drag, 𝕄 at q_k for Euler and at the predictor for BDF2),
// tip position at t = 0.16 s against a run at h/32, for h = 20, 10, 5 ms.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "common/model_from_toml.h"
#include "common/small_helices.h"
#include "stokesrods/sim/integrator.h"

namespace stokesrods {
namespace {

Vec3 TipAt(const std::string& integrator, double h, double t_end) {
  const Model model = testing::ModelFromToml(testing::SmallHelicesToml(
      1, 15, 600, "model = \"rss\"", "integrator = \"" + integrator + "\""));
  State state = MakeRestState(model);
  Workspace ws(model);
  const int steps = static_cast<int>(std::lround(t_end / h));
  for (int k = 0; k < steps; ++k) {
    const StepReport r = Step(model, h, &state, &ws);
    EXPECT_TRUE(r.ok) << r.message;
  }
  const RodModel& rod = model.rods[0];
  return state.q.segment<3>(rod.dof_offset + NodeDof(rod.num_nodes() - 1));
}

// Observed orders log2(e(h)/e(h/2)) on h = 20, 10, 5 ms.
std::vector<double> ObservedOrders(const std::string& integrator) {
  const double t_end = 0.16;
  const Vec3 reference = TipAt("bdf2", 0.02 / 32, t_end);
  std::vector<double> errors;
  for (double h : {0.02, 0.01, 0.005}) errors.push_back((TipAt(integrator, h, t_end) - reference).norm());
  std::printf("%s: tip errors %.3e %.3e %.3e m\n", integrator.c_str(), errors[0], errors[1],
              errors[2]);
  return {std::log2(errors[0] / errors[1]), std::log2(errors[1] / errors[2])};
}

TEST(IntegratorOrder, EulerIsFirstOrder) {
  const std::vector<double> p = ObservedOrders("euler");
  std::printf("implicit Euler: observed orders %.2f %.2f\n", p[0], p[1]);
  EXPECT_NEAR(p[1], 1.0, 0.25);
}

TEST(IntegratorOrder, Bdf2IsSecondOrder) {
  const std::vector<double> p = ObservedOrders("bdf2");
  std::printf("BDF2: observed orders %.2f %.2f\n", p[0], p[1]);
  EXPECT_NEAR(p[1], 2.0, 0.3);
}

// The predictor's guess with its edges at their extrapolated lengths (ExtrapolateEdgeLengths,
// SetEdgeLengths): on a helix clamped at its first two nodes, a guess stretched, turned and with
// its fixed nodes and twists moved by the step. Every free edge takes the length 2|e_k| − |e_{k−1}| (q_{k−1}
// shrunk by 2 % about the origin, so 1.02 |e_k|), or |e_k| without q_{k−1}, and points from its
// first node (as placed) at its second node's guessed position; the fixed nodes' positions and
// all twist angles stay as guessed.
TEST(Predictor, SetsEachEdgeToItsExtrapolatedLengthInItsGuessedDirection) {
  const Model model = testing::ModelFromToml(testing::SmallHelicesToml(1, 15, 600, "model = \"rss\""));
  const RodModel& rod = model.rods[0];
  const State state = MakeRestState(model);
  VecX guess = state.q, before = state.q;
  for (int i = 0; i < rod.num_nodes(); ++i) {  // stretched by 3 %, turned, shifted
    Vec3 x = 1.03 * state.q.segment<3>(rod.dof_offset + NodeDof(i));
    x = Vec3(x.x() - 0.05 * x.y(), x.y() + 0.05 * x.x(), x.z()) + Vec3(1e-3, 0.0, 0.0);
    guess.segment<3>(rod.dof_offset + NodeDof(i)) = x;
    before.segment<3>(rod.dof_offset + NodeDof(i)) *= 0.98;
  }
  for (int j = 0; j + 1 < rod.num_nodes(); ++j) guess(rod.dof_offset + NodeDof(j) + 3) += 0.1 * j;
  const auto fixed = [&](int node) {
    return std::binary_search(rod.fixed_dofs.begin(), rod.fixed_dofs.end(), NodeDof(node));
  };
  ASSERT_TRUE(fixed(0) && fixed(1) && !fixed(2));
  const auto node = [&](const VecX& q, int k) { return Vec3(q.segment<3>(rod.dof_offset + NodeDof(k))); };
  for (const double growth : {1.0, 1.02}) {
    VecX kept = guess, lengths;
    ExtrapolateEdgeLengths(model, state.q, growth == 1.0 ? nullptr : &before, &lengths);
    SetEdgeLengths(model, lengths, &kept);
    for (int i = 0; i < rod.num_nodes(); ++i) {
      if (fixed(i)) {
        EXPECT_EQ(node(kept, i), node(guess, i)) << i;
      }
      if (i == 0 || fixed(i)) continue;
      const Vec3 edge = node(kept, i) - node(kept, i - 1);
      const double length = (node(state.q, i) - node(state.q, i - 1)).norm();
      EXPECT_NEAR(edge.norm(), growth * length, 1e-15) << i;
      const Vec3 aim = node(guess, i) - node(kept, i - 1);
      EXPECT_NEAR(edge.normalized().dot(aim.normalized()), 1.0, 1e-14) << i;
    }
    for (int j = 0; j + 1 < rod.num_nodes(); ++j)
      EXPECT_EQ(kept(rod.dof_offset + NodeDof(j) + 3), guess(rod.dof_offset + NodeDof(j) + 3)) << j;
  }
}

}  // namespace
}  // namespace stokesrods
