// libFuzzer target over configuration parsing, validation, the model build and the run plan
// (fuzz/config_input.h). Build and run: scripts/fuzz_config.sh.
#include <cstddef>
#include <cstdint>
#include <string>

#include "config_input.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    stokesrods::fuzz::CheckConfigInput(std::string(reinterpret_cast<const char*>(data), size));
  } catch (const stokesrods::ConfigError&) {
    // Bad input, reported as such: what we want.
  }
  return 0;
}
