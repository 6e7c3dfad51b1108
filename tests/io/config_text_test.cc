// The resolved configuration as text (show-config) and the overrides of exclusive keys.
#include <gtest/gtest.h>


#include <cstdlib>
#include <fstream>
#include <sstream>

#include "stokesrods/io/config.h"
#include "stokesrods/io/config_docs.h"

namespace stokesrods {
namespace {

constexpr char kHelix[] = R"(
[run]
t_bar_end = 0.5
time_step = 0.02
output_interval = 0.029999999999999999
[[rods]]
omega_bar = 320
loads = [{node = 3, force = [0.1, 1e-300, -0.3333333333333333]}]
)";

TEST(ConfigText, AnOverrideOfOneOfTwoExclusiveKeysReplacesTheOther) {
  const Config c = ParseConfig(kHelix, "case.toml", {"run.duration=5", "rods.omega=2.5"});
  EXPECT_DOUBLE_EQ(*c.run.duration, 5.0);
  EXPECT_FALSE(c.run.t_bar_end.has_value());
  EXPECT_DOUBLE_EQ(*c.rods[0].omega, 2.5);
  EXPECT_FALSE(c.rods[0].omega_bar.has_value());
  const Config back = ParseConfig(ConfigToToml(c), "resolved.toml", {"run.t_bar_end=0.25"});
  EXPECT_DOUBLE_EQ(*back.run.t_bar_end, 0.25);
  EXPECT_FALSE(back.run.duration.has_value());
  // In a file, both at once is still an error.
  try {
    ParseConfig("[run]\nduration = 1.0\nt_bar_end = 0.5\n[[rods]]\n", "both.toml");
    FAIL() << "both run.duration and run.t_bar_end accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("exactly one of"), std::string::npos) << e.what();
  }
}

// Every double printed with the fewest digits that read back to the same bits.
TEST(ConfigText, NumbersArePrintedShortestAndReadBackExactly) {
  const Config c = ParseConfig(kHelix, "case.toml");
  const std::string text = ConfigToToml(c);
  for (const char* line : {"time_step = 0.02\n", "output_interval = 0.03\n", "t_bar_end = 0.5\n",
                           "young_modulus = 10000000.0\n", "radius = 0.001\n",
                           "force = [0.1, 1e-300, -0.3333333333333333]"})
    EXPECT_NE(text.find(line), std::string::npos) << line << " not in\n" << text;
  EXPECT_EQ(text.find("0000000001"), std::string::npos) << text;
  const Config back = ParseConfig(text, "resolved.toml");
  EXPECT_EQ(back.run.output_interval, c.run.output_interval);
  EXPECT_EQ(back.rods[0].loads[0].force, c.rods[0].loads[0].force);
  EXPECT_EQ(ConfigToToml(back), text);
  // Sections in the order of the SPEC, [run] first.
  EXPECT_EQ(text.rfind("[run]\n", 0), 0u) << text;
}

// docs/config_keys.md is generated from the field lists; it must be what they give today.
TEST(ConfigDocs, KeysPageIsUpToDate) {
  const std::string generated = ConfigKeysMarkdown();
  const std::string path = std::string(STOKESRODS_SOURCE_DIR) + "/docs/config_keys.md";
  if (const char* update = std::getenv("STOKESRODS_UPDATE_DOCS"); update && *update == '1')
    std::ofstream(path) << generated;
  std::ifstream in(path);
  std::stringstream page;
  page << in.rdbuf();
  EXPECT_EQ(page.str(), generated)
      << path << " is out of date; regenerate it with STOKESRODS_UPDATE_DOCS=1 "
      << "build/release/tests/io/io_test --gtest_filter=ConfigDocs.*";
}

TEST(ConfigDocs, EveryKeyOfTheReaderIsListedWithItsDefault) {
  const std::vector<ConfigKey> keys = ListConfigKeys();
  auto find = [&](const std::string& k) {
    for (const ConfigKey& c : keys)
      if (c.key == k) return c;
    return ConfigKey{};
  };
  EXPECT_EQ(find("run.time_step").default_value, "0.001");
  EXPECT_EQ(find("run.time_step").type, "number");
  EXPECT_EQ(find("run.duration").default_value, "");
  EXPECT_EQ(find("fluid.model").default_value, "\"rss\"");
  EXPECT_EQ(find("rods.base").default_value, "[0.0, 0.0, 0.0]");
  EXPECT_EQ(find("rods.loads[].node").type, "integer");
  EXPECT_EQ(find("flow_field.resolution").default_value, "[36, 126]");
}

}  // namespace
}  // namespace stokesrods
