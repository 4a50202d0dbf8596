#pragma once
/// MuJoCo's warnings, kept in the process instead of printed and appended to MUJOCO_LOG.TXT in
/// the working directory (MuJoCo 2.2.2's default). `install_mujoco_warning_handler()` (called by
/// `World::Load`) sets MuJoCo's global `mju_user_warning` once; the handler may run in any
/// thread (the physics thread too): it only copies the text into a small mutex-protected ring of
/// the newest messages and counts. MuJoCo's fatal errors (`mju_user_error`) are left as they are.
#include <cstdint>
#include <string>
#include <vector>

namespace spidar::physics {

struct MujocoWarnings {
  std::uint64_t count = 0;            ///< warnings since the process started
  std::vector<std::string> messages;  ///< the newest ones (at most kMujocoWarningsKept), oldest first
};

inline constexpr std::size_t kMujocoWarningsKept = 16;

/// Routes MuJoCo's warnings into the process-wide log (idempotent, thread-safe).
void install_mujoco_warning_handler();
/// The warnings recorded so far (any thread).
MujocoWarnings mujoco_warnings();

}  // namespace spidar::physics
