#include "spidar/device/serial_port.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/file.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <utility>

#include "spidar/core/clock.hpp"

namespace spidar::device {
namespace {

struct BaudEntry {
  int baud;
  speed_t speed;
};
constexpr BaudEntry kBauds[] = {
    {9600, B9600},       {19200, B19200},     {38400, B38400},     {57600, B57600},
    {115200, B115200},   {230400, B230400},   {460800, B460800},   {500000, B500000},
    {576000, B576000},   {921600, B921600},   {1000000, B1000000}, {1152000, B1152000},
    {1500000, B1500000}, {2000000, B2000000}, {2500000, B2500000}, {3000000, B3000000},
    {3500000, B3500000}, {4000000, B4000000},
};

std::int64_t now_ns() { return core::monotonic_ns(); }

timespec to_timespec(std::int64_t ns) {
  if (ns < 0) ns = 0;
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(ns / 1'000'000'000);
  ts.tv_nsec = static_cast<long>(ns % 1'000'000'000);
  return ts;
}

std::int64_t seconds_to_ns(double s) {
  if (!(s > 0.0)) return 0;
  if (s > 1e6) s = 1e6;
  return static_cast<std::int64_t>(std::llround(s * 1e9));
}

/// Waits until `events` are possible on fd or the deadline passes. Returns revents, 0 on timeout,
/// −1 on error (errno set).
int wait_for(int fd, short events, std::int64_t deadline_ns) {
  for (;;) {
    pollfd p{fd, events, 0};
    const timespec ts = to_timespec(deadline_ns - now_ns());
    const int r = ppoll(&p, 1, &ts, nullptr);
    if (r < 0 && errno == EINTR) continue;
    if (r < 0) return -1;
    if (r == 0) return 0;
    return p.revents;
  }
}

std::string errno_text(int e) {
  std::string s = std::strerror(e);
  return s;
}

}  // namespace

IoResult read_some(int fd, std::span<std::uint8_t> out, double timeout_s) {
  const std::int64_t deadline = now_ns() + seconds_to_ns(timeout_s);
  const int rev = wait_for(fd, POLLIN, deadline);
  if (rev < 0) return {IoStatus::kError, 0, errno};
  if (rev == 0) return {IoStatus::kTimeout, 0, 0};
  if (rev & POLLNVAL) return {IoStatus::kError, 0, EBADF};
  for (;;) {
    const ssize_t n = ::read(fd, out.data(), out.size());
    if (n > 0) return {IoStatus::kOk, static_cast<std::size_t>(n), 0};
    if (n == 0) return {IoStatus::kClosed, 0, 0};
    if (errno == EINTR) continue;
    if (errno == EAGAIN || errno == EWOULDBLOCK) {
      if (rev & (POLLHUP | POLLERR)) return {IoStatus::kClosed, 0, 0};
      return {IoStatus::kOk, 0, 0};  // spurious wake-up: nothing to read after all
    }
    if (errno == EIO) return {IoStatus::kClosed, 0, EIO};
    return {IoStatus::kError, 0, errno};
  }
}

IoResult read_ready(int fd, std::span<std::uint8_t> out) {
  int available = 0;
  if (::ioctl(fd, FIONREAD, &available) != 0) {
    // A hung-up tty answers EIO; a pty whose other side is gone may also say ENXIO.
    if (errno == EIO || errno == ENXIO) return {IoStatus::kClosed, 0, errno};
    return {IoStatus::kError, 0, errno};
  }
  if (available <= 0 || out.empty()) return {IoStatus::kOk, 0, 0};
  const std::size_t want = std::min(out.size(), static_cast<std::size_t>(available));
  for (;;) {
    const ssize_t n = ::read(fd, out.data(), want);
    if (n > 0) return {IoStatus::kOk, static_cast<std::size_t>(n), 0};
    if (n == 0) return {IoStatus::kClosed, 0, 0};  // input was there: 0 means hung up
    if (errno == EINTR) continue;
    if (errno == EAGAIN || errno == EWOULDBLOCK) return {IoStatus::kOk, 0, 0};  // flushed meanwhile
    if (errno == EIO) return {IoStatus::kClosed, 0, EIO};
    return {IoStatus::kError, 0, errno};
  }
}

IoResult write_all(int fd, std::span<const std::uint8_t> data, double timeout_s) {
  const std::int64_t deadline = now_ns() + seconds_to_ns(timeout_s);
  std::size_t done = 0;
  while (done < data.size()) {
    const ssize_t n = ::write(fd, data.data() + done, data.size() - done);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
      const int rev = wait_for(fd, POLLOUT, deadline);
      if (rev < 0) return {IoStatus::kError, done, errno};
      if (rev == 0) return {IoStatus::kTimeout, done, 0};
      if (rev & POLLNVAL) return {IoStatus::kError, done, EBADF};
      if ((rev & (POLLHUP | POLLERR)) && !(rev & POLLOUT)) return {IoStatus::kClosed, done, 0};
      continue;
    }
    if (n < 0 && (errno == EIO || errno == EPIPE)) return {IoStatus::kClosed, done, errno};
    return {IoStatus::kError, done, n < 0 ? errno : EIO};
  }
  return {IoStatus::kOk, done, 0};
}

unsigned baud_to_speed(int baud) {
  for (const auto& e : kBauds) {
    if (e.baud == baud) return static_cast<unsigned>(e.speed);
  }
  return 0;
}

int standard_baud_at_least(double baud) {
  for (const auto& e : kBauds) {  // ascending
    if (static_cast<double>(e.baud) >= baud) return e.baud;
  }
  return 0;
}

namespace {

/// The error for a baud rate termios cannot set, naming the port and the rates it can.
Error unsupported_baud(const std::string& what, int baud) {
  std::string msg = what;
  msg += ": unsupported baud rate ";
  msg += std::to_string(baud);
  msg += " (expected a standard rate: 9600, 19200, 38400, 57600, 115200, 230400, 460800, "
         "500000, 576000, 921600, 1000000, 1152000, 1500000, 2000000, 2500000, 3000000, "
         "3500000 or 4000000)";
  return Error{msg};
}

}  // namespace

Status make_raw(int fd, int baud, const std::string& what) {
  termios t{};
  if (tcgetattr(fd, &t) != 0) {
    std::string msg = what;
    msg += ": not a terminal (tcgetattr: ";
    msg += errno_text(errno);
    msg += ")";
    return Error{msg};
  }
  cfmakeraw(&t);
  t.c_cflag |= CLOCAL | CREAD;
  t.c_cflag &= ~static_cast<tcflag_t>(CRTSCTS | CSTOPB | PARENB);
  t.c_iflag &= ~static_cast<tcflag_t>(IXON | IXOFF | IXANY);
  t.c_cc[VMIN] = 0;
  t.c_cc[VTIME] = 0;
  if (baud != 0) {
    const unsigned speed = baud_to_speed(baud);
    if (speed == 0) return unsupported_baud(what, baud);
    cfsetispeed(&t, static_cast<speed_t>(speed));
    cfsetospeed(&t, static_cast<speed_t>(speed));
  }
  if (tcsetattr(fd, TCSANOW, &t) != 0) {
    std::string msg = what;
    msg += ": cannot set raw mode at ";
    msg += std::to_string(baud);
    msg += " baud (tcsetattr: ";
    msg += errno_text(errno);
    msg += ")";
    return Error{msg};
  }
  return Ok{};
}

SerialPort::~SerialPort() { close(); }

SerialPort::SerialPort(SerialPort&& other) noexcept
    : fd_(std::exchange(other.fd_, -1)),
      path_(std::move(other.path_)),
      baud_ignored_(std::exchange(other.baud_ignored_, false)) {}

SerialPort& SerialPort::operator=(SerialPort&& other) noexcept {
  if (this != &other) {
    close();
    fd_ = std::exchange(other.fd_, -1);
    path_ = std::move(other.path_);
    baud_ignored_ = std::exchange(other.baud_ignored_, false);
  }
  return *this;
}

void SerialPort::close() {
  if (fd_ >= 0) {
    // Give the tty back: TIOCEXCL would outlive this descriptor on a tty whose other side stays
    // open (a pty slave while its master lives). The flock goes with the descriptor.
    (void)::ioctl(fd_, TIOCNXCL);
    ::close(fd_);
  }
  fd_ = -1;
  baud_ignored_ = false;
}

Result<SerialPort> SerialPort::open(const std::string& path, int baud) {
  std::string what = "serial port ";
  what += path;
  if (baud_to_speed(baud) == 0) return unsupported_baud(what, baud);  // before touching the device
  auto in_use = [&what] {
    std::string msg = what;
    msg += ": in use by another process (it holds the port exclusively; close it first)";
    return Error{msg};
  };
  const int fd = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    if (errno == EBUSY) return in_use();  // another holder set TIOCEXCL
    std::string msg = what;
    msg += ": cannot open (";
    msg += errno_text(errno);
    msg += ")";
    return Error{msg};
  }
  // flock before TIOCEXCL: a port someone else holds must not lose its TIOCEXCL to our close().
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    const int e = errno;
    ::close(fd);
    if (e == EWOULDBLOCK) return in_use();
    std::string msg = what;
    msg += ": cannot lock (flock: ";
    msg += errno_text(e);
    msg += ")";
    return Error{msg};
  }
  SerialPort port;
  port.fd_ = fd;
  port.path_ = path;
  if (Status s = make_raw(fd, baud, what); !s) return s.error();
  if (::ioctl(fd, TIOCEXCL) != 0) {
    std::string msg = what;
    msg += ": cannot take the port exclusively (TIOCEXCL: ";
    msg += errno_text(errno);
    msg += ")";
    return Error{msg};
  }
  struct stat st {};
  constexpr unsigned kUsbAcmMajor = 166;  // Linux: /dev/ttyACM*
  port.baud_ignored_ = ::fstat(fd, &st) == 0 && S_ISCHR(st.st_mode) && major(st.st_rdev) == kUsbAcmMajor;
  tcflush(fd, TCIOFLUSH);
  return port;
}

