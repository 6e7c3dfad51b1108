// `stokesrods sweep` as users run it: cases in separate processes, failure isolation, resume after
// a finished or an interrupted sweep, a failed case retried with [[adjust]], the [refine]
// bisection (kept by an interrupted rerun), a relinked executable, bad sweep files, and the same
// sweep under mpirun -n 2.
#include <gtest/gtest.h>

#include <string>

#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "common/scratch_dir.h"

namespace {

namespace fs = std::filesystem;

// Tiny cases: 5 steps of an 11-node helix; "solver.newton_max_iterations" = 1 makes one fail.
const char* kBase =
    "[run]\nduration = 0.05\ntime_step = 0.01\nframes = false\n[fluid]\nmodel = \"rss\"\n"
    "[[rods]]\nnodes = 11\nomega_bar = 100\n";

fs::path Dir(const std::string& name) {
  const fs::path dir = stokesrods::testing::ScratchPath("stokesrods_sweep_cli") / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "base.toml") << kBase;
  return dir;
}

std::string Read(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

struct Outcome {
  int code = -1;
  std::string err;
};

Outcome Shell(const fs::path& dir, const std::string& command) {
  const fs::path err = dir / "stderr.txt";
  const int status = std::system((command + " > /dev/null 2> " + err.string() + " < /dev/null").c_str());
  return {WEXITSTATUS(status), Read(err)};
}

std::string Sweep(const fs::path& dir) { return std::string(STOKESRODS_BINARY) + " sweep " + dir.string(); }

// sweep.csv as rows of column → value (no quoted commas in the columns read here).
std::vector<std::map<std::string, std::string>> ReadCsv(const fs::path& path) {
  std::istringstream in(Read(path));
  std::string line;
  std::getline(in, line);
  std::vector<std::string> header;
  std::istringstream h(line);
  for (std::string f; std::getline(h, f, ',');) header.push_back(f);
  std::vector<std::map<std::string, std::string>> rows;
  while (std::getline(in, line)) {
    std::istringstream r(line);
    std::map<std::string, std::string> row;
    std::string f;
    for (std::size_t i = 0; i < header.size() && std::getline(r, f, ','); ++i) row[header[i]] = f;
    rows.push_back(row);
  }
  return rows;
}

TEST(SweepCli, AFailingCaseIsRecordedAndTheOthersComplete) {
  const fs::path dir = Dir("failure");
  std::ofstream(dir / "s.toml") << "base = \"base.toml\"\noutput = \"" << (dir / "out").string()
                                << "\"\n[set]\n\"run.time_step\" = 0.025\n[vary]\n"
                                << "\"solver.newton_max_iterations\" = [1, 30]\n"
                                << "\"rods.omega_bar\" = [100, 200]\n";
  const Outcome o = Shell(dir, Sweep(dir / "s.toml") + " --jobs 2");
  EXPECT_EQ(o.code, 3) << o.err;  // not every case completed
  const auto rows = ReadCsv(dir / "out" / "sweep.csv");
  ASSERT_EQ(rows.size(), 4u);
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(rows[i].at("status"), i < 2 ? "failed" : "completed") << rows[i].at("case");
    EXPECT_EQ(rows[i].at("exit_code"), i < 2 ? "3" : "0");
  }
  EXPECT_NE(rows[2].at("rod1_length_bar"), "");
  EXPECT_EQ(rows[2].at("t_bar").empty(), false);
  EXPECT_NE(o.err.find("4/4 done (2 failed)"), std::string::npos) << o.err;
}

