#include "spidar/core/atomic_write.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <filesystem>
#include <system_error>

namespace spidar::core {
namespace {

namespace fs = std::filesystem;

std::string errno_text(int err) { return std::error_code(err, std::generic_category()).message(); }

/// Removes the temporary file unless released (the rename succeeded).
class TempFile {
 public:
  TempFile(std::string path, int fd) : path_(std::move(path)), fd_(fd) {}
  ~TempFile() {
    if (fd_ >= 0) ::close(fd_);
    if (!path_.empty()) ::unlink(path_.c_str());
  }
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;
  int fd() const { return fd_; }
  const std::string& path() const { return path_; }
  /// Closes the descriptor; returns 0 or the errno of a failed close.
  int close() {
    const int r = ::close(fd_);
    fd_ = -1;
    return r == 0 ? 0 : errno;
  }
  void release() { path_.clear(); }

 private:
  std::string path_;
  int fd_;
};

std::atomic<unsigned> g_counter{0};

}  // namespace

std::string resolve_symlinks(const std::string& path) {
  if (path.find('\0') != std::string::npos) throw FileError(path, "path contains a NUL character");
  fs::path p(path);
  for (int hops = 0; hops <= 40; ++hops) {
    struct stat st {};
    if (::lstat(p.c_str(), &st) != 0 || !S_ISLNK(st.st_mode)) return p.string();
    std::error_code ec;
    const fs::path target = fs::read_symlink(p, ec);
    if (ec) throw FileError(path, "cannot read the symbolic link " + p.string() + ": " + ec.message());
    p = target.is_absolute() ? target : p.parent_path() / target;
  }
  throw FileError(path, "too many levels of symbolic links (a loop?)");
}

void write_file_atomic(const std::string& path, std::string_view bytes, const AtomicWriteOptions& options) {
  const std::string target = resolve_symlinks(path);
  const std::string via = target == path ? "" : " (the symbolic link's target " + target + ")";
  auto fail = [&](const std::string& what) -> FileError { return FileError(path, what + via); };

  struct stat st {};
  const bool exists = ::stat(target.c_str(), &st) == 0;
  if (exists && !S_ISREG(st.st_mode))
    throw fail(S_ISDIR(st.st_mode) ? "is a directory" : "is not a regular file (refusing to replace it)");

  const fs::path t(target);
  const fs::path dir = t.has_parent_path() ? t.parent_path() : fs::path(".");
  const mode_t mode = exists ? (st.st_mode & 07777) : 0666;  // a new file: 0666 & ~umask by open()
  int fd = -1;
  std::string tmp;
  for (int attempt = 0; attempt < 100 && fd < 0; ++attempt) {
    tmp = (dir / ("." + t.filename().string() + ".tmp-" + std::to_string(::getpid()) + "-" +
                  std::to_string(g_counter.fetch_add(1))))
              .string();
    fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC | O_NOFOLLOW, mode);
    if (fd < 0 && errno != EEXIST) break;
  }
  if (fd < 0) throw fail("cannot create a temporary file in " + dir.string() + ": " + errno_text(errno));
  TempFile file(tmp, fd);
  if (exists) {
    // open() applied the umask: keep the old file's permissions, and its owner where allowed
    // (root, or the same owner): best effort, the content matters more.
    if (::fchmod(fd, mode) != 0) {
    }
    if (::fchown(fd, st.st_uid, st.st_gid) != 0) {
    }
  }

  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw fail("write failed: " + errno_text(errno) + " (the previous content is kept)");
    }
    done += static_cast<std::size_t>(n);
  }
  if (options.sync && ::fsync(fd) != 0)
    throw fail("write failed (fsync): " + errno_text(errno) + " (the previous content is kept)");
  if (const int err = file.close(); err != 0)
    throw fail("write failed (close): " + errno_text(err) + " (the previous content is kept)");
  if (::rename(tmp.c_str(), target.c_str()) != 0)
    throw fail("cannot replace the file: " + errno_text(errno) + " (the previous content is kept)");
  file.release();
  if (options.sync) {
    const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dfd >= 0) {
      (void)::fsync(dfd);
      ::close(dfd);
    }
  }
}

}  // namespace spidar::core
