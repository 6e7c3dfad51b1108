#include "stokesrods/io/writers.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>

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

FrameWriter::FrameWriter(const std::string& output_dir, long keep)
    : dir_(output_dir),
      entries_(LeadingLines((fs::path(output_dir) / "rods.pvd").string(), "<DataSet ", keep)) {
  std::error_code ec;
  fs::create_directories(fs::path(dir_) / "frames", ec);
  if (ec) throw IoError(fmt::format("{}/frames: cannot create: {}", dir_, ec.message()));
}

void FrameWriter::Write(const Model& model, const State& state,
                        const std::vector<FramePointData>& data) {
  const std::string name = fmt::format("frames/rods_{:05d}.vtp", entries_.size());
  std::string xml;
  xml += "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n<PolyData>\n";
  xml += fmt::format("<Piece NumberOfPoints=\"{}\" NumberOfLines=\"{}\">\n", model.num_nodes,
                     model.rods.size());
  xml += "<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (const RodModel& rod : model.rods)
    for (int i = 0; i < rod.num_nodes(); ++i) {
      const Vec3 x = state.q.segment<3>(rod.dof_offset + NodeDof(i));
      xml += fmt::format("{:.10g} {:.10g} {:.10g}\n", x.x(), x.y(), x.z());
    }
  xml += "</DataArray></Points>\n<Lines>\n<DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">\n";
  for (const RodModel& rod : model.rods) {
    for (int i = 0; i < rod.num_nodes(); ++i) xml += fmt::format("{} ", rod.node_offset + i);
    xml += "\n";
  }
  xml += "</DataArray>\n<DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">\n";
  for (const RodModel& rod : model.rods) xml += fmt::format("{} ", rod.node_offset + rod.num_nodes());
  xml += "\n</DataArray>\n</Lines>\n<PointData>\n<DataArray type=\"Int32\" Name=\"rod\" format=\"ascii\">\n";
  for (std::size_t r = 0; r < model.rods.size(); ++r)
    for (int i = 0; i < model.rods[r].num_nodes(); ++i) xml += fmt::format("{} ", r + 1);
  xml += "\n</DataArray>\n";
  for (const FramePointData& d : data) {
    if (d.values == nullptr || d.values->size() != 3 * model.num_nodes) continue;
    xml += fmt::format("<DataArray type=\"Float64\" Name=\"{}\" NumberOfComponents=\"3\" format=\"ascii\">\n", d.name);
    for (int k = 0; k < model.num_nodes; ++k)
      xml += fmt::format("{:.8g} {:.8g} {:.8g}\n", (*d.values)(3 * k), (*d.values)(3 * k + 1),
                         (*d.values)(3 * k + 2));
    xml += "</DataArray>\n";
  }
  xml += "</PointData>\n</Piece>\n</PolyData>\n</VTKFile>\n";
  WriteFileAtomically((fs::path(dir_) / name).string(), xml);
  entries_.push_back(
      fmt::format("<DataSet timestep=\"{:.10g}\" part=\"0\" file=\"{}\"/>", state.time, name));

  std::string pvd = "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n";
  for (const std::string& entry : entries_) pvd += entry + "\n";
  pvd += "</Collection>\n</VTKFile>\n";
  WriteFileAtomically((fs::path(dir_) / "rods.pvd").string(), pvd);
}

}  // namespace stokesrods
