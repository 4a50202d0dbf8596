#pragma once
// A fuzz target's corpus as a regression test: every file of `dir` goes through the entry point
// libFuzzer calls (LLVMFuzzerTestOneInput, linked in from fuzz/), which aborts on an invariant
// violation. So `make test` (CTest, no clang needed) replays the corpora that `make fuzz` grows.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace spidar::test {

/// Runs every regular file of `dir` (sorted by name) through the fuzz target; expects at least
/// `min_files` of them.
inline void replay_fuzz_corpus(const std::filesystem::path& dir, std::size_t min_files) {
  namespace fs = std::filesystem;
  ASSERT_TRUE(fs::is_directory(dir)) << dir;
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.is_regular_file()) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  EXPECT_GE(files.size(), min_files) << dir << ": the seed corpus is missing";
  for (const fs::path& f : files) {
    SCOPED_TRACE(f.filename().string());
    std::ifstream in(f, std::ios::binary);
    const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_EQ(LLVMFuzzerTestOneInput(bytes.data(), bytes.size()), 0);
  }
}

}  // namespace spidar::test
