// Whole-file writes: new content or old content, through symbolic links, errors naming the path.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "spidar/core/atomic_write.hpp"
#include "temp_dir.hpp"

namespace {

namespace fs = std::filesystem;
using spidar::core::FileError;
using spidar::core::write_file_atomic;
using spidar::core::testing::TempDir;

std::string slurp(const std::string& p) {
  std::ifstream f(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(f), {});
}

std::size_t entries(const std::string& dir) {
  std::size_t n = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++n;
  return n;
}

TEST(AtomicWrite, CreatesAndReplacesAFileAndLeavesNoTemporaryFile) {
  TempDir d;
  const std::string p = d.path() + "/report.json";
  write_file_atomic(p, "first\n");
  EXPECT_EQ(slurp(p), "first\n");
  write_file_atomic(p, "second, longer\n", {.sync = false});
  EXPECT_EQ(slurp(p), "second, longer\n");
  write_file_atomic(p, "");
  EXPECT_EQ(slurp(p), "");
  EXPECT_EQ(entries(d.path()), 1u);
}

TEST(AtomicWrite, KeepsTheFilesPermissions) {
  TempDir d;
  const std::string p = d.write("cfg.yaml", "old");
  fs::permissions(p, fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
  write_file_atomic(p, "new");
  EXPECT_EQ(fs::status(p).permissions() & fs::perms::all,
            fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
}

TEST(AtomicWrite, WritesThroughASymlinkChainAndKeepsTheLinks) {
  TempDir d;
  fs::create_directories(d.path() + "/real");
  const std::string target = d.write("real/dev.yaml", "old");
  fs::create_symlink("real/dev.yaml", d.path() + "/link1");    // relative
  fs::create_symlink(d.path() + "/link1", d.path() + "/link2");  // absolute, to a link
  write_file_atomic(d.path() + "/link2", "new content");
  EXPECT_TRUE(fs::is_symlink(d.path() + "/link1"));
  EXPECT_TRUE(fs::is_symlink(d.path() + "/link2"));
  EXPECT_EQ(slurp(target), "new content");
  EXPECT_EQ(slurp(d.path() + "/link2"), "new content");
  // A dangling link names the file to create.
  fs::create_symlink("real/new.json", d.path() + "/dangling");
  write_file_atomic(d.path() + "/dangling", "created");
  EXPECT_EQ(slurp(d.path() + "/real/new.json"), "created");
  EXPECT_TRUE(fs::is_symlink(d.path() + "/dangling"));
}

TEST(AtomicWrite, RefusesDirectoriesDevicesAndLinkLoopsNamingThePath) {
  TempDir d;
  fs::create_directories(d.path() + "/sub");
  try {
    write_file_atomic(d.path() + "/sub", "x");
    FAIL() << "a directory was replaced";
  } catch (const FileError& e) {
    EXPECT_EQ(e.path(), d.path() + "/sub");
    EXPECT_NE(std::string(e.what()).find("is a directory"), std::string::npos) << e.what();
  }
  // A link to /dev/full: the device is never renamed over (we run as root in CI).
  fs::create_symlink("/dev/full", d.path() + "/full");
  try {
    write_file_atomic(d.path() + "/full", "x");
    FAIL() << "a device was replaced";
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find("not a regular file"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("/dev/full"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(fs::is_character_file("/dev/full"));
  fs::create_symlink("b", d.path() + "/a");
  fs::create_symlink("a", d.path() + "/b");
  EXPECT_THROW(write_file_atomic(d.path() + "/a", "x"), FileError);
  EXPECT_THROW(write_file_atomic(d.path() + "/no/such/folder/f.json", "x"), FileError);
}

/// Lowers the largest file this process may write (RLIMIT_FSIZE) for the scope: writes beyond it
/// fail with EFBIG as on a full disk. SIGXFSZ is ignored meanwhile (it would kill the process).
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    old_handler_ = std::signal(SIGXFSZ, SIG_IGN);
    ::getrlimit(RLIMIT_FSIZE, &old_);
    rlimit r = old_;
    r.rlim_cur = bytes;
    ok_ = ::setrlimit(RLIMIT_FSIZE, &r) == 0;
  }
  ~FileSizeLimit() {
    ::setrlimit(RLIMIT_FSIZE, &old_);
    std::signal(SIGXFSZ, old_handler_);
  }
  bool ok() const { return ok_; }

 private:
  rlimit old_{};
  void (*old_handler_)(int) = nullptr;
  bool ok_ = false;
};

TEST(AtomicWrite, AFailedWriteKeepsTheOldContentAndNamesThePath) {
  TempDir d;
  const std::string p = d.write("dev.yaml", "the old calibration\n");
  fs::create_symlink("dev.yaml", d.path() + "/link.yaml");
  const std::string big(64 * 1024, 'x');
  std::string message;
  {
    FileSizeLimit limit(4096);
    ASSERT_TRUE(limit.ok());
    try {
      write_file_atomic(d.path() + "/link.yaml", big);
    } catch (const FileError& e) {
      message = e.what();
    }
  }
  ASSERT_FALSE(message.empty()) << "the write did not fail";
  EXPECT_NE(message.find(d.path() + "/link.yaml"), std::string::npos) << message;
  EXPECT_NE(message.find("write failed"), std::string::npos) << message;
  EXPECT_NE(message.find(p), std::string::npos) << "names the link's target: " << message;
  EXPECT_EQ(slurp(p), "the old calibration\n");
  EXPECT_TRUE(fs::is_symlink(d.path() + "/link.yaml"));
  EXPECT_EQ(entries(d.path()), 2u) << "the temporary file is removed";
}

}  // namespace
