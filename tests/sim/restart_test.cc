// Exact restart: a run that forgets its reused factors at step k (ForgetReuse) and a fresh
// Workspace given the State and the StepHistory of step k take bit-identical steps afterwards.
// This is what makes `--resume` reproduce an uninterrupted run byte for byte (io/checkpoint.h);
// a piece of step-to-step state that neither is saved nor rebuilt fails it.
#include <gtest/gtest.h>

#include <string>

#include "common/model_from_toml.h"
#include "common/small_helices.h"
#include "stokesrods/sim/integrator.h"

namespace stokesrods {
namespace {

// Steps `before` steps, then continues `after` steps in the same Workspace (after ForgetReuse)
// and in a fresh one restored from the history; returns max |q_same − q_fresh| (exact: 0).
double RestartDifference(const std::string& toml, double h, int before, int after) {
  const Model model = testing::ModelFromToml(toml);
  State state = MakeRestState(model);
  Workspace ws(model);
  for (int k = 0; k < before; ++k) {
    const StepReport r = Step(model, h, &state, &ws);
    EXPECT_TRUE(r.ok) << r.message;
  }
  ForgetReuse(&ws);
  State resumed = state;
  Workspace fresh(model);
  RestoreHistory(CaptureHistory(ws), &fresh);
  double difference = 0.0;
  for (int k = 0; k < after; ++k) {
    const StepReport a = Step(model, h, &state, &ws);
    const StepReport b = Step(model, h, &resumed, &fresh);
    EXPECT_TRUE(a.ok && b.ok) << a.message << b.message;
    EXPECT_EQ(a.newton_iterations, b.newton_iterations) << "step " << k;
    EXPECT_EQ(a.krylov_iterations, b.krylov_iterations) << "step " << k;
    difference = std::max({difference, (state.q - resumed.q).cwiseAbs().maxCoeff(),
                           (state.velocity - resumed.velocity).cwiseAbs().maxCoeff()});
  }
  return difference;
}

struct Case {
  const char* name;
  int rods, nodes;
  double h;  // [s]
  const char* fluid;
  const char* run;
};

class Restart : public ::testing::TestWithParam<Case> {};

TEST_P(Restart, FreshWorkspaceWithTheHistoryStepsBitIdentically) {
  const Case& c = GetParam();
  // Reuse across steps on (jacobian_max_age 30), so that ForgetReuse has something to forget.
  const std::string toml = testing::SmallHelicesToml(c.rods, c.nodes, 900, c.fluid, c.run) +
                           "[solver]\njacobian_max_age = 30\n";
  EXPECT_EQ(RestartDifference(toml, c.h, 7, 30), 0.0) << c.name;
}

INSTANTIATE_TEST_SUITE_P(
    Integrators, Restart,
    ::testing::Values(
        Case{"euler_rss_krylov", 2, 15, 0.01, "model = \"rss\"", ""},
        Case{"bdf2_rss_krylov", 2, 15, 0.01, "model = \"rss\"", "integrator = \"bdf2\""},
        Case{"bdf2_rss_direct", 1, 15, 0.01, "model = \"rss\"\nsolver = \"direct\"",
             "integrator = \"bdf2\""},
        Case{"bdf2_matrix_free", 2, 15, 0.01, "model = \"rss\"\nmobility = \"matrix_free\"",
             "integrator = \"bdf2\""},
        Case{"explicit_matrix_free", 2, 15, 2e-4,
             "model = \"rss\"\nmobility = \"matrix_free\"\ncoupling = \"explicit\"",
             "time_step = 2e-4"},
        Case{"bdf2_lsbt", 1, 83, 0.01, "model = \"lsbt\"", "integrator = \"bdf2\""},
        Case{"euler_rft", 1, 15, 0.01, "model = \"rft\"", ""}),
    [](const ::testing::TestParamInfo<Case>& p) { return std::string(p.param.name); });

// At h = 0.2 ms the dense 𝕄 is extrapolated between assemblies (fluid/mobility_reuse.h): at the
// restart point its history is kept (not forgotten), goes to the fresh Workspace through the
// StepHistory and is assembled again there; the continuation is still bit-identical.
TEST(Restart, KeptMobilityReuseContinuesBitIdentically) {
  const std::string toml = testing::SmallHelicesToml(2, 15, 900, "model = \"rss\"", "");
  const Model model = testing::ModelFromToml(toml);
  State state = MakeRestState(model);
  Workspace ws(model);
  for (int k = 0; k < 40; ++k) ASSERT_TRUE(Step(model, 2e-4, &state, &ws).ok);
  ForgetReuse(&ws);
  const StepHistory history = CaptureHistory(ws);
  ASSERT_GE(history.mobility_reuse.geometries.size(), 2u);
  ASSERT_GT(history.mobility_reuse.interval, 1);  // extrapolating
  EXPECT_EQ(RestartDifference(toml, 2e-4, 40, 40), 0.0);
}

// Without ForgetReuse the reused factors make the continuation differ (within the Newton
// tolerance, not bitwise): the test above would catch a ForgetReuse that forgets nothing.
TEST(Restart, ReusedFactorsChangeTheContinuationWhenNotForgotten) {
  const Model model = testing::ModelFromToml(
      testing::SmallHelicesToml(1, 15, 900, "model = \"rss\"", "integrator = \"bdf2\"") +
      "[solver]\njacobian_max_age = 30\n");
  State state = MakeRestState(model);
  Workspace ws(model);
  for (int k = 0; k < 7; ++k) ASSERT_TRUE(Step(model, 0.01, &state, &ws).ok);
  State resumed = state;
  Workspace fresh(model);
  RestoreHistory(CaptureHistory(ws), &fresh);
  for (int k = 0; k < 5; ++k) {
    ASSERT_TRUE(Step(model, 0.01, &state, &ws).ok);
    ASSERT_TRUE(Step(model, 0.01, &resumed, &fresh).ok);
  }
  EXPECT_GT((state.q - resumed.q).cwiseAbs().maxCoeff(), 0.0);
}

}  // namespace
}  // namespace stokesrods
