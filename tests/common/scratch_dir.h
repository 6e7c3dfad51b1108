// Scratch paths of a test process under the system's temporary directory, removed when the
// process ends with all its tests passed (kept for inspection when one failed).
#pragma once

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

#include <gtest/gtest.h>

namespace stokesrods::testing {

/// temp/<name>.<pid> (a directory or a file; created by the caller), removed at exit if every
/// test of the process passed.
inline std::filesystem::path ScratchPath(const std::string& name) {
  struct Remover {
    std::vector<std::filesystem::path> paths;
    ~Remover() {
      if (!::testing::UnitTest::GetInstance()->Passed()) return;
      std::error_code ignored;
      for (const auto& p : paths) std::filesystem::remove_all(p, ignored);
    }
  };
  static Remover remover;
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / (name + "." + std::to_string(getpid()));
  if (std::find(remover.paths.begin(), remover.paths.end(), path) == remover.paths.end())
    remover.paths.push_back(path);
  return path;
}

}  // namespace stokesrods::testing
