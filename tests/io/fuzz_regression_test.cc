// Replays the configuration fuzzer's stored inputs (tests/data/fuzz/: its seeds and every input
// that once crashed it): each must build or end in a ConfigError, nothing else.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "fuzz/config_input.h"

namespace stokesrods {
namespace {

TEST(FuzzRegression, EveryStoredInputBuildsOrIsAConfigError) {
  const std::filesystem::path dir = std::filesystem::path(STOKESRODS_SOURCE_DIR) / "tests/data/fuzz";
  int inputs = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    std::ifstream in(entry.path(), std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    ++inputs;
    try {
      fuzz::CheckConfigInput(text.str());
    } catch (const ConfigError&) {
    } catch (const std::exception& e) {
      ADD_FAILURE() << entry.path() << ": " << typeid(e).name() << ": " << e.what();
    }
  }
  EXPECT_GE(inputs, 2);
}

}  // namespace
}  // namespace stokesrods
