// <DataArray> elements of VTK XML files (the ParaView frames), in one of three encodings:
//   ascii     the values as text (doubles with a given number of significant digits);
//   binary    inline base64 of a UInt64 byte count followed by the little-endian values;
//   appended  raw: the element carries an offset into the file's <AppendedData encoding="raw">
//             block, which holds, per array, the UInt64 byte count and the values (the smallest
//             and fastest to read).
// The file's VTKFile element must say header_type="UInt64" and byte_order="LittleEndian".
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace stokesrods {

enum class VtkFormat { kAscii, kBase64, kAppended };

/// The arrays of one VTK XML file, in order: Add returns each <DataArray> element; AppendedData
/// the block that goes after the last element's parent closes, before </VTKFile>.
class VtkArrays {
 public:
  explicit VtkArrays(VtkFormat format) : format_(format) {}
  /// Float64 values; ASCII with `digits` significant digits, binary and appended exact.
  std::string Add(const std::string& name, const std::vector<double>& values, int components,
                  int digits);
  /// Int32 values.
  std::string Add(const std::string& name, const std::vector<std::int32_t>& values,
                  int components);
  /// `<AppendedData encoding="raw">_…</AppendedData>` with the appended arrays; empty otherwise.
  std::string AppendedData() const;

 private:
  template <class T>
  std::string Encoded(const std::string& name, const char* type, const std::vector<T>& values,
                      int components, const std::string& ascii_text);
  VtkFormat format_;
  std::string appended_;  ///< the raw block after '_' (appended)
};

/// A VTK XML PolyData file up to the opening of its <PointData> element (`point_data_attributes`
/// inside its tag, e.g. ` Scalars="radius"`): the header, the points (3 per point) and the cells
/// of kind `cells` ("Lines" or "Verts") given by their connectivity and offsets.
std::string PolyDataStart(VtkArrays* arrays, const std::vector<double>& points, const char* cells,
                          const std::vector<std::int32_t>& connectivity,
                          const std::vector<std::int32_t>& offsets,
                          const std::string& point_data_attributes = "");
/// Closes what PolyDataStart opened, with the appended data block if any.
std::string PolyDataEnd(const VtkArrays& arrays);

/// RFC 4648 base64 of `bytes`.
std::string Base64(const std::string& bytes);

}  // namespace stokesrods
