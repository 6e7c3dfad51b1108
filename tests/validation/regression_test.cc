// Regression: a tiny two-helix case (RSS, implicit, contact on), 100 steps, against its stored final
// row (tests/data/regression_two_helices.csv). The tolerances are about ten times the change that
// a tenfold change of the Newton tolerance makes to the same run (measured: positions 1.2e-11 m,
// Δb/R 4.9e-10, clamp forces 4.6e-13 N, torques 4e-15 N m): a change of physics or numerics shows.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <sstream>

#include "common/cell_toml.h"
#include "common/model_from_toml.h"
#include "stokesrods/sim/integrator.h"
#include "stokesrods/sim/observables.h"

namespace stokesrods {
namespace {

const std::string kCase = R"(
[run]
duration = 1.0
time_step = 0.01
[fluid]
model = "rss"
[contact]
enabled = true
)" + testing::HelixToml(15, 0.0, "omega_bar = 300") +
                            testing::HelixToml(15, 0.0175, "omega_bar = 300");

std::map<std::string, double> ReadReference() {
  std::ifstream in(std::string(STOKESRODS_SOURCE_DIR) + "/tests/data/regression_two_helices.csv");
  std::map<std::string, double> values;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#' || line.rfind("column,", 0) == 0) continue;
    const auto comma = line.find(',');
    values[line.substr(0, comma)] = std::stod(line.substr(comma + 1));
  }
  return values;
}

TEST(Regression, TwoHelicesFinalRowMatchesTheStoredOne) {
  const Model model = testing::ModelFromToml(kCase);
  State state = MakeRestState(model);
  Workspace ws(model);
  StepReport report;
  for (int k = 0; k < 100; ++k) {
    report = Step(model, 0.01, &state, &ws);
    ASSERT_TRUE(report.ok) << report.message;
  }
  const std::vector<std::string> columns = TimeseriesColumns(model);
  const std::vector<double> row = CalcTimeseriesRow(model, state, ws, report);
  const std::map<std::string, double> reference = ReadReference();
  ASSERT_EQ(reference.size(), 12u);
  for (const auto& [name, expected] : reference) {
    const auto it = std::find(columns.begin(), columns.end(), name);
    ASSERT_NE(it, columns.end()) << name;
    const double value = row[static_cast<std::size_t>(it - columns.begin())];
    const double tolerance = name.find("torque") != std::string::npos  ? 5e-14
                             : name.find("force") != std::string::npos ? 5e-12
                             : name == "delta_b_over_R"                ? 5e-9
                                                                       : 1.5e-10;
    EXPECT_NEAR(value, expected, tolerance) << name;
  }
}

}  // namespace
}  // namespace stokesrods
