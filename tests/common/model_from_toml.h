// Tests build their models from tiny TOML configs kept as raw strings (as MuJoCo does with XML).
#pragma once

#include <string>

#include "stokesrods/io/build_model.h"
#include "stokesrods/io/config.h"

namespace stokesrods::testing {

inline Model ModelFromToml(const std::string& text) {
  return BuildModel(ParseConfig(text, "test.toml"));
}

}  // namespace stokesrods::testing
