#include "stokesrods/io/writers.h"
#include "stokesrods/io/config.h"

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "stokesrods/io/config_fields.h"
#include "stokesrods/io/config_overrides.h"

namespace stokesrods {

ConfigError::ConfigError(const std::string& file, const std::string& key,
                         const std::string& problem)
    : std::runtime_error(fmt::format("{}: {}: {}", file, key.empty() ? "(file)" : key, problem)),
      file_(file),
      key_(key) {}

namespace {

// ---- Reading: types checked here, values in Validate (config_validate.cc). ------------------

class Reader {
 public:
  Reader(const toml::table* table, std::string prefix, const std::string& file)
      : table_(table), prefix_(std::move(prefix)), file_(file) {}

  template <class T>
  void operator()(const char* key, T& field) {
    known_.insert(key);
    if (table_ == nullptr) return;
    const toml::node* node = table_->get(key);
    if (node != nullptr) Read(*node, Path(key), &field);
  }

  /// Every key of the table must have been visited.
  void RejectUnknownKeys() const {
    if (table_ == nullptr) return;
    for (const auto& [key, node] : *table_) {
      if (known_.count(std::string(key.str())) == 0) {
        std::string list;
        for (const std::string& k : known_) list += (list.empty() ? "" : ", ") + k;
        throw ConfigError(file_, Path(std::string(key.str())),
                          fmt::format("unknown key (known here: {})", list));
      }
    }
  }

 private:
  std::string Path(const std::string& key) const {
    return prefix_.empty() ? key : prefix_ + "." + key;
  }
  [[noreturn]] void Wrong(const std::string& path, const char* expected,
                          const toml::node& node) const {
    throw ConfigError(file_, path,
                      fmt::format("expected {}, got {}", expected, toml::impl::node_type_friendly_names
                                      [static_cast<int>(node.type())]));
  }
  void Read(const toml::node& n, const std::string& path, std::string* out) const {
    if (!n.is_string()) Wrong(path, "a string", n);
    *out = *n.value<std::string>();
  }
  void Read(const toml::node& n, const std::string& path, double* out) const {
    if (!n.is_number()) Wrong(path, "a number", n);
    *out = *n.value<double>();
  }
  void Read(const toml::node& n, const std::string& path, std::optional<double>* out) const {
    double v = 0.0;
    Read(n, path, &v);
    *out = v;
  }
  void Read(const toml::node& n, const std::string& path, int* out) const {
    if (!n.is_integer()) Wrong(path, "an integer", n);
    const std::int64_t v = *n.value<std::int64_t>();
    if (v < -1000000000 || v > 1000000000) throw ConfigError(file_, path, "integer out of range");
    *out = static_cast<int>(v);
  }
  void Read(const toml::node& n, const std::string& path, bool* out) const {
    if (!n.is_boolean()) Wrong(path, "true or false", n);
    *out = *n.value<bool>();
  }
  void Read(const toml::node& n, const std::string& path, Vec3* out) const {
    const toml::array* a = n.as_array();
    if (a == nullptr || a->size() != 3) Wrong(path, "an array of 3 numbers", n);
    for (int k = 0; k < 3; ++k) Read(*a->get(k), fmt::format("{}[{}]", path, k), &(*out)(k));
  }
  template <class T>
  void ReadList(const toml::node& n, const std::string& path, std::vector<T>* out,
                const char* expected) const {
    const toml::array* a = n.as_array();
    if (a == nullptr) Wrong(path, expected, n);
    out->assign(a->size(), T{});
    for (std::size_t i = 0; i < a->size(); ++i)
      Read(*a->get(i), fmt::format("{}[{}]", path, i), &(*out)[i]);
  }
  void Read(const toml::node& n, const std::string& path, std::vector<double>* out) const {
    ReadList(n, path, out, "an array of numbers");
  }
  void Read(const toml::node& n, const std::string& path, std::vector<int>* out) const {
    ReadList(n, path, out, "an array of integers");
  }
  void Read(const toml::node& n, const std::string& path, std::vector<Vec3>* out) const {
    const toml::array* a = n.as_array();
    if (a == nullptr) Wrong(path, "an array of [x, y, z] points", n);
    out->assign(a->size(), Vec3::Zero());
    for (std::size_t i = 0; i < a->size(); ++i)
      Read(*a->get(i), fmt::format("{}[{}]", path, i), &(*out)[i]);
  }
  template <class S>
  void Read(const toml::node& n, const std::string& path, std::vector<S>* out) const {
    const toml::array* a = n.as_array();
    if (a == nullptr) Wrong(path, "an array of tables", n);
    out->assign(a->size(), S{});
    for (std::size_t i = 0; i < a->size(); ++i) {
      const toml::table* t = a->get(i)->as_table();
      if (t == nullptr) Wrong(fmt::format("{}[{}]", path, i), "a table", *a->get(i));
      Reader inner(t, fmt::format("{}[{}]", path, i), file_);
      VisitFields((*out)[i], inner);
      inner.RejectUnknownKeys();
    }
  }

