#include "sweep_command.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <thread>

#include <fmt/format.h>

#include "stokesrods/io/analysis.h"
#include "stokesrods/io/config.h"
#include "stokesrods/io/writers.h"

extern char** environ;

namespace stokesrods {

namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

double Since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Each case is started from /proc/self/exe, the file this process runs, not from a path: a rebuild
// unlinks the path and links a new file there, but the kernel keeps the old file while this process
// runs it, and posix_spawn's child (sharing this process's memory map until it execs) execs exactly
// it. So every case of a sweep runs the scheduler's own build, however often the path is relinked.
// A path resolved at start would run the new build (or nothing while the linker writes it); a copy
// of the executable in the sweep folder would cost its size (~170 MB in release) in every folder.
constexpr const char* kSelfExecutable = "/proc/self/exe";

// The name the case's process gets as argv[0]: the executable's path, for `ps` and messages.
std::string SelfName() {
  std::error_code ec;
  const fs::path self = fs::read_symlink(kSelfExecutable, ec);
  return ec ? std::string("stokesrods") : self.string();
}

// Starts `stokesrods run ...` for case c, its output in <case>/run.log. Returns the child's pid.
pid_t SpawnCase(const Sweep& sweep, const SweepCase& c, bool resume, int threads) {
  std::error_code ec;
  fs::create_directories(c.output_dir, ec);
  if (ec) throw IoError(fmt::format("{}: cannot create the case folder: {}", c.output_dir, ec.message()));
  const std::string log = (fs::path(c.output_dir) / "run.log").string();
  std::vector<std::string> args = {SelfName()};
  for (std::string& a : CaseArguments(sweep, c, resume)) args.push_back(std::move(a));
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::vector<std::string> env_text;
  for (char** e = environ; *e != nullptr; ++e)
    if (std::strncmp(*e, "OMP_NUM_THREADS=", 16) != 0) env_text.emplace_back(*e);
  env_text.push_back(fmt::format("OMP_NUM_THREADS={}", threads));
  std::vector<char*> envp;
  for (std::string& e : env_text) envp.push_back(e.data());
  envp.push_back(nullptr);

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  // Its own process group: a Ctrl-C on the terminal reaches the sweep only, which forwards one
  // SIGINT to each running case (a second one would make the case skip its final checkpoint).
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP);
  posix_spawnattr_setpgroup(&attr, 0);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, kSelfExecutable, &actions, &attr, argv.data(), envp.data());
  posix_spawnattr_destroy(&attr);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0)
    throw IoError(fmt::format("cannot start {} ({}): {}", kSelfExecutable, argv[0], std::strerror(rc)));
  return pid;
}

CaseRecord RecordOfExit(const SweepCase& c, int wait_status, double wall) {
  const int code = WIFEXITED(wait_status) ? WEXITSTATUS(wait_status) : 0;
  const int signal = WIFSIGNALED(wait_status) ? WTERMSIG(wait_status) : 0;
  return MakeCaseRecord(code, signal, wall, ReadFileText((fs::path(c.output_dir) / "summary.json").string()).value_or(""));
}

std::string Hms(double seconds) {
  const long s = std::lround(std::max(0.0, seconds));
  return fmt::format("{:02d}:{:02d}:{:02d}", s / 3600, (s / 60) % 60, s % 60);
}

// The state of the whole sweep on rank 0.
class Board {
 public:
  Board(Sweep* sweep, const SweepCommandOptions& options) : sweep_(*sweep), options_(options) {
    for (std::size_t i = 0; i < sweep_.cases.size(); ++i) Admit(i);
    WriteSweepCsv(sweep_, records_);
  }

  /// New cases (the [refine] pass): run unless they finished in an earlier session.
  void Add(std::vector<SweepCase> cases) {
    for (SweepCase& c : cases) {
      sweep_.cases.push_back(std::move(c));
      Admit(sweep_.cases.size() - 1);
    }
    WriteSweepCsv(sweep_, records_);
  }

  const std::vector<CaseRecord>& Records() const { return records_; }

  bool HasQueued() const { return !queue_.empty(); }
  int Skipped() const { return skipped_; }
  int Resumable() const { return resumable_; }
  int Take() {
    const int i = queue_.front();
    queue_.pop_front();
    records_[i].status = "running";
    ++running_;
    return i;
  }
  bool Resume(int i) const { return resume_[i]; }
  int Running() const { return running_; }

  void Finish(int i, CaseRecord record) {
    --running_;
    ++done_;
    if (record.status != "completed" && record.status != "interrupted") ++failed_;
    if (record.status != "interrupted") session_wall_ += record.wall_seconds, ++session_done_;
    records_[i] = std::move(record);
    WriteSweepCsv(sweep_, records_);
  }

  void Report(int slots, bool force) {
    if (!force && Since(last_report_) < 60.0) return;
    last_report_ = Clock::now();
    const double mean = session_done_ > 0 ? session_wall_ / session_done_ : 0.0;
    const double left = mean * (static_cast<double>(queue_.size()) + 0.5 * running_) / std::max(1, slots);
    fmt::print(stderr, "[sweep] {}/{} done ({} failed), {} running, {} queued, {} left\n",
               done_ + skipped_, sweep_.cases.size(), failed_, running_, queue_.size(),
               session_done_ > 0 ? "about " + Hms(left) : std::string("unknown time"));
  }

  int ExitCode(bool interrupted) const {
    if (interrupted) return 130;
    for (const CaseRecord& r : records_)
      if (r.status != "completed") return 3;
    return 0;
  }

