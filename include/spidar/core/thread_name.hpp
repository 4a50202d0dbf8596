#pragma once
/// Names the calling thread for the system's tools (Linux: /proc/PID/task/TID/comm, as `top -H`,
/// `ps -L`, perf and gdb show it), and reads back what each named thread has cost. spidar-mr's
/// threads are named "spidar-<role>": servo, watchdog, physics, camera, output, record, capture,
/// shape, side, spin, fit (the main thread keeps the program's name).
#include <string>
#include <string_view>
#include <vector>

namespace spidar::core {

/// Sets the calling thread's name, cut to the kernel's 15 characters. Best effort: a failure
/// changes nothing else.
void set_thread_name(std::string_view name);

/// The calling thread's name ("" where it cannot be read).
std::string thread_name();

/// CPU time (user + system) of the process's threads alive now, summed by name [s]; most first.
/// A thread started by a named one inherits its name (e.g. a video encoder's workers).
struct ThreadCpu {
  std::string name;
  double cpu_s = 0;  ///< [s], in the kernel's clock ticks (10 ms here)
  int threads = 0;   ///< threads of that name
};
std::vector<ThreadCpu> thread_cpu_by_name();

}  // namespace spidar::core
