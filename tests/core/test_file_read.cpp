#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <functional>
#include <future>

#include "spidar/core/file_read.hpp"
#include "temp_dir.hpp"

namespace spidar::core {
namespace {

using testing::TempDir;

/// The FileError message of `fn`, or "no error".
std::string file_error_of(const std::function<void()>& fn) {
  try {
    fn();
  } catch (const FileError& e) {
    return e.what();
  }
  return "no error";
}

TEST(ReadFileBounded, ReadsARegularFileUpToTheLimit) {
  TempDir dir;
  const std::string bytes("a\0b\377cdef", 8);
  const auto path = dir.write("f.bin", bytes);
  EXPECT_EQ(read_file_bounded(path, 8, "a test file"), bytes);
  EXPECT_EQ(read_file_bounded(dir.write("empty", ""), 0, "a test file"), "");
}

TEST(ReadFileBounded, RefusesAFileAboveTheLimitNamingBothSizes) {
  TempDir dir;
  const auto path = dir.write("big", std::string(101, 'x'));
  EXPECT_EQ(file_error_of([&] { read_file_bounded(path, 100, "a test file"); }),
            path + ": 101 bytes, more than the 100 allowed for a test file");
}

TEST(ReadFileBounded, StopsReadingAFileWhoseSizeIsNotKnown) {
  // Files in /proc say they are empty regular files but have content.
  struct stat st {};
  if (::stat("/proc/self/maps", &st) != 0 || st.st_size != 0) GTEST_SKIP() << "no procfs";
  EXPECT_EQ(file_error_of([] { read_file_bounded("/proc/self/maps", 16, "a test file"); }),
            "/proc/self/maps: more than the 16 bytes allowed for a test file (it grew while "
            "being read, or its size was not known)");
}

TEST(ReadFileBounded, RefusesADirectory) {
  TempDir dir;
  try {
    read_file_bounded(dir.path(), 100, "a test file");
    ADD_FAILURE() << "no error";
  } catch (const FileError& e) {
    EXPECT_EQ(std::string(e.what()), dir.path() + ": is a directory");
    EXPECT_EQ(e.path(), dir.path());
    EXPECT_EQ(e.reason(), "is a directory");
  }
}

TEST(ReadFileBounded, RefusesADevice) {
  EXPECT_EQ(file_error_of([] { read_file_bounded("/dev/zero", 100, "a test file"); }),
            "/dev/zero: is not a regular file");
  EXPECT_EQ(file_error_of([] { read_file_bounded("/dev/null", 100, "a test file"); }),
            "/dev/null: is not a regular file");
}

TEST(ReadFileBounded, RefusesAFifoWithoutWaitingForAWriter) {
  TempDir dir;
  const std::string fifo = dir.path() + "/fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  auto result = std::async(std::launch::async, [&] {
    return file_error_of([&] { read_file_bounded(fifo, 100, "a test file"); });
  });
  // The call must not open the FIFO at all. Should it block in open(), a writer releases it so
  // the test fails instead of hanging.
  if (result.wait_for(std::chrono::seconds(10)) == std::future_status::timeout) {
    ADD_FAILURE() << "read_file_bounded blocked on a FIFO";
    const int fd = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
    if (fd >= 0) ::close(fd);
  }
  EXPECT_EQ(result.get(), fifo + ": is not a regular file");
}

TEST(ReadFileBounded, RefusesAPathWithANulCharacter) {
  TempDir dir;
  dir.write("a", "content");
  // c_str() would name the existing file `a`; the whole path names something else.
  const std::string path = dir.path() + "/a" + std::string(1, '\0') + ".yaml";
  EXPECT_EQ(file_error_of([&] { read_file_bounded(path, 100, "a test file"); }),
            dir.path() + "/a\\x00.yaml: path contains a NUL character");
}

TEST(ReadFileBounded, MissingFileAndControlCharactersInTheName) {
  EXPECT_EQ(file_error_of([] { read_file_bounded("/nonexistent/x.csv", 100, "a test file"); }),
            "/nonexistent/x.csv: cannot open file (does it exist and is it readable?)");
  EXPECT_EQ(file_error_of([] { read_file_bounded("/nonexistent/a\nb", 100, "a test file"); }),
            "/nonexistent/a\\x0ab: cannot open file (does it exist and is it readable?)");
}

}  // namespace
}  // namespace spidar::core
