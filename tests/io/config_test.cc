#include "stokesrods/io/config.h"

#include <gtest/gtest.h>

#include "stokesrods/io/build_model.h"

namespace stokesrods {
namespace {

constexpr char kTwoHelices[] = R"(
[run]
duration = 1.0
[[rods]]
omega_bar = 320
[[rods]]
base = [0.03, 0.0, 0.0]
omega_bar = 320
)";

// The error message of parsing `text`, or "" if it parsed.
std::string ErrorOf(const std::string& text, const std::vector<std::string>& overrides = {}) {
  try {
    BuildModel(ParseConfig(text, "case.toml", overrides));
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(Config, DefaultsAreThePapersHelix) {
  const Config c = ParseConfig(kTwoHelices, "case.toml");
  ASSERT_EQ(c.rods.size(), 2u);
  EXPECT_EQ(c.rods[0].shape, "helix");
  EXPECT_EQ(c.rods[0].nodes, 65);
  EXPECT_DOUBLE_EQ(c.rods[0].radius, 1e-3);
  EXPECT_DOUBLE_EQ(c.rods[0].young_modulus, 10e6);
  EXPECT_DOUBLE_EQ(c.fluid.regularization, 1.02);
  EXPECT_EQ(c.fluid.model, "rss");
  EXPECT_EQ(c.fluid.coupling, "implicit");
  EXPECT_EQ(c.run.output, "out/stokesrods");
  const Model m = BuildModel(c);
  // ω̄ = 320 ↔ 15 rpm for the paper's helix (Fig. 1).
  EXPECT_NEAR(m.rods[0].omega * 60.0 / (2.0 * kPi), 15.0, 0.02);
}

TEST(Config, ErrorsNameTheFileTheKeyAndTheProblem) {
  struct Case {
    std::string text, expected;
  };
  const std::vector<Case> cases = {
      {"[[rods]]\nradiuss = 1e-3\n", "case.toml: rods.1.radiuss: unknown key"},
      {"[[rods]]\nradius = \"big\"\n", "case.toml: rods.1.radius: expected a number, got string"},
      {"[[rods]]\nradius = -1.0\n", "case.toml: rods.1.radius: must be a finite number > 0"},
      {"[[rods]]\npoisson_ratio = 0.6\n", "rods.1.poisson_ratio: must lie in (−1, 0.5]"},
      {"[[rods]]\nshape = \"straight\"\nnodes = 2\n", "rods.1.nodes: must be between 3"},
      {"[[rods]]\nclamped_nodes = 3\n", "rods.1.clamped_nodes: must be between 0 and 2"},
      {"[[rods]]\nomega = 1.0\nomega_bar = 2.0\n", "rods.1.omega_bar: give omega or omega_bar"},
      {"[[rods]]\nclamped_nodes = 1\nomega = 1.0\n", "rods.1.omega: a rotation needs clamped_nodes = 2"},
      {"[run]\nduration = 1.0\nt_bar_end = 1.0\n[[rods]]\n", "run.duration: a dynamic run needs exactly one"},
      {"[run]\n[[rods]]\n", "run.duration: a dynamic run needs exactly one"},
      {"[run]\nmode = \"static\"\n[fluid]\nmodel = \"lbm\"\n[[rods]]\n", "fluid.model: \"lbm\" is not one of"},
      {"[run]\nmode = \"static\"\n", "rods: missing"},
      {"[runn]\n[[rods]]\n", "case.toml: runn: unknown section"},
      {"[run]\nmode = \"static\"\n[[rods]]\nloads = [{node = 65, force = [0,0,1]}]\n",
       "rods.1.loads[0].node: must be between 0 and 64"},
      {"[run]\nmode = \"static\"\n[[rods]]\nbase = [1, 2]\n", "rods.1.base: expected an array of 3 numbers"},
      {"[run]\nmode = \"static\"\n[[rods]]\n[[rods]]\nbase = [0.001, 0, 0]\n",
       "case.toml: rods.2.base: rod 2 overlaps rod 1 at the start"},
      {"[run\n", "case.toml: line 1, column 5:"},
  };
  for (const Case& c : cases) {
    // Rod-level cases get a valid [run] so that the rod's own error is the first one.
    const bool has_run = c.text.find("[run") != std::string::npos ||
                         c.text.find("[runn]") != std::string::npos ||
                         c.text.find("[fluid]") != std::string::npos;
    const std::string text = has_run ? c.text : "[run]\nmode = \"static\"\n" + c.text;
    const std::string error = ErrorOf(text);
    EXPECT_NE(error.find(c.expected), std::string::npos)
        << "input:\n" << text << "\nerror: " << error << "\nexpected: " << c.expected;
  }
}

TEST(Config, SetOverridesOneKeyOnEveryRodOrOnOne) {
  const Config all = ParseConfig(kTwoHelices, "case.toml", {"rods.omega_bar=533"});
  EXPECT_DOUBLE_EQ(*all.rods[0].omega_bar, 533.0);
  EXPECT_DOUBLE_EQ(*all.rods[1].omega_bar, 533.0);
  const Config one = ParseConfig(kTwoHelices, "case.toml",
                                 {"rods.2.omega_bar=100", "run.time_step=5e-4", "fluid.model=none",
                                  "rods.2.base=[0.06, 0.0, 0.0]"});
  EXPECT_DOUBLE_EQ(*one.rods[0].omega_bar, 320.0);
  EXPECT_DOUBLE_EQ(*one.rods[1].omega_bar, 100.0);
  EXPECT_DOUBLE_EQ(one.run.time_step, 5e-4);
  EXPECT_EQ(one.fluid.model, "none");
  EXPECT_DOUBLE_EQ(one.rods[1].base.x(), 0.06);
  EXPECT_NE(ErrorOf(kTwoHelices, {"rods.3.radius=1"}).find("rod 3 does not exist"),
            std::string::npos);
  EXPECT_NE(ErrorOf(kTwoHelices, {"run.time_step"}).find("--set expects KEY=VALUE"),
            std::string::npos);
  EXPECT_NE(ErrorOf(kTwoHelices, {"run.time_stepp=1"}).find("run.time_stepp: unknown key"),
            std::string::npos);
}

TEST(Config, TheResolvedConfigurationReadsBackToItself) {
  const Config c = ParseConfig(kTwoHelices, "case.toml", {"rods.2.omega_bar=100"});
  const std::string text = ConfigToToml(c);
  const Config again = ParseConfig(text, "resolved.toml");
  EXPECT_EQ(ConfigToToml(again), text);
  EXPECT_NE(ConfigToJson(c).find("\"omega_bar\" : 100"), std::string::npos) << ConfigToJson(c);
}

}  // namespace
}  // namespace stokesrods
