// Replacing a user's file keeps the previous version beside it.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "spidar/core/file_read.hpp"
#include "spidar/core/file_write.hpp"
#include "temp_dir.hpp"

namespace spidar::core {
namespace {

using testing::TempDir;

std::string slurp(const std::string& p) {
  std::ifstream f(p);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

TEST(ReplaceFileKeepingPrevious, KeepsEachPreviousVersionUnderItsOwnName) {
  TempDir dir;
  const std::string p = dir.write("dev.yaml", "one\n");
  const std::string b1 = replace_file_keeping_previous(p, "two\n");
  const std::string b2 = replace_file_keeping_previous(p, "three\n");
  EXPECT_EQ(slurp(p), "three\n");
  EXPECT_NE(b1, b2);  // within one second: a numbered name, not an overwrite
  EXPECT_EQ(slurp(b1), "one\n");
  EXPECT_EQ(slurp(b2), "two\n");
  EXPECT_NE(b1.find("dev.yaml.bak-"), std::string::npos) << b1;
  EXPECT_FALSE(std::filesystem::exists(p + ".tmp"));
  // A new file has no previous version.
  EXPECT_EQ(replace_file_keeping_previous(dir.path() + "/new.yaml", "x"), "");
  EXPECT_EQ(slurp(dir.path() + "/new.yaml"), "x");
  // An unwritable place: a FileError naming it.
  EXPECT_THROW(replace_file_keeping_previous(dir.path() + "/no/such/dir/f", "x"), FileError);
}

}  // namespace
}  // namespace spidar::core
