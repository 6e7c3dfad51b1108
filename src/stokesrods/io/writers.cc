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

FrameWriter::FrameWriter(const std::string& output_dir) : dir_(output_dir) {
  std::error_code ec;
  fs::create_directories(fs::path(dir_) / "frames", ec);
  if (ec) throw IoError(fmt::format("{}/frames: cannot create: {}", dir_, ec.message()));
}

void FrameWriter::Write(const Model& model, const State& state,
                        const std::vector<FramePointData>& data) {
  const std::string name = fmt::format("frames/rods_{:05d}.vtp", frames_.size());
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
  frames_.emplace_back(state.time, name);

  std::string pvd = "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n";
  for (const auto& [t, file] : frames_)
    pvd += fmt::format("<DataSet timestep=\"{:.10g}\" part=\"0\" file=\"{}\"/>\n", t, file);
  pvd += "</Collection>\n</VTKFile>\n";
  WriteFileAtomically((fs::path(dir_) / "rods.pvd").string(), pvd);
}

namespace {
constexpr char kMagic[8] = {'S', 'R', 'C', 'K', 'P', 'T', '0', '1'};

void Put(std::string* out, const void* data, std::size_t bytes) {
  out->append(static_cast<const char*>(data), bytes);
}
void PutVec(std::string* out, const VecX& v) {
  const std::int64_t n = v.size();
  Put(out, &n, sizeof n);
  Put(out, v.data(), sizeof(double) * static_cast<std::size_t>(n));
}
}  // namespace

void SaveCheckpoint(const std::string& path, const State& state) {
  std::string out(kMagic, sizeof kMagic);
  Put(&out, &state.time, sizeof state.time);
  Put(&out, &state.step, sizeof state.step);
  PutVec(&out, state.q);
  PutVec(&out, state.velocity);
  for (const RodFrames& rod : state.rods) {
    for (std::size_t j = 0; j < rod.frames.size(); ++j) {
      Put(&out, rod.frames[j].d1.data(), 3 * sizeof(double));
      Put(&out, rod.frames[j].d2.data(), 3 * sizeof(double));
      Put(&out, rod.tangents[j].data(), 3 * sizeof(double));
    }
    PutVec(&out, rod.reference_twist);
  }
  WriteFileAtomically(path, out);
}

State LoadCheckpoint(const std::string& path, const Model& model) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(fmt::format("{}: cannot open the checkpoint", path));
  auto get = [&](void* data, std::size_t bytes) {
    in.read(static_cast<char*>(data), static_cast<std::streamsize>(bytes));
    if (!in) throw IoError(fmt::format("{}: truncated checkpoint", path));
  };
  auto get_vec = [&](VecX* v, Eigen::Index expected) {
    std::int64_t n = 0;
    get(&n, sizeof n);
    if (n != expected) throw IoError(fmt::format("{}: checkpoint does not match the model", path));
    v->resize(n);
    get(v->data(), sizeof(double) * static_cast<std::size_t>(n));
  };
  char magic[8];
  get(magic, sizeof magic);
  if (std::memcmp(magic, kMagic, sizeof kMagic) != 0)
    throw IoError(fmt::format("{}: not a stokesrods checkpoint", path));
  State state;
  get(&state.time, sizeof state.time);
  get(&state.step, sizeof state.step);
  get_vec(&state.q, model.num_dofs);
  get_vec(&state.velocity, model.num_dofs);
  for (const RodModel& rod : model.rods) {
    RodFrames f;
    f.frames.resize(rod.num_nodes() - 1);
    f.tangents.resize(rod.num_nodes() - 1);
    for (int j = 0; j + 1 < rod.num_nodes(); ++j) {
      get(f.frames[j].d1.data(), 3 * sizeof(double));
      get(f.frames[j].d2.data(), 3 * sizeof(double));
      get(f.tangents[j].data(), 3 * sizeof(double));
    }
    get_vec(&f.reference_twist, rod.num_nodes());
    state.rods.push_back(std::move(f));
  }
  return state;
}

}  // namespace stokesrods
