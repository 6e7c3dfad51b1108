// The sweep under `mpirun -n K`: rank 0 schedules (and runs --jobs cases itself); ranks 1..K-1
// each run one case at a time and get the next one from rank 0 when they report a result, so a
// rank that drew cheap cases simply asks more often (dynamic load balancing).
#include <mpi.h>

#include <cstdlib>

#include <nlohmann/json.hpp>

#include "sweep_command.h"

namespace stokesrods {

namespace {

constexpr int kAssignTag = 1;  // rank 0 → worker: a case index, or -1 for "no more"
constexpr int kResultTag = 2;  // worker → rank 0: the finished case's record as JSON text

std::string RecordToJson(int index, const CaseRecord& r) {
  return nlohmann::json{{"index", index},           {"status", r.status},
                        {"message", r.message},     {"exit_code", r.exit_code},
                        {"wall_seconds", r.wall_seconds}, {"rank", r.rank},
                        {"final", r.final_values}}
      .dump();
}

// A message of any length: probe its size, then receive it.
std::string ReceiveText(int source, int tag) {
  MPI_Status status;
  MPI_Probe(source, tag, MPI_COMM_WORLD, &status);
  int length = 0;
  MPI_Get_count(&status, MPI_CHAR, &length);
  std::string text(static_cast<std::size_t>(length), '\0');
  MPI_Recv(text.data(), length, MPI_CHAR, source, tag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  return text;
}

class MpiWorkers : public RemoteWorkers {
 public:
  explicit MpiWorkers(int size) : size_(size) {}
  int Count() const override { return size_ - 1; }
  void Assign(int worker, int index, const SweepCase& c) override {
    const std::string text = nlohmann::json{{"index", index}, {"case", CaseToJson(c)}}.dump();
    MPI_Send(text.data(), static_cast<int>(text.size()), MPI_CHAR, worker + 1, kAssignTag,
             MPI_COMM_WORLD);
  }
  std::optional<FinishedCase> Poll() override {
    int arrived = 0;
    MPI_Status status;
    MPI_Iprobe(MPI_ANY_SOURCE, kResultTag, MPI_COMM_WORLD, &arrived, &status);
    if (arrived == 0) return std::nullopt;
    const nlohmann::json j = nlohmann::json::parse(ReceiveText(status.MPI_SOURCE, kResultTag));
    FinishedCase f;
    f.worker = status.MPI_SOURCE - 1;
    f.index = j.at("index").get<int>();
    f.record.status = j.at("status").get<std::string>();
    f.record.message = j.at("message").get<std::string>();
    f.record.exit_code = j.at("exit_code").get<int>();
    f.record.wall_seconds = j.at("wall_seconds").get<double>();
    f.record.rank = j.at("rank").get<int>();
    f.record.final_values = j.at("final");
    return f;
  }
  void StopAll() override {
    for (int w = 0; w < Count(); ++w) Assign(w, -1, SweepCase{});
  }

 private:
  int size_;
};

void ServeCases(const Sweep& sweep, const SweepCommandOptions& options) {
  while (true) {
    const nlohmann::json assignment = nlohmann::json::parse(ReceiveText(0, kAssignTag));
    const int index = assignment.at("index").get<int>();
    if (index < 0) return;
    const SweepCase c = CaseFromJson(assignment.at("case"));
    CaseRecord r;
    try {
      r = RunCaseProcess(sweep, c, ReadCaseRecord(sweep, c).resumable, options.threads,
                         options.interrupted);
    } catch (const std::exception& e) {
      r.status = "error";
      r.exit_code = 4;
      r.message = e.what();
    }
    MPI_Comm_rank(MPI_COMM_WORLD, &r.rank);
    const std::string text = RecordToJson(index, r);
    MPI_Send(text.data(), static_cast<int>(text.size()), MPI_CHAR, 0, kResultTag, MPI_COMM_WORLD);
  }
}

}  // namespace

bool LaunchedByMpi() {
  return std::getenv("OMPI_COMM_WORLD_SIZE") != nullptr || std::getenv("PMI_SIZE") != nullptr ||
         std::getenv("PMIX_RANK") != nullptr;
}

int RunSweepMpi(const SweepCommandOptions& options) {
  MPI_Init(nullptr, nullptr);
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  int code = 0;
  try {
    const Sweep sweep = LoadSweep(options.file, options.output);  // every rank checks the file
    if (rank == 0) {
      MpiWorkers workers(size);
      code = ScheduleSweep(sweep, options, &workers);
    } else {
      ServeCases(sweep, options);
    }
  } catch (...) {
    MPI_Finalize();
    throw;  // bad input is the same on every rank: each exits 2 with the message
  }
  MPI_Finalize();
  return code;
}

}  // namespace stokesrods
