#pragma once
/// Names the calling thread for the system's tools (Linux: /proc/PID/task/TID/comm, as `top -H`,
/// `ps -L`, perf and gdb show it). spidar-mr's threads are named "spidar-<role>": servo, watchdog,
/// physics, camera, output, record, capture, shape, side, spin, fit.
#include <string>
#include <string_view>

namespace spidar::core {

/// Sets the calling thread's name, cut to the kernel's 15 characters. Best effort: a failure
/// changes nothing else.
void set_thread_name(std::string_view name);

/// The calling thread's name ("" where it cannot be read).
std::string thread_name();

}  // namespace spidar::core
