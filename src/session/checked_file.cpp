#include "checked_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <system_error>

namespace spidar::session {
namespace {

constexpr std::size_t kBufferBytes = 64 * 1024;

std::string errno_text(int err) { return std::error_code(err, std::generic_category()).message(); }

}  // namespace

CheckedFile::CheckedFile(std::string path) : path_(std::move(path)) {
  fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC | O_NOCTTY, 0666);
  if (fd_ < 0) throw core::FileError(path_, "cannot create the file: " + errno_text(errno));
  buffer_.reserve(kBufferBytes);
}

CheckedFile::~CheckedFile() {
  if (fd_ >= 0) ::close(fd_);
}

void CheckedFile::fail(const std::string& reason) {
  if (error_.empty()) {
    reason_ = reason;
    error_ = core::FileError(path_, reason).what();
  }
}

bool CheckedFile::flush() {
  std::size_t done = 0;
  while (ok() && done < buffer_.size()) {
    const ssize_t n = ::write(fd_, buffer_.data() + done, buffer_.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      fail("write failed: " + errno_text(errno));
    } else {
      done += static_cast<std::size_t>(n);
    }
  }
  buffer_.clear();
  return ok();
}

bool CheckedFile::write(std::string_view text) {
  if (!ok() || fd_ < 0) return false;
  buffer_.append(text);
  if (buffer_.size() >= kBufferBytes) return flush();
  return true;
}

void CheckedFile::close() {
  if (fd_ >= 0) {
    flush();
    if (ok() && ::fsync(fd_) != 0 && errno != EINVAL && errno != EROFS)  // EINVAL: e.g. a pipe
      fail("write failed (fsync): " + errno_text(errno));
    if (::close(fd_) != 0 && ok()) fail("write failed (close): " + errno_text(errno));
    fd_ = -1;
  }
  if (!ok()) throw core::FileError(path_, reason_);
}

}  // namespace spidar::session
