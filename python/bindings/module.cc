// The Python module stokesrods._core (SPEC "Python"): the C++ core bound with pybind11, nothing
// reimplemented. Configurations come as a TOML path or a dict of the same schema and go through
// the same reader and validation as the command line (ConfigError becomes ValueError).
#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings/convert.h"
#include "stokesrods/io/runner.h"
#include "stokesrods/io/writers.h"

namespace py = pybind11;

namespace stokesrods::python {
void BindSimulation(py::module_& m);  // simulation.cc

namespace {

py::dict RunResultDict(const RunResult& r) {
  static const char* kStatus[] = {"completed", "failed", "interrupted"};
  py::dict d;
  d["status"] = kStatus[static_cast<int>(r.status)];
  d["message"] = r.message;
  d["output_dir"] = r.output_dir;
  d["steps"] = r.steps;
  d["newton_iterations"] = r.newton_iterations;
  d["wall_seconds"] = r.wall_seconds;
  return d;
}

// Runs a case as `stokesrods run` does and returns what RunCase returns; the outputs are read
// back by the Python layer (stokesrods/results.py).
py::dict Run(const py::object& config, const py::object& overrides, const py::object& progress,
             bool resume) {
  const Config parsed = ConfigFromPython(config, overrides);
  RunOptions options;
  options.resume = resume;
  bool interrupted = false;
  options.interrupted = [&interrupted] {
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) {  // Ctrl-C in a terminal or a notebook
      PyErr_Clear();
      interrupted = true;
    }
    return interrupted;
  };
  if (!progress.is_none()) {
    options.progress = [&progress](const RunProgress& p) {
      py::gil_scoped_acquire gil;
      progress(p.time, p.duration, p.wall_seconds, p.steps);
    };
  }
  RunResult result;
  {
    py::gil_scoped_release release;
    result = RunCase(parsed, options);
  }
  if (interrupted) {
    PyErr_SetString(PyExc_KeyboardInterrupt,
                    (result.message + "; outputs flushed, checkpoint written in " + result.output_dir).c_str());
    throw py::error_already_set();
  }
  return RunResultDict(result);
}

}  // namespace
}  // namespace stokesrods::python

PYBIND11_MODULE(_core, m) {
  using namespace stokesrods;
  m.doc() = "stokesrods: elastic rods in a viscous Stokes fluid (the C++ core)";
  m.attr("__version__") = STOKESRODS_VERSION;
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const ConfigError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const IoError& e) {
      PyErr_SetString(PyExc_OSError, e.what());
    }
  });
  m.def("run", &python::Run, py::arg("config"), py::arg("overrides") = py::none(),
        py::arg("progress") = py::none(), py::arg("resume") = false,
        "Runs one case and writes its outputs (as `stokesrods run`); returns the status dict.");
  m.def(
      "resolve_config",
      [](const py::object& config, const py::object& overrides) {
        return ConfigToToml(python::ConfigFromPython(config, overrides));
      },
      py::arg("config"), py::arg("overrides") = py::none(),
      "The resolved configuration as TOML text (as `stokesrods show-config`).");
  python::BindSimulation(m);
}
