// <DataArray> elements of VTK XML files (the ParaView frames): ASCII, or binary for large runs
// (base64 of a UInt64 byte count followed by the little-endian values; the file's VTKFile
// element must say header_type="UInt64").
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace stokesrods {

/// Float64 values; ASCII with `digits` significant digits, binary exact.
std::string VtkDataArray(const std::string& name, const std::vector<double>& values,
                         int components, bool binary, int digits);
/// Int32 values.
std::string VtkDataArray(const std::string& name, const std::vector<std::int32_t>& values,
                         int components, bool binary);

/// RFC 4648 base64 of `bytes`.
std::string Base64(const std::string& bytes);

}  // namespace stokesrods
