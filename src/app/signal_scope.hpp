#pragma once
/// SIGINT and SIGTERM as a request to end a run cleanly (run, demo): while a SignalScope lives,
/// the signals only set a flag the run's loop polls; the run then finishes its outputs and exits
/// with kExitSigint / kExitSigterm. The previous handlers come back when the scope ends.
#include <atomic>
#include <csignal>
#include <string>

#include "cli_support.hpp"

namespace spidar::app {

/// The signal that asked to end the run (SIGINT, SIGTERM), 0 while none did.
inline std::atomic<int> g_signal{0};

extern "C" inline void spidar_on_end_signal(int sig) { g_signal.store(sig); }

class SignalScope {
 public:
  SignalScope() {
    g_signal.store(0);
    struct sigaction sa {};
    sa.sa_handler = spidar_on_end_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, &old_int_);
    sigaction(SIGTERM, &sa, &old_term_);
  }
  ~SignalScope() {
    sigaction(SIGINT, &old_int_, nullptr);
    sigaction(SIGTERM, &old_term_, nullptr);
  }
  SignalScope(const SignalScope&) = delete;
  SignalScope& operator=(const SignalScope&) = delete;

  /// The signal received so far (0: none).
  static int received() { return g_signal.load(); }
  /// "SIGINT" / "SIGTERM" for a received signal, else `otherwise`.
  static std::string ended_by(const std::string& otherwise) {
    const int s = received();
    return s == SIGINT ? "SIGINT" : s == SIGTERM ? "SIGTERM" : otherwise;
  }
  /// The exit code for a received signal (kExitSigint / kExitSigterm), else `otherwise`.
  static int exit_code(int otherwise) {
    const int s = received();
    return s == SIGINT ? kExitSigint : s == SIGTERM ? kExitSigterm : otherwise;
  }

 private:
  struct sigaction old_int_ {}, old_term_ {};
};

}  // namespace spidar::app
