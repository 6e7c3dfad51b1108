#include "stokesrods/io/vtk_arrays.h"

#include <fmt/format.h>

namespace stokesrods {
namespace {

template <class T>
std::string Binary(const std::vector<T>& values) {
  static_assert(sizeof(T) == 4 || sizeof(T) == 8);
  const std::uint64_t bytes = values.size() * sizeof(T);
  std::string raw(reinterpret_cast<const char*>(&bytes), sizeof bytes);  // x86-64: little-endian
  raw.append(reinterpret_cast<const char*>(values.data()), bytes);
  return Base64(raw);
}

std::string Element(const std::string& name, const char* type, int components, bool binary,
                    const std::string& body) {
  return fmt::format("<DataArray type=\"{}\" Name=\"{}\" NumberOfComponents=\"{}\" format=\"{}\">\n{}\n"
                     "</DataArray>\n",
                     type, name, components, binary ? "binary" : "ascii", body);
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

std::string VtkDataArray(const std::string& name, const std::vector<double>& values,
                         int components, bool binary, int digits) {
  if (binary) return Element(name, "Float64", components, true, Binary(values));
  std::string body;
  for (std::size_t i = 0; i < values.size(); ++i)
    body += fmt::format("{:.{}g}{}", values[i], digits,
                        (i + 1) % static_cast<std::size_t>(components) == 0 ? "\n" : " ");
  if (!body.empty()) body.pop_back();
  return Element(name, "Float64", components, false, body);
}

std::string VtkDataArray(const std::string& name, const std::vector<std::int32_t>& values,
                         int components, bool binary) {
  if (binary) return Element(name, "Int32", components, true, Binary(values));
  std::string body;
  for (std::int32_t v : values) body += fmt::format("{} ", v);
  if (!body.empty()) body.pop_back();
  return Element(name, "Int32", components, false, body);
}

}  // namespace stokesrods
