// One configuration input as the fuzzer and its regression test (tests/io/fuzz_regression_test.cc)
// feed it: TOML text, then optionally a line "--set" followed by one override per line. Parses,
// validates, builds the model and the run plan; returns normally or throws ConfigError. Any other
// exception, crash or sanitizer report is a bug.
#pragma once

#include <sstream>
#include <string>
#include <vector>

#include "stokesrods/io/build_model.h"
#include "stokesrods/io/config.h"

namespace stokesrods::fuzz {

/// Models above this many nodes are valid but slow to build: the fuzzer explores the parser and
/// the checks, so it skips them after validation.
constexpr long kMaxFuzzNodes = 2000;

inline void CheckConfigInput(const std::string& input) {
  std::string text = input;
  std::vector<std::string> overrides;
  if (const std::size_t split = input.find("\n--set\n"); split != std::string::npos) {
    text = input.substr(0, split);
    std::istringstream lines(input.substr(split + 7));
    for (std::string line; std::getline(lines, line);) overrides.push_back(line);
  }
  const Config config = ParseConfig(text, "fuzz.toml", overrides);
  long nodes = 0;
  for (const RodConfig& rod : config.rods) nodes += rod.nodes;
  if (nodes > kMaxFuzzNodes) return;
  const Model model = BuildModel(config);
  MakeRunPlan(config, model);
}

}  // namespace stokesrods::fuzz
