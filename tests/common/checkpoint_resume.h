// A run and its resumption from a checkpoint, stepped side by side (for bit-identity tests).
#pragma once

#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <memory>
#include <string>

#include "stokesrods/io/simulation.h"
#include "common/scratch_dir.h"

namespace stokesrods {

struct ResumedPair {
  std::unique_ptr<Simulation> uninterrupted, resumed;
};

/// Runs the configuration `text` for `before` steps, saves a checkpoint, loads it into a fresh
/// Simulation, then steps both `after` more steps (a failed step is a test failure).
inline ResumedPair RunAndResume(const std::string& text, int before, int after) {
  const std::string path = testing::ScratchPath("stokesrods_resume").string();
  ResumedPair p{std::make_unique<Simulation>(ParseConfig(text, "case.toml")), nullptr};
  for (int k = 0; k < before; ++k) EXPECT_TRUE(p.uninterrupted->Step().ok);
  p.uninterrupted->SaveCheckpoint(path);
  p.resumed = std::make_unique<Simulation>(ParseConfig(text, "case.toml"));
  p.resumed->LoadCheckpoint(path);
  std::filesystem::remove(path);
  for (int k = 0; k < after; ++k) {
    EXPECT_TRUE(p.uninterrupted->Step().ok);
    EXPECT_TRUE(p.resumed->Step().ok);
  }
  return p;
}

}  // namespace stokesrods
