// Replays the configuration fuzzer's stored inputs (tests/data/fuzz/: its seeds and every input
// that once crashed it): each must build or end in a ConfigError, nothing else; and the rest of
// its seed corpus, the examples, which must build. Under the asan preset this is the corpus
// replayed under AddressSanitizer + UBSan (gcc), besides the fuzzer's own clang build.
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

TEST(FuzzRegression, EveryExampleConfigurationBuilds) {
  const std::filesystem::path dir = std::filesystem::path(STOKESRODS_SOURCE_DIR) / "examples";
  int inputs = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".toml") continue;
    std::ifstream in(entry.path(), std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    ++inputs;
    EXPECT_NO_THROW(fuzz::CheckConfigInput(text.str())) << entry.path();
  }
  EXPECT_GE(inputs, 5);
}

}  // namespace
}  // namespace stokesrods
