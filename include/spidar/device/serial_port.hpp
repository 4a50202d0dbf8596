#pragma once
/// A POSIX termios serial port in raw mode (8 data bits, no parity, one stop bit, no flow
/// control, no line editing), and pseudo-terminal pairs for running the serial path without
/// hardware. Reads wait with poll() and a timeout; writes write everything or fail.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "spidar/core/result.hpp"

namespace spidar::device {

/// Outcome of one read or write on a file descriptor.
enum class IoStatus {
  kOk,       ///< bytes moved
  kTimeout,  ///< nothing happened within the timeout
  kClosed,   ///< the other side is gone: EOF, EIO, hang-up
  kError,    ///< any other failure; see error_number
};

struct IoResult {
  IoStatus status = IoStatus::kOk;
  std::size_t bytes = 0;  ///< bytes read or written
  int error_number = 0;   ///< errno for kError (and for kClosed when it came from errno)
};

/// Waits up to `timeout_s` [s] for input on `fd`, then reads what is available (at most
/// out.size() bytes). Never allocates.
IoResult read_some(int fd, std::span<std::uint8_t> out, double timeout_s);
/// Reads the bytes a tty already holds (at most out.size()) and returns at once: kOk with 0 bytes
/// when there are none. Unlike read_some, it never waits for the kernel: poll() and read() on a
/// tty with no input first wait for the tty's pending flip-buffer work (`tty_buffer_flush_work`,
/// i.e. for a kworker to move bytes in flight into the line discipline), which takes milliseconds
/// on a loaded machine even with a zero timeout. This asks FIONREAD how many bytes are there and
/// calls read() only if some are. kClosed: the tty was hung up (the other side of a pty closed,
/// a USB device vanished). Never allocates.
IoResult read_ready(int fd, std::span<std::uint8_t> out);
/// Writes all of `data` to `fd`, waiting up to `timeout_s` [s] in total for room. Never allocates.
IoResult write_all(int fd, std::span<const std::uint8_t> data, double timeout_s);

/// The termios speed for a baud rate, or 0 if the rate is not one of the standard Linux rates
/// (9600 … 4000000).
unsigned baud_to_speed(int baud);
/// The smallest standard rate ≥ `baud`, or 0 if even 4000000 is less.
int standard_baud_at_least(double baud);
/// Puts an open tty in raw mode at `baud` (0 keeps the current speed). Errors name `what`.
Status make_raw(int fd, int baud, const std::string& what);

/// An open serial port. Move-only; closes on destruction.
class SerialPort {
 public:
  SerialPort() = default;
  ~SerialPort();
  SerialPort(SerialPort&& other) noexcept;
  SerialPort& operator=(SerialPort&& other) noexcept;
  SerialPort(const SerialPort&) = delete;
  SerialPort& operator=(const SerialPort&) = delete;

  /// Opens `path` (any tty: /dev/ttyACM0, /dev/ttyUSB0, a pty slave) in raw mode at `baud`,
  /// non-blocking, without making it the controlling terminal, and discards stale input.
  /// The port is held exclusively: TIOCEXCL (further open()s of the tty fail with EBUSY, except
  /// for root) and flock(LOCK_EX | LOCK_NB) (what other serial tools check, and what stops a
  /// second process even when it runs as root). A port another process holds is the error
  /// "serial port PATH: in use by another process". Other errors name the path and the errno
  /// text; an unsupported baud rate is an error.
  static Result<SerialPort> open(const std::string& path, int baud);

  IoResult read_some(std::span<std::uint8_t> out, double timeout_s) {
    return device::read_some(fd_, out, timeout_s);
  }
  IoResult read_ready(std::span<std::uint8_t> out) { return device::read_ready(fd_, out); }
  IoResult write_all(std::span<const std::uint8_t> data, double timeout_s) {
    return device::write_all(fd_, data, timeout_s);
  }
  void close();
  bool is_open() const { return fd_ >= 0; }
  int fd() const { return fd_; }
  const std::string& path() const { return path_; }
  /// True for a USB CDC-ACM port (/dev/ttyACM*, character major 166): the device ignores the baud
  /// rate and the USB link carries the frames at its own speed.
  bool baud_ignored() const { return baud_ignored_; }

 private:
  int fd_ = -1;
  std::string path_;
  bool baud_ignored_ = false;
};

/// A pseudo-terminal pair: the master side (for the device emulator) and the path of the slave
/// side (what a host opens as its serial port).
struct PtyPair {
  int master_fd = -1;      ///< owned by the caller: close() it when done
  std::string slave_path;  ///< e.g. /dev/pts/3
};

/// Creates a pty pair with posix_openpt/grantpt/unlockpt, raw mode, master non-blocking.
/// While no process has the slave open, poll() on the master reports hang-up.
Result<PtyPair> open_pty();

}  // namespace spidar::device
