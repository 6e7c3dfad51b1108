// Output files (SPEC "Outputs"): timeseries.csv, ParaView frames, checkpoints. Every writer flushes
// what it has written before returning, so an interrupted run loses nothing.
#pragma once

#include <cstdio>
#include <stdexcept>
#include <optional>
#include <string>
#include <vector>

#include "stokesrods/io/vtk_arrays.h"
#include "stokesrods/sim/model.h"
#include "stokesrods/sim/state.h"

namespace stokesrods {

/// An input/output failure (exit code 4), naming the file.
class IoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// timeseries.csv: a header, then one flushed row per call.
class CsvWriter {
 public:
  CsvWriter(const std::string& path, const std::vector<std::string>& columns, bool append = false);
  ~CsvWriter();
  CsvWriter(const CsvWriter&) = delete;
  CsvWriter& operator=(const CsvWriter&) = delete;
  void WriteRow(const std::vector<double>& row);

 private:
  std::string path_;
  std::FILE* file_ = nullptr;
};

/// Per-node vectors written as point data of the frames (3M each, nodes of all rods in order).
struct FramePointData {
  std::string name;
  const VecX* values = nullptr;
};

/// frames/rods_NNNNN.vtp (one polyline per rod) and the rods.pvd index, rewritten after every
/// frame so ParaView can open a run while it goes.
class FrameWriter {
 public:
  /// `keep`: frames of an earlier run kept (--resume): the first `keep` entries of its rods.pvd,
  /// which must have them; the next frame is number `keep`.
  /// `format`: ASCII (10 digits), base64 or appended raw arrays (io/vtk_arrays.h; both exact).
  explicit FrameWriter(const std::string& output_dir, long keep = 0,
                       VtkFormat format = VtkFormat::kAscii);
  /// With bodies, also frames/bodies_NNNNN.vtp (their surface points as vertices, with `body`,
  /// `velocity` and, given `body_forces` (3P), `hydrodynamic_force`) and the bodies.pvd index.
  void Write(const Model& model, const State& state, const std::vector<FramePointData>& data,
             const VecX* body_forces = nullptr);

 private:
  std::string dir_;
  VtkFormat format_ = VtkFormat::kAscii;
  long keep_ = 0;
  std::vector<std::string> entries_;  ///< the DataSet lines of rods.pvd
  std::vector<std::string> body_entries_;  ///< of bodies.pvd (read on the first body frame)
  bool body_entries_read_ = false;
};

/// The bodies' surface points at the state's time as a VTK PolyData file (vertices).
std::string BodyFrameXml(const Model& model, const State& state, const VecX* body_forces,
                         VtkFormat format);

/// Keeps the header and the first `rows` rows of an existing CSV file (--resume); IoError if it
/// has fewer.
void TruncateCsv(const std::string& path, long rows);

/// Writes text to `path` through a temporary file and a rename (never a half-written file).
void WriteFileAtomically(const std::string& path, const std::string& text);

/// The whole content of a file (bytes as they are), or nothing if it cannot be opened: the
/// caller says which error that is for it.
std::optional<std::string> ReadFileText(const std::string& path);

}  // namespace stokesrods
