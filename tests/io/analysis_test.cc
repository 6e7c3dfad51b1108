// Derived results: crossing time, buckling rule, F̄p averages, critical values along sweep lines
// and the bisection cases, on hand-made timeseries whose answers are known.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "stokesrods/io/analysis.h"
#include "stokesrods/io/sweep.h"
#include "common/scratch_dir.h"

namespace stokesrods {
namespace {

namespace fs = std::filesystem;

fs::path RunDir(const std::string& name, const std::string& csv) {
  const fs::path dir = testing::ScratchPath("stokesrods_analysis_test") / name;
  fs::create_directories(dir);
  std::ofstream(dir / "timeseries.csv") << csv;
  std::ofstream(dir / "summary.json")
      << "{\"status\": \"completed\", \"derived\": {\"omega_bar\": [213.0, 213.0]},"
         " \"config\": {\"rods\": [{\"helix_radius\": 0.01}]}}";
  return dir;
}

TEST(Analysis, CrossingTimeIsInterpolatedAndTheFinalSignDecides) {
  // Δb: 0.04, 0.02, −0.02, 0.01 at t̄ = 0, 1, 2, 3: first ≤ 0 at t̄ = 1.5; uncrossed at the end.
  const std::string header =
      "t_bar,rod1_length_bar,rod1_tip_axis_distance,propulsive_force_bar,delta_b,delta_b_over_R,min_distance\n";
  const fs::path a = RunDir("a", header + "0,1,0.01,0,0.04,4,0.03\n1,1,0.01,1,0.02,2,0.02\n"
                                          "2,1,0.01,3,-0.02,-2,0.01\n3,1.02,0.01,5,0.01,1,0.015\n");
  const RunAnalysis ra = AnalyzeRun(a.string());
  ASSERT_TRUE(ra.first_crossing_t_bar.has_value());
  EXPECT_DOUBLE_EQ(*ra.first_crossing_t_bar, 1.5);
  EXPECT_FALSE(*ra.crossed);
  EXPECT_DOUBLE_EQ(*ra.min_distance, 0.01);
  EXPECT_DOUBLE_EQ(*ra.final_delta_b_over_r, 1.0);
  EXPECT_DOUBLE_EQ(ra.propulsive_force_bar_mean, 4.0);  // rows at t̄ ≥ 1.5: 3 and 5
  EXPECT_DOUBLE_EQ(ra.propulsive_force_bar_final, 5.0);
  EXPECT_DOUBLE_EQ(ra.final_length_bar, 1.02);
  EXPECT_DOUBLE_EQ(ra.omega_bar, 213.0);
  EXPECT_FALSE(ra.buckled);
  EXPECT_EQ(Outcome(ra, "crossed"), std::optional<bool>(false));
  EXPECT_EQ(Outcome(ra, "ever_crossed"), std::optional<bool>(true));  // crossed at t̄ = 1.5
  const fs::path never = RunDir("never", header + "0,1,0.01,0,0.04,4,0.03\n1,1,0.01,1,0.001,0.1,0.02\n");
  EXPECT_EQ(Outcome(AnalyzeRun(never.string()), "ever_crossed"), std::optional<bool>(false));
}

TEST(Analysis, BuckledWhenTheTipLeavesTwoRadiiInTheLastFifth) {
  const std::string header = "t_bar,rod1_length_bar,rod1_tip_axis_distance,propulsive_force_bar\n";
  // 0.05 m off the axis early (t̄ = 0.5 < 0.8 of the run) does not count; 0.021 at the end does.
  const RunAnalysis early = AnalyzeRun(RunDir("b", header + "0,1,0.01,0\n0.5,1,0.05,0\n1,1,0.01,0\n").string());
  EXPECT_FALSE(early.buckled);
  EXPECT_FALSE(early.crossed.has_value());  // one rod
  EXPECT_FALSE(Outcome(early, "ever_crossed").has_value());
  const RunAnalysis late = AnalyzeRun(RunDir("c", header + "0,1,0.01,0\n0.5,1,0.01,0\n1,1,0.021,0\n").string());
  EXPECT_TRUE(late.buckled);
  EXPECT_DOUBLE_EQ(late.max_tip_axis_distance_over_r, 2.1);
}

Sweep LineSweep() {
  Sweep s;
  s.output = "out";
  for (const char* dt : {"3", "8"})
    for (const char* w : {"100", "200", "300", "400"})
      s.cases.push_back(MakeSweepCase(s, "", {{"rods.omega_bar", w}, {"dt", dt}}));
  return s;
}

TEST(Analysis, CriticalValueIsBracketedOnEachLine) {
  const Sweep s = LineSweep();
  // dt = 3: no, no, yes, yes -> (200, 300]; dt = 8: yes, no, no, no -> above 400, not monotone.
  const std::vector<std::optional<bool>> outcomes = {false, false, true, true, true, false, false, false};
  const auto lines = CriticalAlongLines(s, "rods.omega_bar", outcomes);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0].fixed[0].second, "3");
  EXPECT_DOUBLE_EQ(*lines[0].below, 200.0);
  EXPECT_DOUBLE_EQ(*lines[0].above, 300.0);
  EXPECT_TRUE(lines[0].monotone);
  EXPECT_FALSE(lines[1].above.has_value());
  EXPECT_DOUBLE_EQ(*lines[1].below, 400.0);
  EXPECT_FALSE(lines[1].monotone);
  // Unfinished cases are left out: the bracket widens to what is known.
  const auto partial = CriticalAlongLines(s, "rods.omega_bar", {false, std::nullopt, true});
  EXPECT_DOUBLE_EQ(*partial[0].below, 100.0);
  EXPECT_DOUBLE_EQ(*partial[0].above, 300.0);
}

TEST(Analysis, RefinementAddsTheMiddleOfWideBracketsOnce) {
  Sweep s = LineSweep();
  const std::vector<std::optional<bool>> outcomes = {false, false, true, true, false, false, false, false};
  const auto lines = CriticalAlongLines(s, "rods.omega_bar", outcomes);
  const auto added = RefinementCases(s, "rods.omega_bar", lines, 60.0);
  ASSERT_EQ(added.size(), 1u);  // dt = 8 never switches
  EXPECT_EQ(added[0].values[0], (std::pair<std::string, std::string>{"rods.omega_bar", "250"}));
  EXPECT_EQ(added[0].values[1].second, "3");
  EXPECT_TRUE(RefinementCases(s, "rods.omega_bar", lines, 100.0).empty());  // narrow enough
  s.cases.push_back(added[0]);
  EXPECT_TRUE(RefinementCases(s, "rods.omega_bar", lines, 60.0).empty());  // exists already
}

// Two explicit cases with the same values but different names are two lines; each is bisected in
// its own folders (the middle takes its line's name).
TEST(Analysis, RefinementKeepsEachLinesName) {
  Sweep s;
  s.output = "out";
  for (const char* name : {"left", "right"})
    for (const char* w : {"100", "200"}) s.cases.push_back(MakeSweepCase(s, name, {{"rods.omega_bar", w}}));
  const auto lines = CriticalAlongLines(s, "rods.omega_bar", {false, true, false, true});
  const auto added = RefinementCases(s, "rods.omega_bar", lines, 60.0);
  ASSERT_EQ(added.size(), 2u);
  EXPECT_EQ(added[0].name, "left__omega_bar=150");
  EXPECT_EQ(added[1].name, "right__omega_bar=150");
}

}  // namespace
}  // namespace stokesrods
