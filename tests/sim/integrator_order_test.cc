// Order of accuracy in time: implicit Euler is first order, BDF2 second order. A helix in RSS
// fluid driven from rest (implicit drag, 𝕄 at q_k for Euler and at the predictor for BDF2),
// tip position at t = 0.16 s against a run at h/32, for h = 20, 10, 5 ms.
#include <gtest/gtest.h>

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

}  // namespace
}  // namespace stokesrods
