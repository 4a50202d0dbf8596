#pragma once
/// A progress bar for long runs: redrawn in place on a terminal, one line per 10 % otherwise
/// (logs, CI).
#include <cstdio>
#include <iomanip>
#include <ostream>
#include <sstream>
#include <string>
#include <unistd.h>

namespace spidar::app {

class Progress {
 public:
  Progress(double total, std::ostream& os, bool tty = isatty(STDERR_FILENO) != 0)
      : total_(total > 0 ? total : 1), os_(os), tty_(tty) {}

  /// Shows progress `done` of the total with a short status text.
  void update(double done, const std::string& status) {
    const double f = std::clamp(done / total_, 0.0, 1.0);
    const int pct = static_cast<int>(f * 100);
    if (tty_) {
      if (pct == last_pct_ && ++skipped_ < 6) return;  // redraw at most ~5× per second at 30 fps
      skipped_ = 0;
      const int width = 30, filled = static_cast<int>(f * width);
      os_ << "\r[" << std::string(filled, '#') << std::string(width - filled, '-') << "] "
          << std::setw(3) << pct << "%  " << status << "\x1b[K" << std::flush;
    } else if (pct / 10 != last_pct_ / 10 || last_pct_ < 0) {
      os_ << "  " << std::setw(3) << pct << "%  " << status << "\n" << std::flush;
    }
    last_pct_ = pct;
  }
  void finish() {
    if (tty_) os_ << "\n";
    os_ << std::flush;
  }

 private:
  double total_;
  std::ostream& os_;
  bool tty_;
  int last_pct_ = -1;
  int skipped_ = 0;
};

}  // namespace spidar::app