TEST(SweepCli, ARerunSkipsFinishedCasesAndRunsTheMissingOnes) {
  const fs::path dir = Dir("resume");
  std::ofstream(dir / "s.toml") << "base = \"base.toml\"\noutput = \"out\"\n[vary]\n"
                                << "\"rods.omega_bar\" = [100, 200, 300]\n";
  const std::string cmd = "cd " + dir.string() + " && " + Sweep(dir / "s.toml");
  ASSERT_EQ(Shell(dir, cmd).code, 0);
  const fs::path kept = dir / "out" / "omega_bar=100" / "summary.json";
  const auto stamp = fs::last_write_time(kept);
  fs::remove_all(dir / "out" / "omega_bar=300");
  const Outcome again = Shell(dir, cmd);
  ASSERT_EQ(again.code, 0) << again.err;
  EXPECT_NE(again.err.find("3 cases in out (2 finished before, skipped;"), std::string::npos) << again.err;
  EXPECT_EQ(fs::last_write_time(kept), stamp);
  const auto rows = ReadCsv(dir / "out" / "sweep.csv");
  ASSERT_EQ(rows.size(), 3u);
  for (const auto& row : rows) EXPECT_EQ(row.at("status"), "completed");
  // A changed base configuration is not "finished": every case runs again.
  std::ofstream(dir / "base.toml") << std::string(kBase) << "poisson_ratio = 0.4\n";
  const Outcome changed = Shell(dir, cmd);
  EXPECT_NE(changed.err.find("(0 finished before"), std::string::npos) << changed.err;
}

// A failed case retried with its own settings ([[adjust]]): only it runs again, in its folder.
TEST(SweepCli, AnAdjustedFailedCaseRunsAgainAndTheOthersAreKept) {
  const fs::path dir = Dir("adjust");
  const std::string head = "base = \"base.toml\"\noutput = \"out\"\n[set]\n\"run.time_step\" = 0.025\n"
                           "[vary]\n\"rods.omega_bar\" = [100, 200]\n[[adjust]]\n"
                           "where = { \"rods.omega_bar\" = 100 }\n\"solver.newton_max_iterations\" = ";
  std::ofstream(dir / "s.toml") << head << "1\n";  // one Newton iteration: the case fails
  const std::string cmd = "cd " + dir.string() + " && " + Sweep(dir / "s.toml");
  ASSERT_EQ(Shell(dir, cmd).code, 3);
  const fs::path kept = dir / "out" / "omega_bar=200" / "summary.json";
  const auto stamp = fs::last_write_time(kept);
  std::ofstream(dir / "s.toml") << head << "20\n";
  const Outcome again = Shell(dir, cmd);
  ASSERT_EQ(again.code, 0) << again.err;
  EXPECT_NE(again.err.find("2 cases in out (1 finished before, skipped;"), std::string::npos) << again.err;
  EXPECT_EQ(fs::last_write_time(kept), stamp);
  const auto rows = ReadCsv(dir / "out" / "sweep.csv");
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].at("case"), "omega_bar=100");
  EXPECT_EQ(rows[0].at("status"), "completed");
  EXPECT_NE(Read(dir / "out" / "omega_bar=100" / "summary.json").find("\"newton_max_iterations\": 20"),
            std::string::npos);
}

TEST(SweepCli, AnInterruptedSweepKeepsFinishedCasesAndResumesTheOthers) {
  const fs::path dir = Dir("interrupt");
  // One quick case, one that cannot finish within the second before the interrupt.
  std::ofstream(dir / "s.toml") << "base = \"base.toml\"\noutput = \"" << (dir / "out").string()
                                << "\"\n[[cases]]\nname = \"quick\"\n[[cases]]\nname = \"long\"\n"
                                << "\"run.duration\" = 1000.0\n\"run.checkpoint_interval\" = 0.05\n";
  const Outcome o = Shell(dir, "timeout --preserve-status -s INT 2 " + Sweep(dir / "s.toml") + " --jobs 2");
  EXPECT_EQ(o.code, 130) << o.err;
  const auto rows = ReadCsv(dir / "out" / "sweep.csv");
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].at("status"), "completed");
  EXPECT_EQ(rows[1].at("status"), "interrupted");
  // The rerun resumes the long case from its checkpoint (it then runs on: stop it again).
  const Outcome again = Shell(dir, "timeout --preserve-status -s INT 2 " + Sweep(dir / "s.toml"));
  EXPECT_NE(again.err.find("(1 finished before, skipped; 1 to resume)"), std::string::npos) << again.err;
}

TEST(SweepCli, BadSweepFileIsExitTwoNamingFileAndKey) {
  const fs::path dir = Dir("bad");
  std::ofstream(dir / "s.toml") << "base = \"base.toml\"\noutput = \"out\"\n[vary]\n"
                                << "\"rods.omega_barr\" = [1, 2]\n";
  const Outcome o = Shell(dir, Sweep(dir / "s.toml"));
  EXPECT_EQ(o.code, 2);
  EXPECT_NE(o.err.find("s.toml"), std::string::npos) << o.err;
  EXPECT_NE(o.err.find("omega_barr"), std::string::npos) << o.err;
  EXPECT_FALSE(fs::exists(dir / "out"));
}

