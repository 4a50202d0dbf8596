#pragma once
// A fresh, empty directory for a test's files (shared by the test suites).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

namespace spidar::test {

/// `name` with the process id under GoogleTest's temp dir, emptied and created.
inline std::string temp_dir(const std::string& name) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(::testing::TempDir()) / (name + "_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

}  // namespace spidar::test
