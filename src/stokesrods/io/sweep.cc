#include "stokesrods/io/sweep.h"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "stokesrods/io/analysis.h"
#include "stokesrods/io/config.h"
#include "stokesrods/io/config_compare.h"
#include "stokesrods/io/writers.h"

namespace stokesrods {

namespace fs = std::filesystem;

namespace {

using KeyValues = std::vector<std::pair<std::string, const toml::node*>>;

// Dotted keys of a table's leaves ("rods.omega_bar" written quoted or as nested tables), in the
// order they appear in the file (toml++ iterates tables in key order).
void Flatten(const toml::table& table, const std::string& prefix, KeyValues* out) {
  for (const auto& [key, node] : table) {
    const std::string dotted = prefix.empty() ? std::string(key.str()) : prefix + "." + std::string(key.str());
    if (node.is_table()) {
      Flatten(*node.as_table(), dotted, out);
    } else {
      out->emplace_back(dotted, &node);
    }
  }
  if (!prefix.empty()) return;
  std::stable_sort(out->begin(), out->end(), [](const auto& a, const auto& b) {
    const toml::source_position pa = a.second->source().begin, pb = b.second->source().begin;
    return pa.line != pb.line ? pa.line < pb.line : pa.column < pb.column;
  });
}

// A TOML value as the text --set parses back, floats in their shortest exact form: 43, 0.04,
// "lsbt", [0.04, 0.0, 0.0].
std::string TomlText(const toml::node& node) {
  if (const auto* v = node.as_floating_point()) {
    std::string text = fmt::format("{}", v->get());
    if (text.find_first_of(".eEn") == std::string::npos) text += ".0";  // stays a float
    return text;
  }
  if (const auto* a = node.as_array()) {
    std::string text = "[";
    for (std::size_t i = 0; i < a->size(); ++i) text += (i > 0 ? ", " : "") + TomlText(*a->get(i));
    return text + "]";
  }
  std::stringstream s;
  node.visit([&](const auto& v) { s << v; });
  return s.str();
}

// A folder name from the case's values, keys in sorted order (so the name does not change when
// the sweep file lists its keys or values in another order): characters other than
// [A-Za-z0-9._+=-] become '_'.
std::string FolderName(const std::string& prefix,
                       std::vector<std::pair<std::string, std::string>> values) {
  std::sort(values.begin(), values.end());
  std::string name = prefix;
  for (const auto& [key, text] : values) {
    std::string part = key.substr(key.rfind('.') == std::string::npos ? 0 : key.rfind('.') + 1);
    if (key.rfind("rods.", 0) == 0 && key.size() > 5 && std::isdigit(key[5])) part = "rod" + key.substr(5, key.find('.', 5) - 5) + "." + part;
    part += "=" + text;
    if (!name.empty()) name += "__";
    name += part;
  }
  std::string clean;
  for (char ch : name) {
    const bool keep = std::isalnum(static_cast<unsigned char>(ch)) || ch == '.' || ch == '_' ||
                      ch == '-' || ch == '+' || ch == '=';
    if (!keep && !clean.empty() && clean.back() == '_') continue;
    clean += keep ? ch : '_';
  }
  return clean.empty() ? std::string("case") : clean;
}

struct CaseSpec {
  std::string prefix;
  KeyValues keys;
};

// The explicit [[cases]] (one empty case when there are none).
std::vector<CaseSpec> ReadCases(const toml::table& root, const std::string& file) {
  const toml::node* node = root.get("cases");
  if (node == nullptr) return {CaseSpec{}};
  if (!node->is_array_of_tables() || node->as_array()->empty())
    throw ConfigError(file, "cases", "expected one or more [[cases]] tables");
  std::vector<CaseSpec> cases;
  for (const auto& entry : *node->as_array()) {
    CaseSpec spec;
    for (const auto& [key, value] : *entry.as_table()) {
      if (key.str() == "name") {
        if (!value.is_string()) throw ConfigError(file, "cases.name", "expected a string");
        spec.prefix = **value.as_string();
      }
    }
    Flatten(*entry.as_table(), "", &spec.keys);
    std::erase_if(spec.keys, [](const auto& kv) { return kv.first == "name"; });
    cases.push_back(std::move(spec));
  }
  return cases;
}

std::string Override(const std::string& key, const std::string& text) { return key + "=" + text; }

bool IsVaried(const Sweep& sweep, const std::string& key) {
  return std::find(sweep.varied_keys.begin(), sweep.varied_keys.end(), key) != sweep.varied_keys.end();
}

// [[adjust]]: `where` names varied keys only, the other keys are not varied ones.
std::vector<SweepAdjust> ReadAdjustments(const toml::table& root, const Sweep& sweep) {
  const toml::node* node = root.get("adjust");
  if (node == nullptr) return {};
  const std::string& file = sweep.file;
  if (!node->is_array_of_tables() || node->as_array()->empty())
    throw ConfigError(file, "adjust", "expected one or more [[adjust]] tables");
  std::vector<SweepAdjust> adjustments;
  for (const auto& entry : *node->as_array()) {
    toml::table keys = *entry.as_table();
    const toml::node* where = keys.get("where");
    if (where == nullptr || !where->is_table() || where->as_table()->empty())
      throw ConfigError(file, "adjust.where", "expected a table of varied keys and the values that select the cases");
    SweepAdjust adjust;
    KeyValues selected, set;
    Flatten(*where->as_table(), "", &selected);
    for (const auto& [key, value] : selected) {
      if (!IsVaried(sweep, key))
        throw ConfigError(file, "adjust.where." + key, "not a varied key ([[cases]] or [vary]): it selects no case");
      adjust.where.emplace_back(key, TomlText(*value));
    }
    keys.erase("where");
    Flatten(keys, "", &set);
    if (set.empty()) throw ConfigError(file, "adjust", "an [[adjust]] entry sets no key besides `where`");
    for (const auto& [key, value] : set) {
      if (IsVaried(sweep, key))
        throw ConfigError(file, "adjust." + key, "a varied key: give its values in [[cases]] or [vary]");
      adjust.overrides.push_back(Override(key, TomlText(*value)));
    }
    adjustments.push_back(std::move(adjust));
  }
  return adjustments;
}

// Two values as TOML text: numbers compare as numbers (550 and 550.0 are the same), others as text.
bool SameValue(const std::string& a, const std::string& b) {
  char* end_a = nullptr;
  char* end_b = nullptr;
  const double x = std::strtod(a.c_str(), &end_a);
  const double y = std::strtod(b.c_str(), &end_b);
  const bool numbers = !a.empty() && !b.empty() && *end_a == '\0' && *end_b == '\0';
  return numbers ? x == y : a == b;
}

bool Matches(const SweepAdjust& adjust, const std::vector<std::pair<std::string, std::string>>& values) {
  for (const auto& entry : adjust.where) {  // not a structured binding: clang 14 cannot capture one
    const std::string& key = entry.first;
    const auto it = std::find_if(values.begin(), values.end(), [&](const auto& kv) { return kv.first == key; });
    if (it == values.end() || !SameValue(it->second, entry.second)) return false;
  }
  return true;
}

std::optional<RefineSpec> ReadRefine(const toml::table& root, const Sweep& sweep) {
  const toml::node* node = root.get("refine");
  if (node == nullptr) return std::nullopt;
  const std::string& file = sweep.file;
  if (!node->is_table()) throw ConfigError(file, "refine", "expected a table");
  const toml::table& t = *node->as_table();
  for (const auto& [key, value] : t)
    if (key.str() != "key" && key.str() != "criterion" && key.str() != "resolution")
      throw ConfigError(file, "refine." + std::string(key.str()), "unknown key (known: key, criterion, resolution)");
  RefineSpec spec;
  spec.key = t["key"].value_or(std::string());
  if (std::find(sweep.varied_keys.begin(), sweep.varied_keys.end(), spec.key) == sweep.varied_keys.end())
    throw ConfigError(file, "refine.key", "expected one of the varied keys");
  spec.criterion = t["criterion"].value_or(std::string());
  const std::vector<std::string>& criteria = OutcomeCriteria();
  if (std::find(criteria.begin(), criteria.end(), spec.criterion) == criteria.end())
    throw ConfigError(file, "refine.criterion", "expected \"crossed\", \"ever_crossed\" or \"buckled\"");
  spec.resolution = t["resolution"].value_or(0.0);
  if (!(spec.resolution > 0.0)) throw ConfigError(file, "refine.resolution", "expected a number > 0");
  return spec;
}

}  // namespace

std::string OutputOverride(const std::string& dir) {
  return "run.output=" + TomlText(toml::value<std::string>(dir));
}

Sweep ParseSweep(const std::string& toml_text, const std::string& file, const std::string& dir,
                 const std::string& output) {
  toml::table root;
  try {
    root = toml::parse(toml_text, file);
  } catch (const toml::parse_error& e) {
    throw ConfigError(file, fmt::format("line {}", e.source().begin.line), std::string(e.description()));
  }
  static const std::set<std::string> kKeys = {"base", "output", "set", "vary", "cases", "adjust", "refine"};
  for (const auto& [key, node] : root)
    if (kKeys.count(std::string(key.str())) == 0)
      throw ConfigError(file, std::string(key.str()),
                        "unknown key (known: base, output, set, vary, cases, adjust, refine)");
  Sweep sweep;
  sweep.file = file;
  const auto base = root["base"].value<std::string>();
  if (!base) throw ConfigError(file, "base", "missing or not a string: the configuration to vary");
  sweep.base = (fs::path(dir) / *base).lexically_normal().string();
  if (!fs::exists(sweep.base)) throw ConfigError(file, "base", fmt::format("{}: no such file", sweep.base));
  sweep.output = output.empty() ? root["output"].value_or(std::string()) : output;
  if (sweep.output.empty()) throw ConfigError(file, "output", "missing or not a string: the sweep's folder");

  KeyValues fixed, varied;
  for (const char* section : {"set", "vary"}) {
    const toml::node* node = root.get(section);
    if (node == nullptr) continue;
    if (!node->is_table()) throw ConfigError(file, section, "expected a table");
    Flatten(*node->as_table(), "", section == std::string("set") ? &fixed : &varied);
  }
  for (const auto& [key, node] : varied)
    if (!node->is_array() || node->as_array()->empty())
      throw ConfigError(file, "vary." + key, "expected a non-empty list of values");
  const std::vector<CaseSpec> specs = ReadCases(root, file);

  // Column order: the keys of the explicit cases (first seen), then the [vary] keys.
  for (const CaseSpec& spec : specs)
    for (const auto& kv : spec.keys)
      if (std::find(sweep.varied_keys.begin(), sweep.varied_keys.end(), kv.first) == sweep.varied_keys.end())
        sweep.varied_keys.push_back(kv.first);
  for (const auto& kv : varied) sweep.varied_keys.push_back(kv.first);
  for (const auto& [key, node] : fixed) sweep.fixed_overrides.push_back(Override(key, TomlText(*node)));
  sweep.refine = ReadRefine(root, sweep);
  sweep.adjustments = ReadAdjustments(root, sweep);

  std::set<std::string> names;
  for (const CaseSpec& spec : specs) {
    // Odometer over the [vary] lists, the last key fastest.
    std::vector<std::size_t> at(varied.size(), 0);
    for (bool more = true; more;) {
      std::vector<std::pair<std::string, std::string>> values;
      for (const auto& [key, node] : spec.keys) values.emplace_back(key, TomlText(*node));
      for (std::size_t k = 0; k < varied.size(); ++k)
        values.emplace_back(varied[k].first, TomlText(*varied[k].second->as_array()->get(at[k])));
      SweepCase c = MakeSweepCase(sweep, spec.prefix, std::move(values));
      if (!names.insert(c.name).second)
        throw ConfigError(file, c.name, "two cases have the same values (duplicate case)");
      sweep.cases.push_back(std::move(c));
      more = false;
      for (std::size_t k = varied.size(); k-- > 0;) {
        if (++at[k] < varied[k].second->as_array()->size()) {
          more = true;
          break;
        }
        at[k] = 0;
      }
    }
  }
  for (std::size_t i = 0; i < sweep.adjustments.size(); ++i) {
    const auto matches = [&](const SweepCase& c) { return Matches(sweep.adjustments[i], c.values); };
    if (std::none_of(sweep.cases.begin(), sweep.cases.end(), matches))
      throw ConfigError(file, "adjust", fmt::format("[[adjust]] entry {} matches no case", i + 1));
  }
  for (const SweepCase& c : sweep.cases) {
    try {
      LoadConfig(sweep.base, c.overrides);
    } catch (const ConfigError& e) {
      throw ConfigError(file, e.key(), fmt::format("case {}: {}", c.name, e.what()));
    }
  }
  return sweep;
}

SweepCase MakeSweepCase(const Sweep& sweep, const std::string& prefix,
                        std::vector<std::pair<std::string, std::string>> values) {
  SweepCase c;
  c.prefix = prefix;
  c.overrides = sweep.fixed_overrides;
  for (const SweepAdjust& adjust : sweep.adjustments)
    if (Matches(adjust, values)) c.overrides.insert(c.overrides.end(), adjust.overrides.begin(), adjust.overrides.end());
  for (const auto& [key, text] : values) c.overrides.push_back(Override(key, text));
  c.values = std::move(values);
  c.name = FolderName(prefix, c.values);
  c.output_dir = (fs::path(sweep.output) / c.name).string();
  return c;
}

nlohmann::json CaseToJson(const SweepCase& c) {
  return {{"prefix", c.prefix}, {"name", c.name}, {"values", c.values},
          {"overrides", c.overrides}, {"output_dir", c.output_dir}};
}

SweepCase CaseFromJson(const nlohmann::json& j) {
  SweepCase c;
  c.prefix = j.at("prefix").get<std::string>();
  c.name = j.at("name").get<std::string>();
  c.values = j.at("values").get<std::vector<std::pair<std::string, std::string>>>();
  c.overrides = j.at("overrides").get<std::vector<std::string>>();
  c.output_dir = j.at("output_dir").get<std::string>();
  return c;
}

void WriteSweepJson(const Sweep& sweep) {
  nlohmann::json j = {{"file", sweep.file}, {"base", sweep.base}, {"output", sweep.output},
                      {"varied_keys", sweep.varied_keys}, {"fixed_overrides", sweep.fixed_overrides}};
  j["refine"] = sweep.refine ? nlohmann::json{{"key", sweep.refine->key},
                                              {"criterion", sweep.refine->criterion},
                                              {"resolution", sweep.refine->resolution}}
                             : nlohmann::json();
  j["adjust"] = nlohmann::json::array();
  for (const SweepAdjust& a : sweep.adjustments) j["adjust"].push_back({{"where", a.where}, {"overrides", a.overrides}});
  j["cases"] = nlohmann::json::array();
  for (const SweepCase& c : sweep.cases) j["cases"].push_back(CaseToJson(c));
  std::error_code ec;
  fs::create_directories(sweep.output, ec);
  WriteFileAtomically((fs::path(sweep.output) / "sweep.json").string(), j.dump(1) + "\n");
}

Sweep ReadSweepJson(const std::string& dir) {
  const fs::path path = fs::path(dir) / "sweep.json";
  std::ifstream in(path);
  if (!in) throw IoError(path.string() + ": cannot read (not a sweep's folder?)");
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
  if (!j.is_object()) throw IoError(path.string() + ": not JSON");
  Sweep sweep;
  try {
    sweep.file = j.at("file").get<std::string>();
    sweep.base = j.at("base").get<std::string>();
    sweep.output = dir;
    sweep.varied_keys = j.at("varied_keys").get<std::vector<std::string>>();
    sweep.fixed_overrides = j.at("fixed_overrides").get<std::vector<std::string>>();
    if (!j.at("refine").is_null())
      sweep.refine = RefineSpec{j["refine"].at("key").get<std::string>(),
                                j["refine"].at("criterion").get<std::string>(),
                                j["refine"].at("resolution").get<double>()};
    for (const nlohmann::json& a : j.value("adjust", nlohmann::json::array()))  // absent before [[adjust]]
      sweep.adjustments.push_back({a.at("where").get<std::vector<std::pair<std::string, std::string>>>(),
                                   a.at("overrides").get<std::vector<std::string>>()});
    for (const nlohmann::json& c : j.at("cases")) {
      sweep.cases.push_back(CaseFromJson(c));
      sweep.cases.back().output_dir = (fs::path(dir) / sweep.cases.back().name).string();
    }
  } catch (const nlohmann::json::exception& e) {
    throw IoError(fmt::format("{}: {}", path.string(), e.what()));
  }
  return sweep;
}

Sweep LoadSweep(const std::string& path, const std::string& output) {
  const std::optional<std::string> text = ReadFileText(path);
  if (!text) throw ConfigError(path, "", "cannot open the file");
  return ParseSweep(*text, path, fs::path(path).parent_path().string(), output);
}

std::vector<std::string> CaseArguments(const Sweep& sweep, const SweepCase& c, bool resume) {
  std::vector<std::string> args = {"run", sweep.base, "--output", c.output_dir};
  for (const std::string& o : c.overrides) {
    args.push_back("--set");
    args.push_back(o);
  }
  if (resume) args.push_back("--resume");
  return args;
}

}  // namespace stokesrods
