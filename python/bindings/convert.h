// From Python objects to the configuration: a TOML path or a dict of the schema, and overrides
// as a dict {"rods.omega_bar": 533} or a list of "KEY=VALUE" strings.
#pragma once

#include <pybind11/pybind11.h>

#include "stokesrods/io/config.h"

namespace stokesrods::python {

/// Reads and validates as LoadConfig does (throws ConfigError); a dict is turned into TOML text
/// and read by ParseConfig under the name "<dict>".
Config ConfigFromPython(const pybind11::handle& config, const pybind11::handle& overrides);

}  // namespace stokesrods::python
