#include "python_tools.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

namespace stokesrods {

CLI::App* AddPythonTool(CLI::App* app, const std::string& name, const std::string& description) {
  CLI::App* tool = app->add_subcommand(name, description);
  tool->prefix_command();  // everything after the subcommand goes to the tool
  tool->allow_extras();
  return tool;
}

int RunPythonTool(const std::string& module, const std::vector<std::string>& args) {
  const char* env_python = std::getenv("STOKESRODS_PYTHON");
  const char* env_dir = std::getenv("STOKESRODS_PYTHON_DIR");
  const std::string python = env_python ? env_python : "/usr/bin/python3";
  const std::string dir = env_dir ? env_dir : STOKESRODS_PYTHON_SOURCE_DIR;
  const char* old_path = std::getenv("PYTHONPATH");
  const std::string path = old_path && *old_path ? dir + ":" + old_path : dir;
  std::vector<std::string> argv_text = {python, "-m", "stokesrods." + module};
  argv_text.insert(argv_text.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : argv_text) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t pid = fork();
  if (pid == 0) {
    setenv("PYTHONPATH", path.c_str(), 1);
    execv(python.c_str(), argv.data());
    fmt::print(stderr, "error: input/output: cannot start {}: {}\n", python, std::strerror(errno));
    _exit(4);
  }
  int status = 0;
  if (pid < 0 || waitpid(pid, &status, 0) < 0) {
    fmt::print(stderr, "error: input/output: cannot start {}\n", python);
    return 4;
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

}  // namespace stokesrods
