#include "stokesrods/io/config_compare.h"

#include "stokesrods/io/config.h"

namespace stokesrods {

namespace {

// The defaults a new key is held against. `plain` is the top level of a default Config (no rods,
// no bodies, no wall): a whole section or list one side lacks is compared with it. `full` has one
// default rod, body and wall, whose tables hold the defaults of the keys inside list elements.
struct Defaults {
  nlohmann::json plain;
  nlohmann::json full;
};

const Defaults& ConfigDefaults() {
  static const Defaults defaults = [] {
    Config with_items;
    with_items.rods.emplace_back();
    with_items.bodies.emplace_back();
    with_items.wall.emplace();
    return Defaults{nlohmann::json::parse(ConfigToJson(Config{})),
                    nlohmann::json::parse(ConfigToJson(with_items))};
  }();
  return defaults;
}

const nlohmann::json& Child(const nlohmann::json& table, const std::string& key) {
  static const nlohmann::json kNone;
  return table.is_object() && table.contains(key) ? table[key] : kNone;
}

// The default of each element of a list of tables ([[rods]], [[bodies]]); null when unknown.
const nlohmann::json& ElementDefault(const nlohmann::json& list) {
  static const nlohmann::json kNone;
  return list.is_array() && list.size() == 1 && list[0].is_object() ? list[0] : kNone;
}

// `full` holds the defaults inside this value, `plain` the defaults of keys missing at this level.
bool Same(const nlohmann::json& before, const nlohmann::json& now, const nlohmann::json& full,
          const nlohmann::json& plain) {
  if (before.is_object() && now.is_object()) {
    for (const auto& [key, value] : before.items()) {
      if (!now.contains(key)) return false;
      const nlohmann::json& inner = Child(full, key);
      if (!Same(value, now[key], inner, inner)) return false;
    }
    for (const auto& [key, value] : now.items())
      if (!before.contains(key) && Child(plain, key) != value) return false;
    return true;
  }
  if (before.is_array() && now.is_array() && before.size() == now.size()) {
    const nlohmann::json& element = ElementDefault(full);
    for (std::size_t i = 0; i < before.size(); ++i)
      if (!Same(before[i], now[i], element, element)) return false;
    return true;
  }
  return before == now;
}

}  // namespace

bool SameRunSettings(const nlohmann::json& before, const nlohmann::json& now) {
  const Defaults& defaults = ConfigDefaults();
  return Same(before, now, defaults.full, defaults.plain);
}

}  // namespace stokesrods
