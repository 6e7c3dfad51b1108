// The sweep file: expansion into cases, the checks of bad files, and what a rerun skips.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>

#include "stokesrods/io/config.h"
#include "stokesrods/io/sweep.h"

#include "common/scratch_dir.h"

namespace stokesrods {
namespace {

namespace fs = std::filesystem;

const char* kBase =
    "[run]\nduration = 0.05\ntime_step = 0.01\nframes = false\n[fluid]\nmodel = \"none\"\n"
    "[[rods]]\nnodes = 11\nomega_bar = 100\n[[rods]]\nnodes = 11\nbase = [0.04, 0.0, 0.0]\n"
    "omega_bar = 100\n";

fs::path Dir() {
  const fs::path dir = testing::ScratchPath("stokesrods_sweep_test");
  fs::create_directories(dir);
  std::ofstream(dir / "base.toml") << kBase;
  return dir;
}

Sweep Parse(const std::string& text) {
  return ParseSweep("base = \"base.toml\"\noutput = \"" + (Dir() / "out").string() + "\"\n" + text,
                    "s.toml", Dir().string());
}

std::string ErrorOf(const std::string& text) {
  try {
    Parse(text);
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.file(), "s.toml");
    return e.key() + " | " + e.what();
  }
  return "no error";
}

TEST(Sweep, VaryIsTheCartesianProductWithTheLastKeyFastest) {
  const Sweep s = Parse("[vary]\n\"rods.omega_bar\" = [43, 107]\n"
                        "\"rods.2.base\" = [[0.04, 0.0, 0.0], [0.06, 0.0, 0.0], [0.08, 0.0, 0.0]]\n");
  ASSERT_EQ(s.cases.size(), 6u);
  EXPECT_EQ(s.varied_keys, (std::vector<std::string>{"rods.omega_bar", "rods.2.base"}));
  EXPECT_EQ(s.cases[0].values[0].second, "43");
  EXPECT_EQ(s.cases[1].values[1].second, "[0.06, 0.0, 0.0]");
  EXPECT_EQ(s.cases[3].values[0].second, "107");
  EXPECT_EQ(s.cases[3].values[1].second, "[0.04, 0.0, 0.0]");
  EXPECT_EQ(s.cases[0].name, "rod2.base=_0.04_0.0_0.0___omega_bar=43");  // keys sorted
  EXPECT_EQ(s.cases[0].output_dir, (Dir() / "out" / s.cases[0].name).string());
  // The overrides give the configuration the case stands for.
  const Config c = LoadConfig(s.base, s.cases[5].overrides);
  EXPECT_DOUBLE_EQ(*c.rods[0].omega_bar, 107.0);
  EXPECT_DOUBLE_EQ(*c.rods[1].omega_bar, 107.0);
  EXPECT_DOUBLE_EQ(c.rods[1].base.x(), 0.08);
  EXPECT_DOUBLE_EQ(c.rods[0].base.x(), 0.0);
}

TEST(Sweep, FolderNamesDoNotDependOnTheOrderOfKeysOrValues) {
  const Sweep a = Parse("[vary]\n\"rods.omega_bar\" = [43, 107]\n\"run.time_step\" = [0.01, 0.02]\n");
  const Sweep b = Parse("[vary]\n\"run.time_step\" = [0.02, 0.01]\n\"rods.omega_bar\" = [107, 43]\n");
  std::set<std::string> names_a, names_b;
  for (const SweepCase& c : a.cases) names_a.insert(c.name);
  for (const SweepCase& c : b.cases) names_b.insert(c.name);
  EXPECT_EQ(names_a, names_b);
  EXPECT_EQ(names_a.size(), 4u);
  EXPECT_EQ(b.cases[0].values[0].first, "run.time_step");  // columns keep the file's order
}

TEST(Sweep, ExplicitCasesTimesVaryWithFixedSettings) {
  const Sweep s = Parse("[set]\n\"run.time_step\" = 0.02\nfluid.model = \"rft\"\n"
                        "[vary]\nrods.omega_bar = [1, 2, 3]\n"
                        "[[cases]]\nname = \"near\"\n\"rods.2.base\" = [0.04, 0.0, 0.0]\n"
                        "[[cases]]\nname = \"far\"\n\"rods.2.base\" = [1.0, 0.0, 0.0]\n");
  ASSERT_EQ(s.cases.size(), 6u);
  EXPECT_EQ(s.varied_keys, (std::vector<std::string>{"rods.2.base", "rods.omega_bar"}));
  EXPECT_EQ(s.cases[4].name.rfind("far__", 0), 0u) << s.cases[4].name;
  const Config c = LoadConfig(s.base, s.cases[4].overrides);
  EXPECT_DOUBLE_EQ(c.run.time_step, 0.02);
  EXPECT_EQ(c.fluid.model, "rft");
  EXPECT_DOUBLE_EQ(c.rods[1].base.x(), 1.0);
  EXPECT_DOUBLE_EQ(*c.rods[0].omega_bar, 2.0);
  EXPECT_EQ(Parse("").cases.size(), 1u);  // no vary, no cases: the base alone
}

TEST(Sweep, BadFilesNameTheKeyAndTheProblem) {
  EXPECT_NE(ErrorOf("[vary]\n\"rods.omega_bar\" = 5\n").find("vary.rods.omega_bar | "), std::string::npos);
  EXPECT_NE(ErrorOf("[vary]\n\"rods.omega_bar\" = []\n").find("non-empty list"), std::string::npos);
  EXPECT_NE(ErrorOf("frobnicate = 1\n").find("frobnicate | "), std::string::npos);
  const std::string unknown = ErrorOf("[vary]\n\"rods.omega_barr\" = [1]\n");
  EXPECT_NE(unknown.find("omega_barr"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("case omega_barr=1"), std::string::npos) << unknown;
  EXPECT_NE(ErrorOf("[vary]\n\"rods.3.omega_bar\" = [1]\n").find("rod 3 does not exist"), std::string::npos);
  EXPECT_NE(ErrorOf("[vary]\n\"rods.nodes\" = [1]\n").find("case nodes=1"), std::string::npos);
  EXPECT_NE(ErrorOf("[vary]\n\"rods.omega_bar\" = [1, 1]\n").find("duplicate case"), std::string::npos);
  const std::string refine = "[vary]\n\"rods.omega_bar\" = [1, 2]\n[refine]\nkey = \"rods.omega_bar\"\n"
                             "resolution = 0.5\ncriterion = ";
  EXPECT_NE(ErrorOf(refine + "\"fast\"\n").find("\"ever_crossed\""), std::string::npos);
  EXPECT_EQ(Parse(refine + "\"ever_crossed\"\n").refine->criterion, "ever_crossed");
  try {
    ParseSweep("base = \"missing.toml\"\noutput = \"x\"\n", "s.toml", Dir().string());
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "base");
  }
}

// [[adjust]] sets keys in the matching cases only; the others keep the very overrides they had
// without it (so their finished runs still count), and no folder name moves.
TEST(Sweep, AdjustSetsKeysInTheMatchingCasesOnly) {
  const std::string grid = "[vary]\n\"rods.omega_bar\" = [43, 107]\n\"run.time_step\" = [0.01, 0.02]\n"
                           "[refine]\nkey = \"rods.omega_bar\"\ncriterion = \"crossed\"\nresolution = 1.0\n";
  const Sweep plain = Parse(grid);
  const Sweep s = Parse(grid + "[[adjust]]\nwhere = { \"rods.omega_bar\" = 107.0, \"run.time_step\" = 0.02 }\n"
                               "\"solver.max_step_halvings\" = 4\n\"solver.newton_max_iterations\" = 40\n"
                               "[[adjust]]\nwhere = { \"rods.omega_bar\" = 107 }\n\"solver.max_step_halvings\" = 2\n");
  ASSERT_EQ(s.cases.size(), 4u);
  const int default_iterations = LoadConfig(s.base, {}).solver.newton_max_iterations;
  for (std::size_t i = 0; i < 4; ++i) EXPECT_EQ(s.cases[i].name, plain.cases[i].name);
  EXPECT_EQ(s.cases[0].overrides, plain.cases[0].overrides);  // ω̄ = 43: untouched
  EXPECT_EQ(s.cases[1].overrides, plain.cases[1].overrides);
  const Config c2 = LoadConfig(s.base, s.cases[2].overrides);  // 107 at h = 0.01: the second entry
  EXPECT_EQ(c2.solver.max_step_halvings, 2);
  EXPECT_EQ(c2.solver.newton_max_iterations, default_iterations);
  const Config c3 = LoadConfig(s.base, s.cases[3].overrides);  // both match: the later one wins
  EXPECT_EQ(c3.solver.max_step_halvings, 2);
  EXPECT_EQ(c3.solver.newton_max_iterations, 40);
  // A refinement case made later matches the same way (75 is on no entry's line of 107).
  const SweepCase mid = MakeSweepCase(s, "", {{"rods.omega_bar", "75"}, {"run.time_step", "0.02"}});
  EXPECT_EQ(mid.overrides, MakeSweepCase(plain, "", {{"rods.omega_bar", "75"}, {"run.time_step", "0.02"}}).overrides);
  // sweep.json keeps the entries.
  WriteSweepJson(s);
  const Sweep read = ReadSweepJson(s.output);
  ASSERT_EQ(read.adjustments.size(), 2u);
  EXPECT_EQ(read.adjustments[0].where, s.adjustments[0].where);
  EXPECT_EQ(read.adjustments[0].overrides, s.adjustments[0].overrides);
}

TEST(Sweep, BadAdjustEntriesNameTheKeyAndTheProblem) {
  const std::string grid = "[vary]\n\"rods.omega_bar\" = [43, 107]\n[[adjust]]\n";
  EXPECT_NE(ErrorOf(grid + "\"solver.max_step_halvings\" = 4\n").find("adjust.where | "), std::string::npos);
  EXPECT_NE(ErrorOf(grid + "where = { \"run.time_step\" = 0.01 }\n\"solver.max_step_halvings\" = 4\n")
                .find("adjust.where.run.time_step | "), std::string::npos);
  EXPECT_NE(ErrorOf(grid + "where = { \"rods.omega_bar\" = 43 }\n\"rods.omega_bar\" = 44\n")
                .find("adjust.rods.omega_bar | "), std::string::npos);
  EXPECT_NE(ErrorOf(grid + "where = { \"rods.omega_bar\" = 43 }\n").find("sets no key"), std::string::npos);
  EXPECT_NE(ErrorOf(grid + "where = { \"rods.omega_bar\" = 44 }\n\"solver.max_step_halvings\" = 4\n")
                .find("entry 1 matches no case"), std::string::npos);
  const std::string bad_key = ErrorOf(grid + "where = { \"rods.omega_bar\" = 43 }\n\"solver.max_halvings\" = 4\n");
  EXPECT_NE(bad_key.find("max_halvings"), std::string::npos) << bad_key;
  EXPECT_NE(bad_key.find("case omega_bar=43"), std::string::npos) << bad_key;
}

TEST(Sweep, ExitCodesMapToStatuses) {
  EXPECT_EQ(MakeCaseRecord(0, 0, 1.0, "").status, "completed");
  EXPECT_EQ(MakeCaseRecord(3, 0, 1.0, "").status, "failed");
  EXPECT_EQ(MakeCaseRecord(130, 0, 1.0, "").status, "interrupted");
  EXPECT_EQ(MakeCaseRecord(4, 0, 1.0, "").status, "error");
  const CaseRecord killed = MakeCaseRecord(0, 11, 1.0, "");
  EXPECT_EQ(killed.status, "crashed");
  EXPECT_EQ(killed.exit_code, 139);
  EXPECT_EQ(MakeCaseRecord(1, 0, 1.0, "").status, "crashed");
  const CaseRecord r = MakeCaseRecord(0, 0, 2.0, "{\"final\": {\"t_bar\": 0.5}, \"message\": \"\"}");
  EXPECT_DOUBLE_EQ(r.final_values["t_bar"].get<double>(), 0.5);
}

TEST(Sweep, ARerunSkipsOnlyCasesMadeFromTheSameConfiguration) {
  const Sweep s = Parse("[vary]\n\"rods.omega_bar\" = [43, 107]\n");
  const SweepCase& c = s.cases[0];
  fs::remove_all(c.output_dir);
  EXPECT_EQ(ReadCaseRecord(s, c).status, "pending");  // never run
  fs::create_directories(c.output_dir);
  std::vector<std::string> overrides = c.overrides;
  overrides.push_back("run.output=\"" + c.output_dir + "\"");
  const std::string same = ConfigToJson(LoadConfig(s.base, overrides));
  const std::string other = ConfigToJson(LoadConfig(s.base, {"rods.omega_bar=44"}));
  auto write_summary = [&](const std::string& status, const std::string& config) {
    std::ofstream(fs::path(c.output_dir) / "summary.json")
        << "{\"status\": \"" << status << "\", \"config\": " << config
        << ", \"final\": {\"t_bar\": 1.0}, \"wall_seconds\": 3.5}";
  };
  write_summary("completed", same);
  const CaseRecord done = ReadCaseRecord(s, c);
  EXPECT_EQ(done.status, "completed");
  EXPECT_DOUBLE_EQ(done.wall_seconds, 3.5);
  write_summary("failed", same);
  EXPECT_EQ(ReadCaseRecord(s, c).status, "failed");
  write_summary("completed", other);
  EXPECT_EQ(ReadCaseRecord(s, c).status, "pending");
  // Written by a version without rods.body (added since, here at its default): still finished.
  nlohmann::json older = nlohmann::json::parse(same);
  for (auto& rod : older["rods"]) rod.erase("body");
  write_summary("completed", older.dump());
  EXPECT_EQ(ReadCaseRecord(s, c).status, "completed");
  write_summary("interrupted", same);
  EXPECT_EQ(ReadCaseRecord(s, c).status, "pending");  // no checkpoint: start again
  std::ofstream(fs::path(c.output_dir) / "checkpoint.bin") << "x";
  EXPECT_TRUE(ReadCaseRecord(s, c).resumable);
}

// The study sweeps users run (examples/studies): every case is a valid configuration, and Fig. 9's
// cases keep what its file promises (Δt/R = 4, the representative helix's edge length).
TEST(Sweep, TheStudySweepsExpandIntoValidCases) {
  const fs::path studies = fs::path(STOKESRODS_SOURCE_DIR) / "examples" / "studies";
  int files = 0;
  for (const auto& entry : fs::directory_iterator(studies)) {
    if (entry.path().extension() != ".toml") continue;
    ++files;
    const Sweep s = LoadSweep(entry.path().string(), (Dir() / "studies").string());
    EXPECT_GT(s.cases.size(), 1u) << entry.path();
    for (const SweepCase& c : s.cases) EXPECT_NO_THROW(LoadConfig(s.base, c.overrides)) << c.name;
  }
  EXPECT_GE(files, 6);
  const Sweep fig9 = LoadSweep((studies / "fig9_pitch_radius.toml").string(), (Dir() / "fig9").string());
  const double kEdge = 0.2 * std::hypot(1.0, 2.0 * M_PI * 0.01 / 0.05) / 64.0;  // N = 65
  for (const SweepCase& c : fig9.cases) {
    const Config config = LoadConfig(fig9.base, c.overrides);
    const RodConfig& rod = config.rods[0];
    EXPECT_DOUBLE_EQ(config.rods[1].base.x(), 4.0 * rod.helix_radius) << c.name;
    EXPECT_EQ(config.rods[1].nodes, rod.nodes) << c.name;
    const double arc = rod.axis_length * std::hypot(1.0, 2.0 * M_PI * rod.helix_radius / rod.pitch);
    EXPECT_NEAR(arc / (rod.nodes - 1), kEdge, 0.02 * kEdge) << c.name;
  }
}

}  // namespace
}  // namespace stokesrods