  const toml::table* table_;
  std::string prefix_;
  const std::string& file_;
  std::set<std::string> known_;
};

// ---- Writing the resolved configuration. ----------------------------------------------------

class Writer {
 public:
  explicit Writer(toml::table* table) : table_(table) {}
  template <class T>
  void operator()(const char* key, T& field) {
    Write(key, field);
  }

 private:
  void Write(const char* key, const std::string& v) { table_->insert_or_assign(key, v); }
  void Write(const char* key, double v) { table_->insert_or_assign(key, v); }
  void Write(const char* key, int v) { table_->insert_or_assign(key, v); }
  void Write(const char* key, bool v) { table_->insert_or_assign(key, v); }
  void Write(const char* key, const std::optional<double>& v) {
    if (v) table_->insert_or_assign(key, *v);
  }
  static toml::array Array(const Vec3& v) { return toml::array{v.x(), v.y(), v.z()}; }
  void Write(const char* key, const Vec3& v) { table_->insert_or_assign(key, Array(v)); }
  void Write(const char* key, std::vector<double>& v) {
    toml::array a;
    for (double x : v) a.push_back(x);
    table_->insert_or_assign(key, std::move(a));
  }
  void Write(const char* key, std::vector<int>& v) {
    toml::array a;
    for (int x : v) a.push_back(x);
    table_->insert_or_assign(key, std::move(a));
  }
  void Write(const char* key, std::vector<Vec3>& v) {
    if (v.empty()) return;
    toml::array a;
    for (const Vec3& p : v) a.push_back(Array(p));
    table_->insert_or_assign(key, std::move(a));
  }
  template <class S>
  void Write(const char* key, std::vector<S>& v) {
    if (v.empty()) return;
    toml::array a;
    for (S& s : v) {
      toml::table t;
      Writer inner(&t);
      VisitFields(s, inner);
      a.push_back(std::move(t));
    }
    table_->insert_or_assign(key, std::move(a));
  }
  toml::table* table_;
};

template <class S>
void ReadSection(const toml::table& root, const char* name, const std::string& file, S* out) {
  const toml::node* node = root.get(name);
  if (node != nullptr && !node->is_table())
    throw ConfigError(file, name, "expected a table ([" + std::string(name) + "])");
  Reader reader(node ? node->as_table() : nullptr, name, file);
  VisitFields(*out, reader);
  reader.RejectUnknownKeys();
}

// [[name]] tables, each read as one S (messages name them name.K, K from 1).
template <class S>
void ReadTables(const toml::table& root, const char* name, const std::string& file,
                std::vector<S>* out) {
  const toml::node* node = root.get(name);
  if (node == nullptr) return;
  if (!node->is_array_of_tables())
    throw ConfigError(file, name, fmt::format("expected [[{}]] tables", name));
  for (std::size_t i = 0; i < node->as_array()->size(); ++i) {
    S item;
    Reader reader(node->as_array()->get(i)->as_table(), fmt::format("{}.{}", name, i + 1), file);
    VisitFields(item, reader);
    reader.RejectUnknownKeys();
    out->push_back(std::move(item));
  }
}

// The sections other than [[rods]], in the order show-config prints them.
template <class F>
void VisitSections(Config& c, F f) {
  f("run", c.run);
  f("fluid", c.fluid);
  f("contact", c.contact);
  f("gravity", c.gravity);
  f("solver", c.solver);
  f("flow_field", c.flow_field);
}

toml::table ToTable(Config& c) {
  toml::table root;
  VisitSections(c, [&](const char* name, auto& s) {
    toml::table t;
    Writer w(&t);
    VisitFields(s, w);
    root.insert_or_assign(name, std::move(t));
  });
  Writer w(&root);
  w("rods", c.rods);
  if (c.rods.empty()) root.insert_or_assign("rods", toml::array{});
  w("bodies", c.bodies);
  if (c.wall) {
    toml::table t;
    Writer wall(&t);
    VisitFields(*c.wall, wall);
    root.insert_or_assign("wall", std::move(t));
  }
  return root;
}

// ---- TOML text with the shortest numbers that read back the same (0.2, not 0.20000000000000001).

std::string ValueText(const toml::node& node);

std::string QuotedString(const std::string& s) {
  std::string out = "\"";
  for (char ch : s) {
    if (ch == '"' || ch == '\\') out += '\\';
    if (static_cast<unsigned char>(ch) < 0x20) {
      out += fmt::format("\\u{:04X}", static_cast<int>(ch));
      continue;
    }
    out += ch;
  }
  return out + "\"";
}

std::string InlineTable(const toml::table& t) {
  std::string out = "{ ";
  for (const auto& [key, node] : t) out += fmt::format("{}{} = {}", out.size() > 2 ? ", " : "", key.str(), ValueText(node));
  return out + " }";
}

std::string ValueText(const toml::node& node) {
  if (const auto* d = node.as_floating_point()) {
    const double v = d->get();
    if (std::isnan(v)) return "nan";
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    std::string text = fmt::format("{}", v);  // shortest round trip
    if (text.find_first_of(".e") == std::string::npos) text += ".0";
    return text;
  }
  if (const auto* a = node.as_array()) {
    std::string out = "[";
    for (std::size_t i = 0; i < a->size(); ++i) out += (i ? ", " : "") + ValueText(*a->get(i));
    return out + "]";
  }
  if (const auto* t = node.as_table()) return InlineTable(*t);
  if (const auto* str = node.as_string()) return QuotedString(str->get());
  std::stringstream out;
  node.visit([&out](const auto& v) { out << v; });
  return out.str();
}

// "key = value" lines in the order of the field list.
class TextWriter {
 public:
  explicit TextWriter(std::string* out) : out_(out) {}
  template <class T>
  void operator()(const char* key, T& field) {
    toml::table t;
    Writer writer(&t);
    writer(key, field);
    if (const toml::node* node = t.get(key)) *out_ += fmt::format("{} = {}\n", key, ValueText(*node));
  }

