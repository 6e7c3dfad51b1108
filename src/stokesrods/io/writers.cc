#include "stokesrods/io/writers.h"

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "stokesrods/io/vtk_arrays.h"
#include "stokesrods/rod/frames.h"

namespace stokesrods {

namespace fs = std::filesystem;

CsvWriter::CsvWriter(const std::string& path, const std::vector<std::string>& columns, bool append)
    : path_(path) {
  file_ = std::fopen(path.c_str(), append ? "a" : "w");
  if (file_ == nullptr)
    throw IoError(fmt::format("{}: cannot open for writing: {}", path, std::strerror(errno)));
  if (!append) {
    std::string header;
    for (const std::string& c : columns) header += (header.empty() ? "" : ",") + c;
    std::fputs((header + "\n").c_str(), file_);
    std::fflush(file_);
  }
}

CsvWriter::~CsvWriter() {
  if (file_) std::fclose(file_);
}

void CsvWriter::WriteRow(const std::vector<double>& row) {
  std::string line;
  for (std::size_t i = 0; i < row.size(); ++i) {
    if (i > 0) line += ',';
    line += fmt::format("{:.12g}", row[i]);
  }
  line += "\n";
  if (std::fputs(line.c_str(), file_) < 0 || std::fflush(file_) != 0)
    throw IoError(fmt::format("{}: write failed: {}", path_, std::strerror(errno)));
}

void WriteFileAtomically(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary);
    out << text;
    out.flush();
    if (!out) throw IoError(fmt::format("{}: write failed", tmp));
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) throw IoError(fmt::format("{}: cannot rename into place: {}", path, ec.message()));
}

namespace {

// The first `count` lines of a text file that start with `prefix` (after blanks); IoError if
// there are fewer.
std::vector<std::string> LeadingLines(const std::string& path, const std::string& prefix,
                                      long count) {
  std::vector<std::string> lines;
  if (count <= 0) return lines;
  std::ifstream in(path);
  if (!in) throw IoError(fmt::format("{}: cannot resume: the file is missing", path));
  for (std::string line; lines.size() < static_cast<std::size_t>(count) && std::getline(in, line);) {
    const std::size_t start = line.find_first_not_of(" \t");
    if (start != std::string::npos && line.compare(start, prefix.size(), prefix) == 0)
      lines.push_back(line);
  }
  if (lines.size() < static_cast<std::size_t>(count))
    throw IoError(fmt::format("{}: cannot resume: it has {} entries, the checkpoint needs {}", path,
                              lines.size(), count));
  return lines;
}

// Appends a frame to a .pvd index and rewrites it.
void AddToIndex(const std::string& dir, const char* index, double time, const std::string& file,
                std::vector<std::string>* entries) {
  entries->push_back(
      fmt::format("<DataSet timestep=\"{:.10g}\" part=\"0\" file=\"{}\"/>", time, file));
  std::string pvd = "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n";
  for (const std::string& entry : *entries) pvd += entry + "\n";
  pvd += "</Collection>\n</VTKFile>\n";
  WriteFileAtomically((fs::path(dir) / index).string(), pvd);
}

}  // namespace

void TruncateCsv(const std::string& path, long rows) {
  std::string header;
  std::ifstream in(path);
  if (!in) throw IoError(fmt::format("{}: cannot resume: the file is missing", path));
  std::getline(in, header);
  std::string text = header + "\n";
  long kept = 0;
  for (std::string line; kept < rows && std::getline(in, line); ++kept) text += line + "\n";
  if (kept < rows)
    throw IoError(fmt::format("{}: cannot resume: it has {} rows, the checkpoint needs {}", path,
                              kept, rows));
  WriteFileAtomically(path, text);
}

FrameWriter::FrameWriter(const std::string& output_dir, long keep, VtkFormat format)
    : dir_(output_dir),
      format_(format),
      keep_(keep),
      entries_(LeadingLines((fs::path(output_dir) / "rods.pvd").string(), "<DataSet ", keep)) {
  std::error_code ec;
  fs::create_directories(fs::path(dir_) / "frames", ec);
  if (ec) throw IoError(fmt::format("{}/frames: cannot create: {}", dir_, ec.message()));
}

void FrameWriter::Write(const Model& model, const State& state,
                        const std::vector<FramePointData>& data, const VecX* body_forces) {
  const std::string name = fmt::format("frames/rods_{:05d}.vtp", entries_.size());
  const std::size_t m = static_cast<std::size_t>(model.num_nodes);
  std::vector<double> points, radius, d1, d2;
  std::vector<std::int32_t> connectivity, offsets, rod_id;
  for (std::size_t r = 0; r < model.rods.size(); ++r) {
    const RodModel& rod = model.rods[r];
    for (int i = 0; i < rod.num_nodes(); ++i) {
      const Vec3 x = state.q.segment<3>(rod.dof_offset + NodeDof(i));
      points.insert(points.end(), {x.x(), x.y(), x.z()});
      // The material frame of the edge after the node (the last node: of the last edge).
      const int edge = std::min(i, rod.num_nodes() - 2);
      Vec3 m1, m2;
      MaterialFrame(state.rods[r].frames[edge], state.q(rod.dof_offset + TwistDof(edge)), &m1, &m2);
      d1.insert(d1.end(), {m1.x(), m1.y(), m1.z()});
      d2.insert(d2.end(), {m2.x(), m2.y(), m2.z()});
      radius.push_back(rod.radius);
      connectivity.push_back(rod.node_offset + i);
      rod_id.push_back(static_cast<std::int32_t>(r + 1));
    }
    offsets.push_back(rod.node_offset + rod.num_nodes());
  }
  VtkArrays arrays(format_);
  std::string xml =
      PolyDataStart(&arrays, points, "Lines", connectivity, offsets, " Scalars=\"radius\"");
  xml += arrays.Add("rod", rod_id, 1);
  xml += arrays.Add("radius", radius, 1, 10);
  xml += arrays.Add("material_d1", d1, 3, 8) + arrays.Add("material_d2", d2, 3, 8);
  for (const FramePointData& d : data) {
    if (d.values == nullptr || static_cast<std::size_t>(d.values->size()) != 3 * m) continue;
    xml += arrays.Add(d.name, std::vector<double>(d.values->data(), d.values->data() + 3 * m), 3,
                      8);
  }
  xml += PolyDataEnd(arrays);
  WriteFileAtomically((fs::path(dir_) / name).string(), xml);
  AddToIndex(dir_, "rods.pvd", state.time, name, &entries_);
  if (model.bodies.empty()) return;
  if (!body_entries_read_)
    body_entries_ = LeadingLines((fs::path(dir_) / "bodies.pvd").string(), "<DataSet ", keep_);
  body_entries_read_ = true;
  const std::string body_name = fmt::format("frames/bodies_{:05d}.vtp", body_entries_.size());
  WriteFileAtomically((fs::path(dir_) / body_name).string(),
                      BodyFrameXml(model, state, body_forces, format_));
  AddToIndex(dir_, "bodies.pvd", state.time, body_name, &body_entries_);
}

std::optional<std::string> ReadFileText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace stokesrods