 private:
  void Admit(std::size_t i) {
    CaseRecord r = ReadCaseRecord(sweep_, sweep_.cases[i]);
    const bool skip = r.status == "completed" || (r.status == "failed" && !options_.retry_failed);
    if (skip) ++skipped_;
    else queue_.push_back(static_cast<int>(i));
    if (r.status == "failed" && skip) ++failed_;
    if (r.resumable) ++resumable_;
    resume_.push_back(r.resumable);
    records_.push_back(std::move(r));
  }

  Sweep& sweep_;
  const SweepCommandOptions& options_;
  std::vector<CaseRecord> records_;
  std::vector<bool> resume_;
  std::deque<int> queue_;
  int skipped_ = 0, resumable_ = 0, running_ = 0, done_ = 0, failed_ = 0, session_done_ = 0;
  double session_wall_ = 0.0;
  Clock::time_point last_report_ = Clock::now();
};

// The [refine] pass: the middles of the brackets still wider than the resolution (none: done).
std::vector<SweepCase> NextRefinement(const Sweep& sweep, const std::vector<CaseRecord>& records) {
  if (!sweep.refine) return {};
  std::vector<std::optional<bool>> outcomes(sweep.cases.size());
  for (std::size_t i = 0; i < sweep.cases.size(); ++i) {
    if (records[i].status != "completed") continue;
    try {
      outcomes[i] = Outcome(AnalyzeRun(sweep.cases[i].output_dir), sweep.refine->criterion);
    } catch (const IoError&) {
      // unreadable outputs: the case does not count
    }
  }
  const auto lines = CriticalAlongLines(sweep, sweep.refine->key, outcomes);
  return RefinementCases(sweep, sweep.refine->key, lines, sweep.refine->resolution);
}

}  // namespace

CaseRecord RunCaseProcess(const Sweep& sweep, const SweepCase& c, bool resume, int threads,
                          const std::function<bool()>& interrupted) {
  const auto start = Clock::now();
  const pid_t pid = SpawnCase(sweep, c, resume, threads);
  bool forwarded = false;
  int status = 0;
  while (waitpid(pid, &status, WNOHANG) == 0) {
    if (!forwarded && interrupted && interrupted()) {
      kill(pid, SIGINT);
      forwarded = true;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return RecordOfExit(c, status, Since(start));
}

int ScheduleSweep(Sweep sweep, const SweepCommandOptions& options, RemoteWorkers* remote) {
  // Refinement cases finished in an earlier session are listed from the start, so that sweep.json
  // (what `analyze` reads) keeps them even if this session is interrupted before its refine pass.
  for (SweepCase& c : KnownRefinementCases(sweep)) sweep.cases.push_back(std::move(c));
  WriteSweepJson(sweep);
  Board board(&sweep, options);
  const int remote_count = remote != nullptr ? remote->Count() : 0;
  const int slots = std::max(1, options.jobs) + remote_count;
  fmt::print(stderr, "[sweep] {} cases in {} ({} finished before, skipped; {} to resume); {} at a time{}\n",
             sweep.cases.size(), sweep.output, board.Skipped(), board.Resumable(), slots,
             remote_count > 0 ? fmt::format(" ({} here, {} on other ranks)", options.jobs, remote_count) : "");
  struct Local {
    int index;
    Clock::time_point start;
    bool signalled = false;
  };
  std::map<pid_t, Local> local;
  std::vector<int> idle;
  for (int w = remote_count; w-- > 0;) idle.push_back(w);
  bool interrupted = false;
  while (true) {
    interrupted = interrupted || (options.interrupted && options.interrupted());
    if (interrupted) {
      // Once per case: a second SIGINT would make the run skip its final checkpoint.
      for (auto& [pid, l] : local)
        if (!l.signalled) kill(pid, SIGINT), l.signalled = true;
    } else {
      while (board.HasQueued() && static_cast<int>(local.size()) < std::max(1, options.jobs)) {
        const int i = board.Take();
        local[SpawnCase(sweep, sweep.cases[i], board.Resume(i), options.threads)] = {i, Clock::now(), false};
      }
      while (board.HasQueued() && !idle.empty()) {
        const int i = board.Take();
        remote->Assign(idle.back(), i, sweep.cases[i]);
        idle.pop_back();
      }
    }
    if (board.Running() == 0 && !interrupted && !board.HasQueued()) {
      std::vector<SweepCase> more = NextRefinement(sweep, board.Records());
      if (!more.empty()) {
        fmt::print(stderr, "[sweep] refining along {}: {} more cases\n", sweep.refine->key, more.size());
        board.Add(std::move(more));
        WriteSweepJson(sweep);
        continue;
      }
    }
    if (board.Running() == 0 && (interrupted || !board.HasQueued())) break;
    bool progressed = false;
    int status = 0;
    for (pid_t pid; (pid = waitpid(-1, &status, WNOHANG)) > 0;) {
      auto it = local.find(pid);
      if (it == local.end()) continue;
      const int i = it->second.index;
      board.Finish(i, RecordOfExit(sweep.cases[i], status, Since(it->second.start)));
      local.erase(it);
      progressed = true;
    }
    while (remote != nullptr) {
      std::optional<FinishedCase> f = remote->Poll();
      if (!f) break;
      board.Finish(f->index, std::move(f->record));
      idle.push_back(f->worker);
      progressed = true;
    }
    board.Report(slots, progressed);
    if (!progressed) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  if (remote != nullptr) remote->StopAll();
  fmt::print(stderr, "[sweep] {}; table in {}\n", interrupted ? "interrupted" : "finished",
             (fs::path(sweep.output) / "sweep.csv").string());
  return board.ExitCode(interrupted);
}

int RunSweepCommand(const SweepCommandOptions& options) {
  if (LaunchedByMpi()) return RunSweepMpi(options);
  const Sweep sweep = LoadSweep(options.file, options.output);
  return ScheduleSweep(sweep, options, nullptr);
}

}  // namespace stokesrods
