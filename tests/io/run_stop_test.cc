// run.stop_when_buckled: a run stops at the first output row where rod 1 has buckled by analyze's
// rule, on the trajectory the full run takes, and a helix that stays helical runs to the end.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "stokesrods/io/analysis.h"
#include "stokesrods/io/config.h"
#include "stokesrods/io/runner.h"
#include "common/scratch_dir.h"

namespace stokesrods {
namespace {

namespace fs = std::filesystem;

// summary.json's physics: its final row, message and counts (not the process's wall time).
std::string ReadSummaryFinal(const std::string& dir) {
  std::ifstream in(dir + "/summary.json");
  nlohmann::json s = nlohmann::json::parse(in);
  return nlohmann::json{{"final", s["final"]}, {"message", s["message"]}, {"steps", s["steps"]},
                        {"newton_iterations", s["newton_iterations"]},
                        {"max_penetration", s["max_penetration"]}}.dump();
}

// The paper's helix, coarse (N = 25, h = 20 ms) for a test of seconds.
// Steps that fail are halved: after the buckling the full run needs it, and a step that succeeds
// is the same step with or without the option.
RunResult RunHelix(const std::string& name, double omega_bar, bool stop, double t_bar_end,
                   bool resume = false) {
  const fs::path dir = testing::ScratchPath("stokesrods_run_stop_test") / name;
  if (!resume) fs::remove_all(dir);
  const Config config = LoadConfig(
      std::string(STOKESRODS_SOURCE_DIR) + "/examples/helix.toml",
      {"run.output=\"" + dir.string() + "\"", "run.t_bar_end=" + std::to_string(t_bar_end), "run.time_step=0.02",
       "run.integrator=\"bdf2\"", "run.output_interval=0.2", "run.frames=false", "rods.nodes=25", "solver.max_step_halvings=3",
       "rods.omega_bar=" + std::to_string(omega_bar),
       std::string("run.stop_when_buckled=") + (stop ? "true" : "false")});
  RunOptions options;
  options.resume = resume;
  return RunCase(config, options);
}

TEST(RunStop, ABuckledHelixStopsOnTheFullRunsTrajectory) {
  const RunResult stopped = RunHelix("stopped", 2500.0, true, 0.03);
  const RunResult full = RunHelix("full", 2500.0, false, 0.03);
  ASSERT_EQ(stopped.status, RunStatus::kCompleted) << stopped.message;
  ASSERT_EQ(full.status, RunStatus::kCompleted) << full.message;
  EXPECT_NE(stopped.message.find("buckled"), std::string::npos) << stopped.message;
  EXPECT_LT(stopped.steps, full.steps);
  const auto a = ReadTimeseries(stopped.output_dir + "/timeseries.csv");
  const auto b = ReadTimeseries(full.output_dir + "/timeseries.csv");
  const std::vector<double>& tip = a.at("rod1_tip_axis_distance");
  ASSERT_LT(tip.size(), b.at("rod1_tip_axis_distance").size());
  for (std::size_t i = 0; i < tip.size(); ++i)
    EXPECT_EQ(tip[i], b.at("rod1_tip_axis_distance")[i]) << "row " << i;
  // It stops at the first row past 2R, and analyze calls the stopped run buckled.
  EXPECT_GT(tip.back(), 2.0 * 0.01);
  for (std::size_t i = 0; i + 1 < tip.size(); ++i) EXPECT_LE(tip[i], 2.0 * 0.01) << "row " << i;
  EXPECT_TRUE(AnalyzeRun(stopped.output_dir).buckled);
}

TEST(RunStop, AStoppedRunResumedStopsAgainWhereItStopped) {
  // Its checkpoint is at the row that stopped it: the resumed run (e.g. after a kill before the
  // summary was written) takes no further step and writes the same summary.
  const RunResult stopped = RunHelix("again", 2500.0, true, 0.03);
  ASSERT_NE(stopped.message.find("buckled"), std::string::npos) << stopped.message;
  const std::string dir = stopped.output_dir;
  const auto rows = ReadTimeseries(dir + "/timeseries.csv").at("t_bar").size();
  const std::string summary = ReadSummaryFinal(dir);
  fs::remove(fs::path(dir) / "summary.json");
  const RunResult resumed = RunHelix("again", 2500.0, true, 0.03, /*resume=*/true);
  EXPECT_EQ(resumed.message, stopped.message);
  EXPECT_EQ(resumed.steps, stopped.steps);
  EXPECT_EQ(ReadTimeseries(dir + "/timeseries.csv").at("t_bar").size(), rows);
  EXPECT_EQ(ReadSummaryFinal(dir), summary);
}

TEST(RunStop, AHelixThatStaysHelicalRunsToTheEnd) {
  const RunResult stable = RunHelix("stable", 300.0, true, 0.05);
  ASSERT_EQ(stable.status, RunStatus::kCompleted) << stable.message;
  EXPECT_EQ(stable.message, "");
  EXPECT_FALSE(AnalyzeRun(stable.output_dir).buckled);
  const auto rows = ReadTimeseries(stable.output_dir + "/timeseries.csv");
  EXPECT_GE(rows.at("t_bar").back(), 0.05 - 1e-9);
}

TEST(RunStop, NeedsAHelixAsRodOne) {
  EXPECT_THROW(ParseConfig("[run]\nduration = 1.0\nstop_when_buckled = true\n[[rods]]\n"
                           "shape = \"straight\"\nnodes = 5\n",
                           "c.toml"),
               ConfigError);
}

}  // namespace
}  // namespace stokesrods
