// The recording reader's fuzz corpus as a test: every file of fuzz/corpus/recording_reader goes
// through the entry point libFuzzer calls (fuzz/fuzz_recording_reader.cpp), which aborts on an
// invariant violation (an exception other than RecordingError, a message without FILE:LINE, or a
// row that does not read back the same after writing it again).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

TEST(FuzzCorpus, RecordingReaderCorpusPassesTheFuzzInvariants) {
  namespace fs = std::filesystem;
  const fs::path dir = SPIDAR_FUZZ_CORPUS;
  ASSERT_TRUE(fs::is_directory(dir)) << dir;
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.is_regular_file()) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  EXPECT_GE(files.size(), 8u) << "the seed corpus has a file per CSV and session.json, valid and damaged";
  for (const fs::path& f : files) {
    SCOPED_TRACE(f.filename().string());
    std::ifstream in(f, std::ios::binary);
    const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_EQ(LLVMFuzzerTestOneInput(bytes.data(), bytes.size()), 0);
  }
}

}  // namespace
