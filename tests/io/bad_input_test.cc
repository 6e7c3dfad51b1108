// Bad input never runs (SPEC: exit 2, the message names the file, the key and the problem):
// every case of issue 10's list that is decided before the first step.
#include <gtest/gtest.h>

#include <regex>
#include <string>

#include "stokesrods/io/build_model.h"
#include "stokesrods/io/config.h"
#include "common/model_from_toml.h"

namespace stokesrods {
namespace {

constexpr char kRun[] = "[run]\nduration = 1.0\ntime_step = 0.01\n";
constexpr char kRod[] = "[[rods]]\nnodes = 21\naxis_length = 0.1\nhelix_radius = 0.008\n";

// The error of building the model and the run plan of `text`, or "" if both succeed.
std::string ErrorOf(const std::string& text, const std::vector<std::string>& overrides = {}) {
  return testing::ConfigErrorOf(text, overrides);
}

struct Case {
  std::string text, expected;
};

void ExpectErrors(const std::vector<Case>& cases) {
  for (const Case& c : cases) {
    const std::string error = ErrorOf(c.text);
    EXPECT_NE(error.find(c.expected), std::string::npos)
        << "input:\n" << c.text << "\nerror: " << error << "\nexpected: " << c.expected;
  }
}

TEST(BadInput, StepCountsThatOverflowOrAreEmptyAreRefused) {
  const std::string rod = kRod;
  ExpectErrors({
      {"[run]\nduration = 1.0\ntime_step = 1e-300\n" + rod,
       "case.toml: run.time_step: the run would take 1e+300 steps"},
      {"[run]\nduration = 1e300\ntime_step = 1e-3\n" + rod,
       "case.toml: run.time_step: the run would take 1e+303 steps"},
      {"[run]\nt_bar_end = 1e200\n" + rod, "the run would take"},
      {"[run]\nduration = 1.0\ntime_step = 2.0\n" + rod,
       "case.toml: run.time_step: 2 s is longer than the whole run (1 s)"},
      {"[run]\nduration = 1.0\ntime_step = 0.01\noutput_interval = 0.001\n" + rod,
       "case.toml: run.output_interval: run.output_interval = 0.001 s is shorter than "
       "run.time_step = 0.01 s"},
      {"[run]\nduration = 1.0\ntime_step = 0.01\ncheckpoint_interval = 0.005\n" + rod,
       "run.checkpoint_interval: run.checkpoint_interval = 0.005 s is shorter"},
      {"[run]\nduration = 1.0\ncheckpoint_wall_interval = -1.0\n" + rod,
       "run.checkpoint_wall_interval: must be a finite number > 0"},
  });
  EXPECT_EQ(ErrorOf(std::string(kRun) + kRod), "");
}

TEST(BadInput, NotANumberAndInfinitiesAreRefused) {
  const std::string run = kRun, rod = kRod;
  ExpectErrors({
      {"[run]\nduration = inf\n" + rod, "run.duration: must be a finite number > 0 (got inf)"},
      {"[run]\nduration = nan\n" + rod, "run.duration: must be a finite number > 0 (got nan)"},
      {"[run]\nduration = 1.0\ntime_step = -inf\n" + rod, "run.time_step: must be a finite"},
      {run + rod + "radius = nan\n", "rods.1.radius: must be a finite number > 0"},
      {run + rod + "young_modulus = inf\n", "rods.1.young_modulus: must be a finite number > 0"},
      {run + rod + "omega = nan\n", "rods.1.omega: must be finite"},
      {run + rod + "base = [0.0, inf, 0.0]\n", "rods.1.base: must be finite"},
      {run + "[gravity]\nacceleration = [0.0, 0.0, nan]\n" + rod, "gravity.acceleration: must be finite"},
      {run + "[fluid]\nviscosity = nan\n" + rod, "fluid.viscosity: must be a finite number > 0"},
      {run + "[solver]\ndamping = inf\n" + rod, "solver.damping: must be a finite number ≥ 0"},
  });
}

TEST(BadInput, ZeroOrNegativeLengthsAndModuliAndTooFewNodesAreRefused) {
  const std::string run = kRun, rod = kRod;
  ExpectErrors({
      {run + rod + "radius = 0.0\n", "rods.1.radius: must be a finite number > 0 (got 0)"},
      {run + rod + "young_modulus = -1e6\n", "rods.1.young_modulus: must be a finite number > 0"},
      {run + rod + "density = 0\n", "rods.1.density: must be a finite number > 0 (got 0)"},
      {run + "[[rods]]\naxis_length = 0.0\n", "rods.1.axis_length: must be a finite number > 0"},
      {run + "[[rods]]\npitch = -0.01\n", "rods.1.pitch: must be a finite number > 0"},
      {run + "[[rods]]\nhelix_radius = 0.0\n", "rods.1.helix_radius: must be a finite number > 0"},
      {run + "[fluid]\nviscosity = 0.0\n" + rod, "fluid.viscosity: must be a finite number > 0"},
      {run + "[[rods]]\nnodes = 4\n", "rods.1.nodes: must be between 5"},
      {run + "[[rods]]\nshape = \"straight\"\nnodes = 2\n", "rods.1.nodes: must be between 3"},
      {run + "[[rods]]\nshape = \"points\"\npoints = [[0, 0, 0], [0, 0, -0.1]]\n",
       "rods.1.points: shape = \"points\" needs at least 3 points"},
      // Found by the fuzzer (tests/data/fuzz/crash_points_turn_back.toml): a 180° turn.
      {run + "[[rods]]\nshape = \"points\"\npoints = [[1, 0, 0], [0.01, 0, 0], [0.02, 0, 0]]\n",
       "rods.1.points[2]: turns the rod back on itself"},
      // Found by the fuzzer (crash_points_far_node.toml): an edge whose length overflows.
      {run + "[[rods]]\nshape = \"points\"\npoints = [[1, 0, 0], [0.01, 0, 0], [0.02, 0, 1.1e297]]\n",
       "rods.1.points[2]: node 2 at (0.02, 0, 1.1e+297) lies outside ±1e+100 m"},
      // A node so far out that the edges lose their digits; the same for a generated shape.
      {run + "[[rods]]\nshape = \"points\"\npoints = [[1, 0, 0], [0, 0, 0], [0, 0, 1e9]]\n",
       "rods.1.points[2]: node 2 lies 1e+09 m from the origin, more than 1e+08 times edge 0 (1 m)"},
      {run + "[[rods]]\nshape = \"straight\"\nbase = [1e30, 0, 0]\n",
       "rods.1.base: node 0 lies 1e+30 m from the origin"},
      {run + "[[rods]]\nshape = \"straight\"\naxis_length = 1e200\n",
       "rods.1.axis_length: node 1 at (0, 0, -1.5625e+198) lies outside ±1e+100 m"},
      {run + "[[rods]]\nshape = \"points\"\npoints = [[0, 0, 0], [0, 0, nan], [0, 0, 1]]\n",
       "rods.1.points[1]: node 1 at (0, 0, nan) lies outside ±1e+100 m"},
  });
}

TEST(BadInput, RodsOverlappingThemselvesAtTheStartAreRefused) {
  const std::string run = kRun;
  ExpectErrors({
      // The rod is thicker than its helix is wide: it overlaps itself (not a Newton failure).
      {run + "[[rods]]\nradius = 0.012\nhelix_radius = 0.01\n",
       "case.toml: rods.1.radius: rod 1 overlaps itself: its radius 0.012 m is not smaller than "
       "helix_radius 0.01 m"},
      // Turns closer than the rod's diameter.
      {run + "[[rods]]\nradius = 0.004\npitch = 0.006\nnodes = 401\n",
       "case.toml: rods.1.pitch: rod 1 overlaps itself at the start"},
      // A polyline that folds back onto itself.
      {run + "[[rods]]\nshape = \"points\"\nradius = 0.001\nclamped_nodes = 0\n"
             "points = [[0, 0, 0], [0.01, 0, 0], [0.02, 0, 0], [0.02, 0.01, 0], [0.01, 0.0005, 0], "
             "[0.0, 0.0005, 0]]\n",
       "rods.1.points: rod 1 overlaps itself at the start"},
      {run + "[[rods]]\n[[rods]]\nbase = [0.001, 0, 0]\n",
       "case.toml: rods.2.base: rod 2 overlaps rod 1 at the start"},
  });
}

TEST(BadInput, OverridesOfRodsThatDoNotExistAreRefused) {
  const std::string text = std::string(kRun) + kRod;
  // Found by the fuzzer's first look at --set: a rod number past unsigned long threw
  // std::out_of_range (an abort in the command line).
  EXPECT_NE(ErrorOf(text, {"rods.99999999999999999999999.radius=1"})
                .find("rods.99999999999999999999999.radius: rod 99999999999999999999999 does not exist"),
            std::string::npos);
  EXPECT_NE(ErrorOf(text, {"rods.0.radius=1"}).find("rod 0 does not exist (there are 1)"),
            std::string::npos);
}

TEST(BadInput, TomlSyntaxErrorsGiveLineAndColumn) {
  ExpectErrors({
      {"[run]\nduration = 1.0\ntime_step = 0.01\n[[rods]]\nnodes = = 3\n", "case.toml: line 5, column"},
      {"[run\n", "case.toml: line 1, column"},
      {"[run]\nduration = 1.0.0\n", "case.toml: line 2, column"},
  });
}

// The node count the LSBT check suggests must itself pass the check (it suggested N = 87 for a
// helix and then refused 87: the arc length over 2δ ignores how the helix's lead-in spacing
// depends on N).
TEST(BadInput, TheLsbtNodeSuggestionFits) {
  const std::vector<std::string> helices = {
      "",                                            // the paper's helix
      "helix_radius = 0.005\npitch = 0.02\n",
      "radius = 0.0015\naxis_length = 0.15\n",
      "radius = 0.0005\nhelix_radius = 0.004\npitch = 0.03\naxis_length = 0.1\n",
  };
  const std::regex suggestion("nodes = ([0-9]+) fits");
  for (const std::string& helix : helices) {
    const std::string text = std::string(kRun) + "[fluid]\nmodel = \"lsbt\"\n[[rods]]\nnodes = 30\n" + helix;
    const std::string error = ErrorOf(text);
    std::smatch m;
    ASSERT_TRUE(std::regex_search(error, m, suggestion)) << helix << "\n" << error;
    const std::string n = m[1];
    EXPECT_EQ(ErrorOf(text, {"rods.nodes=" + n}), "") << helix << "suggested N = " << n;
  }
}

}  // namespace
}  // namespace stokesrods
