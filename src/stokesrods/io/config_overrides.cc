// The command line's --set KEY=VALUE overrides, applied to the parsed TOML before it is read
// (io/config_overrides.h).
#include "stokesrods/io/config_overrides.h"

#include <sstream>
#include <vector>

#include <fmt/format.h>

#include "stokesrods/io/config.h"

namespace stokesrods {

namespace {

std::vector<std::string> Split(const std::string& s, char sep) {
  std::vector<std::string> parts;
  std::stringstream in(s);
  for (std::string part; std::getline(in, part, sep);) parts.push_back(part);
  return parts;
}

// Keys of which a configuration gives exactly one: an override of one replaces the other
// (--set run.duration=5 on a file that sets run.t_bar_end).
const char* AlternativeKey(const std::string& key) {
  if (key == "duration") return "t_bar_end";
  if (key == "t_bar_end") return "duration";
  if (key == "omega") return "omega_bar";
  if (key == "omega_bar") return "omega";
  return nullptr;
}

void SetKey(toml::table* table, const std::vector<std::string>& path, std::size_t i,
            const toml::node_view<toml::node>& value, const std::string& file,
            const std::string& full) {
  if (i + 1 == path.size()) {
    table->insert_or_assign(path[i], value);
    if (const char* other = AlternativeKey(path[i])) table->erase(other);
    return;
  }
  toml::node* child = table->get(path[i]);
  if (child == nullptr) {
    table->insert_or_assign(path[i], toml::table{});
    child = table->get(path[i]);
  }
  if (!child->is_table()) throw ConfigError(file, full, "--set path goes through a non-table");
  SetKey(child->as_table(), path, i + 1, value, file, full);
}

}  // namespace

void ApplyOverride(toml::table* root, const std::string& assignment, const std::string& file) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw ConfigError(file, assignment, "--set expects KEY=VALUE");
  const std::string key = assignment.substr(0, eq);
  const std::string text = assignment.substr(eq + 1);
  toml::table parsed;
  try {
    parsed = toml::parse("v = " + text);
  } catch (const toml::parse_error&) {
    parsed = toml::table{{"v", text}};  // a bare word is a string: fluid.model=lsbt
  }
  const toml::node_view<toml::node> value = parsed["v"];
  std::vector<std::string> path = Split(key, '.');
  const std::string list_name = path.front();  // [[rods]] and [[bodies]]: every one or one by K
  if (list_name != "rods" && list_name != "bodies") {
    SetKey(root, path, 0, value, file, key);
    return;
  }
  const std::string item = list_name == "rods" ? "rod" : "body";
  toml::array* rods = root->get_as<toml::array>(list_name);
  if (rods == nullptr || path.size() < 2)
    throw ConfigError(file, key, fmt::format("no [[{}]] to set", list_name));
  const bool indexed = !path[1].empty() && path[1].find_first_not_of("0123456789") == std::string::npos;
  if (indexed) {
    // More digits than any rod count: out of range without overflowing the conversion.
    const std::size_t k = path[1].size() > 9 ? std::size_t(-1) : std::stoul(path[1]);
    if (k < 1 || k > rods->size())
      throw ConfigError(file, key, fmt::format("{} {} does not exist (there are {})", item,
                                               path[1], rods->size()));
    path.erase(path.begin(), path.begin() + 2);
    if (path.empty())
      throw ConfigError(file, key, fmt::format("--set needs a key after the {} number", item));
    SetKey(rods->get(k - 1)->as_table(), path, 0, value, file, key);
    return;
  }
  path.erase(path.begin());
  for (auto& rod : *rods) SetKey(rod.as_table(), path, 0, value, file, key);
}


}  // namespace stokesrods
