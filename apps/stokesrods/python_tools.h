// The commands written in Python (render, plot): `python3 -m stokesrods.MODULE ARGS...` with the
// package's directory on PYTHONPATH. They need NumPy, Matplotlib and ffmpeg, not the compiled module.
#pragma once

#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace stokesrods {

/// Adds a subcommand whose arguments all go to the Python tool.
CLI::App* AddPythonTool(CLI::App* app, const std::string& name, const std::string& description);

/// Runs the tool and returns its exit code (4 when the interpreter cannot be started).
/// Interpreter: $STOKESRODS_PYTHON or /usr/bin/python3; package directory:
/// $STOKESRODS_PYTHON_DIR or the source tree's python/.
int RunPythonTool(const std::string& module, const std::vector<std::string>& args);

}  // namespace stokesrods