 private:
  std::string* out_;
};

std::string TomlText(Config& c) {
  std::string out;
  TextWriter writer(&out);
  VisitSections(c, [&](const char* name, auto& section) {
    out += fmt::format("{}[{}]\n", out.empty() ? "" : "\n", name);
    VisitFields(section, writer);
  });
  for (RodConfig& rod : c.rods) {
    out += "\n[[rods]]\n";
    VisitFields(rod, writer);
  }
  for (BodyConfig& body : c.bodies) {
    out += "\n[[bodies]]\n";
    VisitFields(body, writer);
  }
  if (c.wall) {
    out += "\n[wall]\n";
    VisitFields(*c.wall, writer);
  }
  return out;
}

// ---- The list of keys (docs/config_keys.md). -------------------------------------------------

class KeyLister {
 public:
  KeyLister(std::string prefix, std::vector<ConfigKey>* out) : prefix_(std::move(prefix)), out_(out) {}
  template <class T>
  void operator()(const char* key, T& field) {
    toml::table t;
    Writer writer(&t);
    writer(key, field);
    const toml::node* node = t.get(key);
    const std::string value = node ? ValueText(*node) : "";
    out_->push_back({prefix_ + "." + key, TypeName(field), value == "\"\"" ? "" : value});
    Nested(prefix_ + "." + key, field);
  }

