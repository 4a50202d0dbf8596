#include "spidar/core/file_read.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <system_error>

namespace spidar::core {
namespace {

constexpr const char* kCannotOpen = "cannot open file (does it exist and is it readable?)";
constexpr std::size_t kChunkBytes = 64 * 1024;

/// Closes a file descriptor when it goes out of scope.
class FdCloser {
 public:
  explicit FdCloser(int fd) : fd_(fd) {}
  ~FdCloser() { ::close(fd_); }
  FdCloser(const FdCloser&) = delete;
  FdCloser& operator=(const FdCloser&) = delete;

 private:
  int fd_;
};

/// Throws unless `st` is a regular file of at most `max_bytes` bytes.
void require_small_regular_file(const std::string& path, const struct stat& st,
                                std::size_t max_bytes, std::string_view what) {
  if (S_ISDIR(st.st_mode)) throw FileError(path, "is a directory");
  if (!S_ISREG(st.st_mode)) throw FileError(path, "is not a regular file");
  const auto size = static_cast<unsigned long long>(st.st_size < 0 ? 0 : st.st_size);
  if (size > max_bytes) {
    throw FileError(path, std::to_string(size) + " bytes, more than the " +
                              std::to_string(max_bytes) + " allowed for " + std::string(what));
  }
}

}  // namespace

std::string printable_for_message(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if (u >= 0x20 && u != 0x7f) {
      out += c;
    } else {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", static_cast<unsigned>(u));
      out += buf;
    }
  }
  return out;
}

FileError::FileError(std::string path, std::string reason)
    : SpidarError(printable_for_message(path) + ": " + reason),
      path_(std::move(path)),
      reason_(std::move(reason)) {}

std::string read_file_bounded(const std::string& path, std::size_t max_bytes,
                              std::string_view what) {
  if (path.find('\0') != std::string::npos) {
    throw FileError(path, "path contains a NUL character");
  }
  // The type is checked before opening: opening a FIFO for reading would wait for a writer.
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) throw FileError(path, kCannotOpen);
  require_small_regular_file(path, st, max_bytes, what);

  // O_NONBLOCK: should the path have been swapped for a FIFO since the stat, open returns at
  // once and the fstat below refuses it.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) throw FileError(path, kCannotOpen);
  const FdCloser closer(fd);
  if (::fstat(fd, &st) != 0) throw FileError(path, kCannotOpen);
  require_small_regular_file(path, st, max_bytes, what);

  // Read at most max_bytes + 1 bytes: one more than allowed tells that the file grew.
  const std::size_t limit = max_bytes == SIZE_MAX ? max_bytes : max_bytes + 1;
  std::string out;
  out.reserve(static_cast<std::size_t>(st.st_size) + 1);
  std::size_t used = 0;
  while (used < limit) {
    const std::size_t want = std::min(kChunkBytes, limit - used);
    out.resize(used + want);
    const ssize_t n = ::read(fd, out.data() + used, want);
    if (n == 0) break;
    if (n < 0) {
      if (errno == EINTR) continue;
      throw FileError(path,
                      "read failed: " + std::error_code(errno, std::generic_category()).message());
    }
    used += static_cast<std::size_t>(n);
  }
  out.resize(used);
  if (used > max_bytes) {
    throw FileError(path, "more than the " + std::to_string(max_bytes) + " bytes allowed for " +
                              std::string(what) +
                              " (it grew while being read, or its size was not known)");
  }
  return out;
}

}  // namespace spidar::core
