// The command line as users and scripts see it: exit codes, messages, and the SPEC output files.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/scratch_dir.h"

namespace {

namespace fs = std::filesystem;

struct Outcome {
  int code = -1;
  std::string err;
};

Outcome RunCli(const std::string& args) {
  // One stderr file per process and call: ctest runs these tests in parallel processes.
  static int calls = 0;
  const fs::path err = fs::temp_directory_path() /
                       ("stokesrods_cli_test." + std::to_string(getpid()) + "." +
                        std::to_string(++calls) + ".err");
  const std::string cmd = std::string(STOKESRODS_BINARY) + " " + args + " > /dev/null 2> " +
                          err.string() + " < /dev/null";
  const int status = std::system(cmd.c_str());
  std::stringstream text;
  {
    std::ifstream in(err);
    text << in.rdbuf();
  }
  fs::remove(err);
  return {WEXITSTATUS(status), text.str()};
}

fs::path WriteConfig(const std::string& name, const std::string& text) {
  const fs::path dir = stokesrods::testing::ScratchPath("stokesrods_cli_test");
  fs::create_directories(dir);
  std::ofstream(dir / name) << text;
  return dir / name;
}

std::string Read(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(Cli, VersionAndHelp) {
  EXPECT_EQ(RunCli("--version").code, 0);
  EXPECT_EQ(RunCli("--help").code, 0);
  EXPECT_EQ(RunCli("run --help").code, 0);
  EXPECT_EQ(RunCli("frobnicate").code, 2);
}

TEST(Cli, ShowConfigPrintsEveryDefaultAndTheDerivedQuantities) {
  const fs::path out = stokesrods::testing::ScratchPath("stokesrods_cli_show");
  const std::string cmd = std::string(STOKESRODS_BINARY) + " show-config " + STOKESRODS_SOURCE_DIR +
                          "/examples/helix.toml --set rods.omega_bar=1067 > " + out.string();
  ASSERT_EQ(WEXITSTATUS(std::system(cmd.c_str())), 0);
  const std::string text = Read(out);
  fs::remove(out);
  for (const char* expected : {"regularization = 1.02", "poisson_ratio = 0.5", "omega_bar = 1067",
                               "\"EI\"", "\"GJ\"", "\"time_scale\"", "\"omega\""})
    EXPECT_NE(text.find(expected), std::string::npos) << expected << "\n" << text;
}

TEST(Cli, CantileverWritesTheSpecFiles) {
  const fs::path out = stokesrods::testing::ScratchPath("stokesrods_cli_cantilever");
  fs::remove_all(out);
  const Outcome o = RunCli(std::string("run ") + STOKESRODS_SOURCE_DIR + "/examples/cantilever.toml --output " + out.string());
  ASSERT_EQ(o.code, 0) << o.err;
  const std::string csv = Read(out / "timeseries.csv");
  EXPECT_EQ(csv.rfind("time,t_bar,rod1_end_x,rod1_end_y,rod1_end_z,rod1_length,rod1_length_bar,"
                      "rod1_force_x,rod1_force_y,rod1_force_z,rod1_torque_z,propulsive_force,"
                      "propulsive_force_bar", 0), 0u) << csv;
  const nlohmann::json summary = nlohmann::json::parse(Read(out / "summary.json"));
  EXPECT_EQ(summary["status"], "completed");
  for (const char* key : {"message", "config", "derived", "final", "max_penetration", "steps",
                          "newton_iterations", "wall_seconds", "version"})
    EXPECT_TRUE(summary.contains(key)) << key;
  EXPECT_TRUE(summary["derived"].contains("EI"));
  EXPECT_TRUE(summary["derived"].contains("time_scale"));
  // The reaction at the clamp balances the tip load (paper eq. 25: elastic + external forces).
  EXPECT_NEAR(summary["final"]["rod1_force_x"].get<double>(), 1e-5, 1e-12);
  EXPECT_TRUE(fs::exists(out / "frames" / "rods_00000.vtp"));
  EXPECT_TRUE(fs::exists(out / "rods.pvd"));
}

TEST(Cli, BadInputIsExitTwoWithFileKeyAndProblem) {
  const fs::path cfg = WriteConfig("bad.toml", "[run]\nmode = \"static\"\n[[rods]]\nradius = -1.0\n");
  const Outcome o = RunCli("run " + cfg.string());
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.err.find("bad.toml: rods.1.radius: must be a finite number > 0"), std::string::npos) << o.err;
  EXPECT_EQ(RunCli("run /nonexistent/case.toml").code, 2);
  EXPECT_EQ(RunCli("run " + cfg.string() + " --set rods.radius=0.001 --set nope").code, 2);
}

TEST(Cli, UnwritableOutputIsExitFour) {
  const fs::path cfg = WriteConfig("static.toml",
                                   "[run]\nmode = \"static\"\noutput = \"/proc/stokesrods/x\"\n"
                                   "[fluid]\nmodel = \"none\"\n[[rods]]\nshape = \"straight\"\n");
  EXPECT_EQ(RunCli("run " + cfg.string()).code, 4);
  // The output directory is an existing file.
  const fs::path file = WriteConfig("not_a_directory", "x");
  const Outcome o = RunCli("run " + cfg.string() + " --output " + file.string());
  EXPECT_EQ(o.code, 4);
  EXPECT_NE(o.err.find("not_a_directory"), std::string::npos) << o.err;
}

TEST(Cli, NumericalFailureIsExitThreeWithTheLastGoodStateSaved) {
  const fs::path out = stokesrods::testing::ScratchPath("stokesrods_cli_failure");
  fs::remove_all(out);
  // One Newton iteration cannot converge a step that starts far from equilibrium.
  const fs::path cfg = WriteConfig(
      "fail.toml", "[run]\nduration = 1.0\ntime_step = 0.5\n[fluid]\nmodel = \"none\"\n"
                   "[solver]\nnewton_max_iterations = 1\n[[rods]]\nshape = \"straight\"\n"
                   "loads = [{node = 64, force = [1.0, 0.0, 0.0]}]\n");
  const Outcome o = RunCli("run " + cfg.string() + " --output " + out.string());
  EXPECT_EQ(o.code, 3) << o.err;
  EXPECT_NE(o.err.find("Newton did not converge at t = 0.5 s"), std::string::npos) << o.err;
  const nlohmann::json summary = nlohmann::json::parse(Read(out / "summary.json"));
  EXPECT_EQ(summary["status"], "failed");
  EXPECT_TRUE(fs::exists(out / "checkpoint.bin"));
}

TEST(Cli, AFailedStepSaysWhenWhereAndWhatAndIsHalvedWhenAllowed) {
  // A loaded straight rod, steps of 0.25 s and at most 10 Newton iterations: the first step
  // fails; halved down to 1/16 of h where needed, every step converges.
  const fs::path cfg = WriteConfig(
      "halve.toml", "[run]\nduration = 1.0\ntime_step = 0.25\n[fluid]\nmodel = \"none\"\n"
                    "[solver]\nnewton_max_iterations = 10\ndamping = 1.0\n[[rods]]\n"
                    "shape = \"straight\"\nnodes = 21\nloads = [{node = 20, force = [1e-3, 0.0, 0.0]}]\n");
  const fs::path out = stokesrods::testing::ScratchPath("stokesrods_cli_halve");
  fs::remove_all(out);
  const Outcome failed = RunCli("run " + cfg.string() + " --output " + out.string());
  EXPECT_EQ(failed.code, 3);
  for (const char* part : {"Newton did not converge at t = 0.25 s", "after 10 iterations",
                           "largest at rod 1, node 20 (a force)", "try a smaller run.time_step",
                           "solver.max_step_halvings", "checkpoint.bin and the last frame"})
    EXPECT_NE(failed.err.find(part), std::string::npos) << part << "\n" << failed.err;
  EXPECT_TRUE(fs::exists(out / "frames" / "rods_00001.vtp"));  // the last good state (t = 0)
  EXPECT_EQ(nlohmann::json::parse(Read(out / "summary.json"))["step_reductions"], 0);

  fs::remove_all(out);
  const Outcome halved = RunCli("run " + cfg.string() + " --output " + out.string() +
                                " --set solver.max_step_halvings=4");
  ASSERT_EQ(halved.code, 0) << halved.err;
  const nlohmann::json summary = nlohmann::json::parse(Read(out / "summary.json"));
  EXPECT_GE(summary["step_reductions"].get<long>(), 1);
  EXPECT_EQ(summary["steps"], 4);
  std::istringstream csv(Read(out / "timeseries.csv"));
  std::vector<std::string> times;
  for (std::string line; std::getline(csv, line);) times.push_back(line.substr(0, line.find(',')));
  EXPECT_EQ(times, (std::vector<std::string>{"time", "0", "0.25", "0.5", "0.75", "1"}));
}

TEST(Cli, AContactFailureSaysWhenWhereAndWhatAndSavesTheLastGoodState) {
  // Rod 1's tip pushed into rod 2, 3 mm away, with one contact round allowed per step: the first
  // step that brings the rods into contact cannot be resolved.
  const fs::path cfg = WriteConfig(
      "contact.toml", "[run]\nduration = 1.0\ntime_step = 0.01\n[fluid]\nmodel = \"none\"\n"
                      "[contact]\nmax_rounds = 1\n[solver]\ndamping = 1.0\n"
                      "[[rods]]\nshape = \"straight\"\nnodes = 21\n"
                      "loads = [{node = 20, force = [1e-3, 0.0, 0.0]}]\n"
                      "[[rods]]\nshape = \"straight\"\nnodes = 21\nbase = [0.003, 0.0, 0.0]\n");
  const fs::path out = stokesrods::testing::ScratchPath("stokesrods_cli_contact");
  fs::remove_all(out);
  const Outcome o = RunCli("run " + cfg.string() + " --output " + out.string());
  EXPECT_EQ(o.code, 3) << o.err;
  for (const char* part : {"contact not resolved at t = ", "after 1 rounds", "the deepest rod 1, segment ",
                           "against rod 2, segment ", "of the contact distance", "contact.max_rounds",
                           "try a smaller run.time_step", "checkpoint.bin and the last frame"})
    EXPECT_NE(o.err.find(part), std::string::npos) << part << "\n" << o.err;
  const nlohmann::json summary = nlohmann::json::parse(Read(out / "summary.json"));
  EXPECT_EQ(summary["status"], "failed");
  // The last good state: the checkpoint resumes, the last frame is at the time before the failure.
  ASSERT_TRUE(fs::exists(out / "checkpoint.bin"));
  const double failed_at = std::stod(o.err.substr(o.err.find("at t = ") + 7));
  const std::string pvd = Read(out / "rods.pvd");
  const std::size_t last = pvd.rfind("timestep=\"");
  ASSERT_NE(last, std::string::npos) << pvd;
  EXPECT_NEAR(std::stod(pvd.substr(last + 10)), failed_at - 0.01, 1e-9) << pvd;
  // With more rounds the same case runs through.
  fs::remove_all(out);
  const Outcome more = RunCli("run " + cfg.string() + " --output " + out.string() +
                              " --set contact.max_rounds=50 --set run.duration=0.05");
  EXPECT_EQ(more.code, 0) << more.err;
}

TEST(Cli, InterruptFlushesWritesACheckpointAndExits130) {
  const fs::path out = stokesrods::testing::ScratchPath("stokesrods_cli_interrupt");
  fs::remove_all(out);
  const fs::path cfg = WriteConfig("long.toml", "[run]\nduration = 1000.0\ntime_step = 0.01\n"
                                                "[fluid]\nmodel = \"rss\"\n[[rods]]\nnodes = 21\n"
                                                "omega_bar = 500\n");
  const std::string cmd = "timeout --preserve-status -s INT 1 " + std::string(STOKESRODS_BINARY) +
                          " run " + cfg.string() + " --output " + out.string() +
                          " > /dev/null 2>&1 < /dev/null";
  const int status = std::system(cmd.c_str());
  EXPECT_EQ(WEXITSTATUS(status), 130);
  const nlohmann::json summary = nlohmann::json::parse(Read(out / "summary.json"));
  EXPECT_EQ(summary["status"], "interrupted");
  EXPECT_GT(summary["steps"].get<long>(), 0);
  EXPECT_TRUE(fs::exists(out / "checkpoint.bin"));
}

TEST(Cli, ResumeContinuesFromTheCheckpointAsIfNeverStopped) {
  // A run of 0.3 s extended to 0.6 s by --resume: the checkpoint at 0.3 s is a restart point
  // (run.checkpoint_interval), so the outputs equal the 0.6 s run's byte for byte.
  const std::string base = "[run]\ntime_step = 0.01\noutput_interval = 0.05\n"
                           "checkpoint_interval = 0.1\nintegrator = \"bdf2\"\n[fluid]\nmodel = \"rss\"\n"
                           "[solver]\njacobian_max_age = 5\n[[rods]]\nnodes = 21\nomega_bar = 800\n";
  const fs::path cfg = WriteConfig("resume.toml", base);
  const fs::path whole = stokesrods::testing::ScratchPath("stokesrods_cli_whole");
  const fs::path parts = stokesrods::testing::ScratchPath("stokesrods_cli_parts");
  fs::remove_all(whole);
  fs::remove_all(parts);
  ASSERT_EQ(RunCli("run " + cfg.string() + " --set run.duration=0.6 --output " + whole.string()).code, 0);
  ASSERT_EQ(RunCli("run " + cfg.string() + " --set run.duration=0.3 --output " + parts.string()).code, 0);
  const Outcome resumed = RunCli("run " + cfg.string() + " --resume --set run.duration=0.6 --output " +
                                 parts.string());
  ASSERT_EQ(resumed.code, 0) << resumed.err;
  EXPECT_EQ(Read(parts / "timeseries.csv"), Read(whole / "timeseries.csv"));
  EXPECT_EQ(Read(parts / "rods.pvd"), Read(whole / "rods.pvd"));
  EXPECT_EQ(Read(parts / "frames" / "rods_00012.vtp"), Read(whole / "frames" / "rods_00012.vtp"));
  EXPECT_EQ(Read(parts / "checkpoint.bin"), Read(whole / "checkpoint.bin"));
  EXPECT_FALSE(fs::exists(parts / "frames" / "rods_00013.vtp"));
  nlohmann::json a = nlohmann::json::parse(Read(parts / "summary.json"));
  nlohmann::json b = nlohmann::json::parse(Read(whole / "summary.json"));
  for (nlohmann::json* s : {&a, &b}) {  // all but the process's counts and the output directory
    s->erase("wall_seconds");
    s->erase("mobility_reuse");
    s->erase("krylov_products");
    s->erase("preconditioner_builds");
    (*s)["config"]["run"].erase("output");
  }
  EXPECT_EQ(a, b);
}

TEST(Cli, ARunKilledAfterItsLastCheckpointResumesToTheSameSummary) {
  // The last step's checkpoint is written before summary.json: a kill between the two leaves a
  // run whose resume takes no step. Its summary (the final row at full precision, from the
  // checkpoint: the CSV holds 12 digits) is that of the uninterrupted run.
  const fs::path cfg = WriteConfig("last.toml", "[run]\nduration = 0.1\ntime_step = 0.01\n"
                                   "output_interval = 0.03\n[[rods]]\nnodes = 15\nomega_bar = 800\n");
  const fs::path out = stokesrods::testing::ScratchPath("stokesrods_cli_last");
  fs::remove_all(out);
  const std::string run = "run " + cfg.string() + " --output " + out.string();
  ASSERT_EQ(RunCli(run).code, 0);
  const std::string csv = Read(out / "timeseries.csv");
  nlohmann::json whole = nlohmann::json::parse(Read(out / "summary.json"));
  fs::remove(out / "summary.json");
  const Outcome resumed = RunCli(run + " --resume");
  ASSERT_EQ(resumed.code, 0) << resumed.err;
  EXPECT_EQ(Read(out / "timeseries.csv"), csv);
  nlohmann::json again = nlohmann::json::parse(Read(out / "summary.json"));
  EXPECT_FALSE(whole["final"].empty());
  for (nlohmann::json* s : {&whole, &again}) {  // the process's own counts
    s->erase("wall_seconds");
    s->erase("mobility_reuse");
    s->erase("krylov_products");
    s->erase("preconditioner_builds");
  }
  EXPECT_EQ(again, whole);
}

TEST(Cli, ResumeRefusesADamagedForeignOrMismatchedCheckpoint) {
  const fs::path cfg = WriteConfig("ck.toml", "[run]\nduration = 0.05\ntime_step = 0.01\n"
                                              "[fluid]\nmodel = \"rft\"\n[[rods]]\nnodes = 11\n");
  const fs::path out = stokesrods::testing::ScratchPath("stokesrods_cli_checkpoint");
  fs::remove_all(out);
  const std::string run = "run " + cfg.string() + " --output " + out.string();
  ASSERT_EQ(RunCli(run).code, 0);
  const std::string good = Read(out / "checkpoint.bin");
  auto resume_with = [&](const std::string& bytes, const std::string& extra = "") {
    std::ofstream(out / "checkpoint.bin", std::ios::binary) << bytes;
    return RunCli(run + " --resume --set run.duration=0.1" + extra);
  };
  std::string flipped = good;
  flipped[good.size() / 2] ^= 0x10;
  Outcome o = resume_with(flipped);
  EXPECT_EQ(o.code, 4);
  EXPECT_NE(o.err.find("checkpoint.bin: cannot resume from this checkpoint: damaged"), std::string::npos) << o.err;
  o = resume_with(good.substr(0, good.size() - 20));
  EXPECT_EQ(o.code, 4);
  EXPECT_NE(o.err.find("damaged"), std::string::npos) << o.err;
  o = resume_with("PK\x03\x04 not a checkpoint at all");
  EXPECT_EQ(o.code, 4);
  EXPECT_NE(o.err.find("not a stokesrods checkpoint"), std::string::npos) << o.err;
  std::string other_version = good;
  other_version[8] = 10;  // a version after this one (9)
  o = resume_with(other_version);
  EXPECT_EQ(o.code, 4);
  EXPECT_NE(o.err.find("format version 10"), std::string::npos) << o.err;
  o = resume_with(good, " --set rods.nodes=12");
  EXPECT_EQ(o.code, 4);
  EXPECT_NE(o.err.find("belongs to another model"), std::string::npos) << o.err;
  o = resume_with(good, " --set run.time_step=0.005");
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.err.find("run.time_step"), std::string::npos) << o.err;
  EXPECT_EQ(resume_with(good).code, 0);
  const auto with_checksum = [](std::string bytes, char version) {  // FNV-1a, as the checkpoint's
    bytes[8] = version;
    std::uint64_t sum = 14695981039346656037ull;
    for (const char c : bytes) sum = (sum ^ static_cast<unsigned char>(c)) * 1099511628211ull;
    return bytes.append(reinterpret_cast<const char*>(&sum), sizeof sum);
  };
  // A version 8 file (before the cubic predictor's history, version 9: the velocity before the
  // previous, its step, the choice and the damped guess's miss) still resumes.
  std::string v8 = good.substr(0, good.size() - sizeof(std::uint64_t));
  std::int64_t older = 0;  // the velocity's length, then its values: 3 numbers after them
  bool found = false;
  // Its length is the rod's 43 DOFs (11 nodes), or 0 if unknown; 43 first: a rod at rest has a
  // velocity of zeros, and a zero read as the count of an empty vector would cut elsewhere.
  for (const std::int64_t n : {std::int64_t{4 * 11 - 1}, std::int64_t{0}}) {
    if (found) break;
    const std::size_t at = v8.size() - 3 * 8 - 8 * static_cast<std::size_t>(n) - sizeof older;
    std::memcpy(&older, v8.data() + at, sizeof older);
    if (older == n) v8.resize(at), found = true;
  }
  ASSERT_TRUE(found);
  o = resume_with(with_checksum(v8, 8));
  EXPECT_EQ(o.code, 0) << o.err;
  // A version 7 file (before the last time-series row, version 8) still resumes: the row's
  // count and values taken out before the checksum, the version and the checksum rewritten.
  std::string v7 = v8;
  found = false;
  for (std::int64_t n = 1; n < 100 && !found; ++n) {
    const std::size_t at = v7.size() - 8 * static_cast<std::size_t>(n) - sizeof n;
    std::int64_t count = 0;
    std::memcpy(&count, v7.data() + at, sizeof count);
    if (count == n) v7.resize(at), found = true;
  }
  ASSERT_TRUE(found);
  o = resume_with(with_checksum(v7, 7));
  EXPECT_EQ(o.code, 0) << o.err;
  fs::remove(out / "checkpoint.bin");
  o = RunCli(run + " --resume");
  EXPECT_EQ(o.code, 4);
  EXPECT_NE(o.err.find("no checkpoint to resume from"), std::string::npos) << o.err;
}

}  // namespace