// A sweep with a [refine] pass: writes pair.toml into `dir` and returns the sweep file's text.
std::string PairRefineSweep(const fs::path& dir) {
  std::ofstream(dir / "pair.toml") << "[run]\nduration = 0.02\ntime_step = 0.01\nframes = false\n"
                                   << "[fluid]\nmodel = \"rss\"\n[[rods]]\nnodes = 11\n[[rods]]\n"
                                   << "nodes = 11\nbase = [0.0, 0.05, 0.0]\nhelix_radius = 0.0059\n";
  return "base = \"pair.toml\"\noutput = \"" + (dir / "out").string() +
         "\"\n[vary]\n\"rods.1.helix_radius\" = [0.005, 0.01]\n[refine]\n"
         "key = \"rods.1.helix_radius\"\ncriterion = \"crossed\"\nresolution = 0.001\n";
}

// `analyze` of dir/out finds one line, monotone, bracketed by (below, above].
void ExpectOneBracket(const fs::path& dir, const std::string& below, const std::string& above) {
  const std::string analyze = std::string(STOKESRODS_BINARY) + " analyze " + (dir / "out").string();
  ASSERT_EQ(Shell(dir, analyze).code, 0);
  const auto lines = ReadCsv(dir / "out" / "critical.csv");
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_EQ(lines[0].at("below"), below);
  EXPECT_EQ(lines[0].at("above"), above);
  EXPECT_EQ(lines[0].at("monotone"), "1");
}

// The [refine] pass end to end. Two identical helices side by side along y, rod 1's helix radius
// varied: their tips have the same x (Δb = 0) exactly where rod 1's radius equals rod 2's, 5.9 mm.
// Over [5, 10] mm, Δb > 0 below and < 0 above (the tips' x is set by the geometry; two 10 ms steps
// move them by ~1e-5 R). Bisection to 1 mm: 7.5 (crossed), 6.25 (crossed), 5.625 (not), then
// (5.625, 6.25] is narrower than the resolution and the sweep stops.
TEST(SweepCli, TheRefinePassBisectsTheLineToTheResolution) {
  const fs::path dir = Dir("refine");
  std::ofstream(dir / "s.toml") << PairRefineSweep(dir);
  const Outcome o = Shell(dir, Sweep(dir / "s.toml"));
  ASSERT_EQ(o.code, 0) << o.err;
  std::vector<std::string> radii;
  for (const auto& row : ReadCsv(dir / "out" / "sweep.csv")) {
    EXPECT_EQ(row.at("status"), "completed");
    radii.push_back(row.at("rods.1.helix_radius"));
  }
  EXPECT_EQ(radii, (std::vector<std::string>{"0.005", "0.01", "0.0075", "0.00625", "0.005625"}));
  ExpectOneBracket(dir, "0.005625", "0.00625");
  // A rerun finds the refinement's cases again (by their names) and runs none of them.
  const fs::path last = dir / "out" / "rod1.helix_radius=0.005625" / "summary.json";
  const auto stamp = fs::last_write_time(last);
  const Outcome again = Shell(dir, Sweep(dir / "s.toml"));
  EXPECT_EQ(again.code, 0) << again.err;
  EXPECT_EQ(ReadCsv(dir / "out" / "sweep.csv").size(), 5u);
  EXPECT_EQ(fs::last_write_time(last), stamp);
}