 private:
  static const char* TypeName(const std::string&) { return "string"; }
  static const char* TypeName(double) { return "number"; }
  static const char* TypeName(const std::optional<double>&) { return "number"; }
  static const char* TypeName(int) { return "integer"; }
  static const char* TypeName(bool) { return "boolean"; }
  static const char* TypeName(const Vec3&) { return "[x, y, z]"; }
  static const char* TypeName(const std::vector<double>&) { return "array of numbers"; }
  static const char* TypeName(const std::vector<int>&) { return "array of integers"; }
  static const char* TypeName(const std::vector<Vec3>&) { return "array of [x, y, z]"; }
  template <class S>
  static const char* TypeName(const std::vector<S>&) { return "array of tables"; }
  template <class T>
  void Nested(const std::string&, T&) {}
  void Nested(const std::string& path, std::vector<PointLoadConfig>&) {
    PointLoadConfig item;
    KeyLister inner(path + "[]", out_);
    VisitFields(item, inner);
  }

  std::string prefix_;
  std::vector<ConfigKey>* out_;
};

}  // namespace

void ValidateConfig(Config* config);  // config_validate.cc

Config ParseConfig(const std::string& toml_text, const std::string& file,
                   const std::vector<std::string>& overrides) {
  toml::table root;
  try {
    root = toml::parse(toml_text, file);
  } catch (const toml::parse_error& e) {
    throw ConfigError(file, fmt::format("line {}, column {}", e.source().begin.line,
                                        e.source().begin.column),
                      std::string(e.description()));
  }
  for (const std::string& o : overrides) ApplyOverride(&root, o, file);

  Config config;
  config.file = file;
  static const std::set<std::string> kSections = {
      "run", "fluid", "contact", "gravity", "solver", "flow_field", "rods", "bodies", "wall"};
  for (const auto& [key, node] : root)
    if (kSections.count(std::string(key.str())) == 0)
      throw ConfigError(file, std::string(key.str()),
                        "unknown section (known: run, fluid, contact, gravity, solver, "
                        "flow_field, rods, bodies, wall)");
  ReadSection(root, "run", file, &config.run);
  ReadSection(root, "fluid", file, &config.fluid);
  ReadSection(root, "contact", file, &config.contact);
  ReadSection(root, "gravity", file, &config.gravity);
  ReadSection(root, "solver", file, &config.solver);
  ReadSection(root, "flow_field", file, &config.flow_field);
  if (root.get("rods") == nullptr && root.get("bodies") == nullptr)
    throw ConfigError(file, "rods", "missing: at least one [[rods]] (or [[bodies]]) is required");
  ReadTables(root, "rods", file, &config.rods);
  ReadTables(root, "bodies", file, &config.bodies);
  if (root.get("wall") != nullptr) ReadSection(root, "wall", file, &config.wall.emplace());
  ValidateConfig(&config);
  return config;
}

Config LoadConfig(const std::string& path, const std::vector<std::string>& overrides) {
  const std::optional<std::string> text = ReadFileText(path);
  if (!text) throw ConfigError(path, "", "cannot open the file");
  return ParseConfig(*text, path, overrides);
}

std::vector<ConfigKey> ListConfigKeys() {
  Config defaults;
  std::vector<ConfigKey> keys;
  VisitSections(defaults, [&](const char* name, auto& section) {
    KeyLister lister(name, &keys);
    VisitFields(section, lister);
  });
  RodConfig rod;
  KeyLister rod_lister("rods", &keys);
  VisitFields(rod, rod_lister);
  BodyConfig body;
  KeyLister body_lister("bodies", &keys);
  VisitFields(body, body_lister);
  WallConfig wall;
  KeyLister wall_lister("wall", &keys);
  VisitFields(wall, wall_lister);
  return keys;
}

std::string ConfigToToml(const Config& config) {
  Config copy = config;
  return TomlText(copy);
}

std::string ConfigToJson(const Config& config) {
  Config copy = config;
  std::stringstream out;
  out << toml::json_formatter{ToTable(copy)};
  return out.str();
}

}  // namespace stokesrods
