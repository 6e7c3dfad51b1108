#include "bindings/convert.h"

#include <sstream>
#include <string>
#include <vector>

#include <toml++/toml.h>

namespace py = pybind11;

namespace stokesrods::python {
namespace {

const char* kDictName = "<dict>";

toml::table ToTable(const py::dict& dict, const std::string& path);

// One Python value appended to `out` as a TOML node; `path` names it in errors (the dotted key).
void Emit(py::handle value, const std::string& path, toml::array* out) {
  py::object v = py::reinterpret_borrow<py::object>(value);
  if (py::hasattr(v, "tolist")) v = v.attr("tolist")();  // NumPy arrays and scalars
  if (py::isinstance<py::bool_>(v)) {
    out->push_back(v.cast<bool>());
  } else if (py::isinstance<py::int_>(v)) {
    out->push_back(v.cast<std::int64_t>());
  } else if (py::isinstance<py::float_>(v)) {
    out->push_back(v.cast<double>());
  } else if (py::isinstance<py::str>(v)) {
    out->push_back(v.cast<std::string>());
  } else if (py::isinstance<py::dict>(v)) {
    out->push_back(ToTable(v.cast<py::dict>(), path));
  } else if (py::isinstance<py::list>(v) || py::isinstance<py::tuple>(v)) {
    toml::array array;
    std::size_t i = 0;
    for (py::handle item : v) Emit(item, path + "[" + std::to_string(i++) + "]", &array);
    out->push_back(std::move(array));
  } else {
    throw ConfigError(kDictName, path,
                      "cannot be given as a Python " +
                          py::str(v.get_type().attr("__name__")).cast<std::string>() +
                          " (use numbers, strings, booleans, lists and dicts)");
  }
}

// The single node of a one-element array (a copy).
toml::node_view<toml::node> Only(toml::array& one) { return toml::node_view<toml::node>(one.get(0)); }

toml::table ToTable(const py::dict& dict, const std::string& path) {
  toml::table table;
  for (auto [key, value] : dict) {
    if (!py::isinstance<py::str>(key))
      throw ConfigError(kDictName, path, "keys must be strings");
    const std::string name = key.cast<std::string>();
    const std::string full = path.empty() ? name : path + "." + name;
    toml::array one;
    Emit(value, full, &one);
    table.insert_or_assign(name, Only(one));
  }
  return table;
}

// The TOML text of one value, as --set takes it (KEY=VALUE).
std::string ValueText(py::handle value, const std::string& key) {
  toml::table t;
  toml::array one;
  Emit(value, key, &one);
  t.insert_or_assign("v", Only(one));
  std::stringstream out;
  out << t;
  std::string text = out.str();
  return text.substr(text.find('=') + 1);
}

std::vector<std::string> Overrides(const py::handle& overrides) {
  std::vector<std::string> sets;
  if (overrides.is_none()) return sets;
  if (py::isinstance<py::dict>(overrides)) {
    for (auto [key, value] : overrides.cast<py::dict>()) {
      const std::string k = py::str(key).cast<std::string>();
      sets.push_back(k + "=" + ValueText(value, k));
    }
    return sets;
  }
  for (py::handle item : overrides) sets.push_back(py::str(item).cast<std::string>());
  return sets;
}

}  // namespace

Config ConfigFromPython(const py::handle& config, const py::handle& overrides) {
  const std::vector<std::string> sets = Overrides(overrides);
  if (py::isinstance<py::dict>(config)) {
    std::stringstream text;
    text << ToTable(config.cast<py::dict>(), "");
    return ParseConfig(text.str(), kDictName, sets);
  }
  const std::string path = py::module_::import("os").attr("fspath")(config).cast<std::string>();
  return LoadConfig(path, sets);
}

}  // namespace stokesrods::python