// An interrupted rerun keeps the refinement cases an earlier session finished: they are in
// sweep.json from the start, so `analyze` still brackets the line. The rerun runs one grid case
// again (an [[adjust]] makes it long) and is interrupted during it, before any refine pass.
TEST(SweepCli, AnInterruptedRerunKeepsTheRefinementCasesInSweepJson) {
  const fs::path dir = Dir("refine_interrupt");
  const std::string head = PairRefineSweep(dir);
  std::ofstream(dir / "s.toml") << head;
  ASSERT_EQ(Shell(dir, Sweep(dir / "s.toml")).code, 0);
  std::ofstream(dir / "s.toml") << head << "[[adjust]]\n"
                                << "where = { \"rods.1.helix_radius\" = 0.01 }\n"
                                << "\"run.duration\" = 1000.0\n";
  const Outcome o = Shell(dir, "timeout --preserve-status -s INT 2 " + Sweep(dir / "s.toml"));
  EXPECT_EQ(o.code, 130) << o.err;
  EXPECT_NE(o.err.find("5 cases in"), std::string::npos) << o.err;
  EXPECT_EQ(o.err.find("refining"), std::string::npos) << o.err;
  const auto rows = ReadCsv(dir / "out" / "sweep.csv");
  ASSERT_EQ(rows.size(), 5u);
  EXPECT_EQ(rows[1].at("status"), "interrupted");
  EXPECT_EQ(rows[4].at("rods.1.helix_radius"), "0.005625");
  EXPECT_EQ(rows[4].at("status"), "completed");
  ExpectOneBracket(dir, "0.005625", "0.00625");
}

// A rebuild relinks the executable while a sweep runs (the path then names a new file). The cases
// still start, from the sweep's own build: here the path is unlinked once the sweep has started
// (it has opened its sweep file, a FIFO) and replaced by a script that fails.
TEST(SweepCli, CasesStartFromTheSweepsOwnBuildAfterItsPathIsRelinked) {
  const fs::path dir = Dir("relink");
  const fs::path exe = dir / "stokesrods";
  std::error_code ec;
  fs::create_hard_link(STOKESRODS_BINARY, exe, ec);  // a copy if /tmp is another file system
  if (ec) fs::copy_file(STOKESRODS_BINARY, exe);
  std::ofstream(dir / "sweep.txt") << "base = \"base.toml\"\noutput = \"out\"\n[vary]\n"
                                   << "\"rods.omega_bar\" = [100, 200]\n";
  std::ofstream(dir / "new_build") << "#!/bin/sh\nexit 7\n";
  ASSERT_EQ(mkfifo((dir / "s.toml").c_str(), 0600), 0);
  // The shell's open of the FIFO for writing returns once the sweep opened it to read.
  const Outcome o = Shell(dir, "cd " + dir.string() +
                                   " && (./stokesrods sweep s.toml & exec 3> s.toml; rm stokesrods; "
                                   "mv new_build stokesrods; chmod +x stokesrods; "
                                   "cat sweep.txt >&3; exec 3>&-; wait $!)");
  ASSERT_EQ(o.code, 0) << o.err;
  const auto rows = ReadCsv(dir / "out" / "sweep.csv");
  ASSERT_EQ(rows.size(), 2u);
  for (const auto& row : rows) EXPECT_EQ(row.at("status"), "completed") << row.at("message");
  EXPECT_EQ(Shell(dir, (dir / "stokesrods").string()).code, 7);  // the path holds the "new build"
}

#ifdef STOKESRODS_MPIEXEC
TEST(SweepCli, UnderMpirunTheCasesAreSpreadOverTheRanks) {
  const fs::path dir = Dir("mpi");
  std::ofstream(dir / "s.toml") << "base = \"base.toml\"\noutput = \"" << (dir / "out").string()
                                << "\"\n[vary]\n\"rods.omega_bar\" = [100, 200, 300, 400]\n";
  // Under the asan preset: Open MPI 4.1 leaks its startup allocations in components it unloads
  // before LeakSanitizer reports them (no library name left to suppress), so the ranks run
  // without the leak check; the same sweep code runs with it in the tests above.
  const Outcome o = Shell(dir, "ASAN_OPTIONS=detect_leaks=0 " + std::string(STOKESRODS_MPIEXEC) +
                                 " -n 2 --allow-run-as-root --oversubscribe " + Sweep(dir / "s.toml"));
  ASSERT_EQ(o.code, 0) << o.err;
  const auto rows = ReadCsv(dir / "out" / "sweep.csv");
  ASSERT_EQ(rows.size(), 4u);
  std::map<std::string, int> per_rank;
  for (const auto& row : rows) {
    EXPECT_EQ(row.at("status"), "completed");
    ++per_rank[row.at("rank")];
  }
  EXPECT_GT(per_rank["0"], 0) << o.err;
  EXPECT_GT(per_rank["1"], 0) << o.err;
  EXPECT_EQ(per_rank["0"] + per_rank["1"], 4);
}
#endif

}  // namespace
