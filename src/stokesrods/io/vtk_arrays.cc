#include "stokesrods/io/vtk_arrays.h"

#include <fmt/format.h>

namespace stokesrods {
namespace {

// A UInt64 byte count followed by the values, little-endian (x86-64's own order).
template <class T>
std::string CountedBytes(const std::vector<T>& values) {
  static_assert(sizeof(T) == 4 || sizeof(T) == 8);
  const std::uint64_t bytes = values.size() * sizeof(T);
  std::string raw(reinterpret_cast<const char*>(&bytes), sizeof bytes);
  raw.append(reinterpret_cast<const char*>(values.data()), bytes);
  return raw;
}

std::string Element(const std::string& name, const char* type, int components,
                    const char* format, const std::string& body) {
  return fmt::format("<DataArray type=\"{}\" Name=\"{}\" NumberOfComponents=\"{}\" format=\"{}\">\n{}\n"
                     "</DataArray>\n",
                     type, name, components, format, body);
}

}  // namespace

std::string Base64(const std::string& bytes) {
  static constexpr char kAlphabet[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::size_t n = std::min<std::size_t>(3, bytes.size() - i);
    std::uint32_t chunk = 0;
    for (std::size_t k = 0; k < 3; ++k)
      chunk = (chunk << 8) | (k < n ? static_cast<unsigned char>(bytes[i + k]) : 0u);
    for (std::size_t k = 0; k < 4; ++k)
      out += k <= n ? kAlphabet[(chunk >> (18 - 6 * k)) & 63u] : '=';
  }
  return out;
}

template <class T>
std::string VtkArrays::Encoded(const std::string& name, const char* type,
                               const std::vector<T>& values, int components,
                               const std::string& ascii_text) {
  switch (format_) {
    case VtkFormat::kAscii:
      return Element(name, type, components, "ascii", ascii_text);
    case VtkFormat::kBase64:
      return Element(name, type, components, "binary", Base64(CountedBytes(values)));
    case VtkFormat::kAppended:
      break;
  }
  const std::size_t offset = appended_.size();
  appended_ += CountedBytes(values);
  return fmt::format("<DataArray type=\"{}\" Name=\"{}\" NumberOfComponents=\"{}\" "
                     "format=\"appended\" offset=\"{}\"/>\n",
                     type, name, components, offset);
}

std::string VtkArrays::Add(const std::string& name, const std::vector<double>& values,
                           int components, int digits) {
  std::string text;
  if (format_ == VtkFormat::kAscii) {
    for (std::size_t i = 0; i < values.size(); ++i)
      text += fmt::format("{:.{}g}{}", values[i], digits,
                          (i + 1) % static_cast<std::size_t>(components) == 0 ? "\n" : " ");
    if (!text.empty()) text.pop_back();
  }
  return Encoded(name, "Float64", values, components, text);
}

std::string VtkArrays::Add(const std::string& name, const std::vector<std::int32_t>& values,
                           int components) {
  std::string text;
  if (format_ == VtkFormat::kAscii) {
    for (std::int32_t v : values) text += fmt::format("{} ", v);
    if (!text.empty()) text.pop_back();
  }
  return Encoded(name, "Int32", values, components, text);
}

std::string PolyDataStart(VtkArrays* arrays, const std::vector<double>& points, const char* cells,
                          const std::vector<std::int32_t>& connectivity,
                          const std::vector<std::int32_t>& offsets,
                          const std::string& point_data_attributes) {
  std::string xml = fmt::format(
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"1.0\" "
      "byte_order=\"LittleEndian\" header_type=\"UInt64\">\n<PolyData>\n"
      "<Piece NumberOfPoints=\"{}\" NumberOf{}=\"{}\">\n<Points>\n",
      points.size() / 3, cells, offsets.size());
  xml += arrays->Add("points", points, 3, 10) + fmt::format("</Points>\n<{}>\n", cells);
  xml += arrays->Add("connectivity", connectivity, 1);
  xml += arrays->Add("offsets", offsets, 1) + fmt::format("</{}>\n", cells);
  return xml + "<PointData" + point_data_attributes + ">\n";
}

std::string PolyDataEnd(const VtkArrays& arrays) {
  return "</PointData>\n</Piece>\n</PolyData>\n" + arrays.AppendedData() + "</VTKFile>\n";
}

std::string VtkArrays::AppendedData() const {
  if (format_ != VtkFormat::kAppended) return "";
  return "<AppendedData encoding=\"raw\">\n_" + appended_ + "\n</AppendedData>\n";
}

}  // namespace stokesrods
