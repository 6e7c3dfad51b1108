// What a sweep's resume counts as the same run across versions (io/config_compare.h): an older
// summary's configuration lacks the keys added since; those count only when at their defaults.
#include <gtest/gtest.h>

#include <string>

#include "stokesrods/io/config.h"
#include "stokesrods/io/config_compare.h"

namespace stokesrods {
namespace {

const char* kTwoHelices =
    "[run]\nduration = 0.05\ntime_step = 0.01\nframes = false\n"
    "[[rods]]\nnodes = 11\nomega_bar = 100\n[[rods]]\nnodes = 11\nbase = [0.04, 0.0, 0.0]\n"
    "omega_bar = 100\n";

nlohmann::json Resolved(const std::vector<std::string>& overrides = {},
                        const std::string& more = "") {
  return nlohmann::json::parse(ConfigToJson(ParseConfig(kTwoHelices + more, "c.toml", overrides)));
}

// The configuration as a version without `section.key` (in every rod for "rods") wrote it.
nlohmann::json Without(nlohmann::json config, const std::string& section, const std::string& key) {
  if (section == "rods") {
    for (auto& rod : config["rods"]) rod.erase(key);
  } else {
    config[section].erase(key);
  }
  return config;
}

TEST(ConfigCompare, TheSameConfigurationIsTheSameRun) {
  EXPECT_TRUE(SameRunSettings(Resolved(), Resolved()));
  EXPECT_FALSE(SameRunSettings(Resolved(), Resolved({"rods.omega_bar=101"})));
  EXPECT_FALSE(SameRunSettings(Resolved(), Resolved({"rods.2.nodes=12"})));
}

TEST(ConfigCompare, KeysAddedSinceCountWhenAtTheirDefaults) {
  EXPECT_TRUE(SameRunSettings(Without(Resolved(), "rods", "body"), Resolved()));
  EXPECT_TRUE(SameRunSettings(Without(Resolved(), "solver", "max_step_halvings"), Resolved()));
  EXPECT_TRUE(SameRunSettings(Without(Resolved(), "rods", "lead_in"), Resolved()));
  // Set away from its default, the new key asks for another run than the old version made.
  EXPECT_FALSE(SameRunSettings(Without(Resolved(), "solver", "max_step_halvings"),
                               Resolved({"solver.max_step_halvings=3"})));
  EXPECT_FALSE(SameRunSettings(Without(Resolved(), "rods", "lead_in"),
                               Resolved({"rods.lead_in=\"above\""})));
  // One rod of two at a non-default value is enough.
  EXPECT_FALSE(SameRunSettings(Without(Resolved(), "rods", "lead_in"),
                               Resolved({"rods.2.lead_in=\"above\""})));
}

TEST(ConfigCompare, AKeyOrSectionOnlyOneSideHasIsAnotherRun) {
  nlohmann::json removed_since = Resolved();
  removed_since["run"]["old_key"] = 1.0;
  EXPECT_FALSE(SameRunSettings(removed_since, Resolved()));
  // A wall is a new section; its keys have defaults, but a wall the old run did not have is not.
  const nlohmann::json with_wall = Resolved({}, "[wall]\npoint = [0.0, 0.0, 0.05]\n");
  ASSERT_TRUE(with_wall.contains("wall"));
  nlohmann::json no_wall = with_wall;
  no_wall.erase("wall");
  EXPECT_FALSE(SameRunSettings(no_wall, with_wall));
  EXPECT_FALSE(SameRunSettings(with_wall, no_wall));
  nlohmann::json one_rod = Resolved();
  one_rod["rods"].erase(1);
  EXPECT_FALSE(SameRunSettings(one_rod, Resolved()));
}

}  // namespace
}  // namespace stokesrods