Result<PtyPair> open_pty() {
  const int fd = posix_openpt(O_RDWR | O_NOCTTY);
  if (fd < 0) {
    std::string msg = "pseudo-terminal: posix_openpt failed (";
    msg += errno_text(errno);
    msg += ")";
    return Error{msg};
  }
  auto fail = [fd](const char* step) {
    std::string msg = "pseudo-terminal: ";
    msg += step;
    msg += " failed (";
    msg += errno_text(errno);
    msg += ")";
    ::close(fd);
    return Error{msg};
  };
  if (grantpt(fd) != 0) return fail("grantpt");
  if (unlockpt(fd) != 0) return fail("unlockpt");
  char name[128];
  if (ptsname_r(fd, name, sizeof name) != 0) return fail("ptsname_r");
  if (fcntl(fd, F_SETFD, FD_CLOEXEC) != 0) return fail("fcntl(FD_CLOEXEC)");
  const int fl = fcntl(fd, F_GETFL);
  if (fl < 0 || fcntl(fd, F_SETFL, fl | O_NONBLOCK) != 0) return fail("fcntl(O_NONBLOCK)");
  // The master shares the slave's termios: raw mode here means no echo and no byte translation
  // even before a host opens the slave.
  if (Status s = make_raw(fd, 0, "pseudo-terminal master"); !s) {
    ::close(fd);
    return s.error();
  }
  return PtyPair{fd, name};
}

}  // namespace spidar::device
