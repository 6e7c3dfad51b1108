// Tests build their models from tiny TOML configs kept as raw strings (as MuJoCo does with XML).
#pragma once

#include <string>
#include <vector>

#include "stokesrods/io/build_model.h"
#include "stokesrods/io/config.h"

namespace stokesrods::testing {

inline Model ModelFromToml(const std::string& text) {
  return BuildModel(ParseConfig(text, "test.toml"));
}

/// The error of reading "case.toml" with `text` and building its model and run plan, or "" if
/// all succeed.
inline std::string ConfigErrorOf(const std::string& text,
                                 const std::vector<std::string>& overrides = {}) {
  try {
    const Config config = ParseConfig(text, "case.toml", overrides);
    MakeRunPlan(config, BuildModel(config));
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

}  // namespace stokesrods::testing
