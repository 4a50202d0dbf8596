#pragma once
// A fresh, empty directory for a test's files (shared by the test suites), removed when the test
// program exits with every test passed (a failed test's files stay for a look).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <mutex>
#include <string>
#include <system_error>
#include <vector>

namespace spidar::test {

namespace detail {
/// The directories temp_dir() made in this process; removed at exit if every test passed.
struct TempDirs {
  std::mutex mutex;
  std::vector<std::filesystem::path> dirs;
  ~TempDirs() {
    const ::testing::UnitTest* u = ::testing::UnitTest::GetInstance();
    if (u == nullptr || !u->Passed()) return;
    std::error_code ec;  // best effort: a directory a test still holds open stays
    for (const auto& d : dirs) std::filesystem::remove_all(d, ec);
  }
};
inline TempDirs& temp_dirs() {
  static TempDirs dirs;
  return dirs;
}
}  // namespace detail

/// `name` with the process id under GoogleTest's temp dir, where nothing is yet (anything there
/// is removed); removed again at exit when every test passed.
inline std::string scratch_path(const std::string& name) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(::testing::TempDir()) / (name + "_" + std::to_string(getpid()));
  fs::remove_all(dir);
  detail::TempDirs& t = detail::temp_dirs();
  const std::lock_guard<std::mutex> lock(t.mutex);
  t.dirs.push_back(dir);
  return dir.string();
}

/// scratch_path(name), created as an empty directory.
inline std::string temp_dir(const std::string& name) {
  const std::string dir = scratch_path(name);
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace spidar::test
