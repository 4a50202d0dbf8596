#include "spidar/physics/mujoco_log.hpp"

#include <mujoco/mujoco.h>

#include <array>
#include <cstring>
#include <mutex>

namespace spidar::physics {
namespace {

constexpr std::size_t kTextSize = 256;  // MuJoCo's messages are one line (mju_warning: 1000 max)

struct Log {
  std::mutex mutex;
  std::array<std::array<char, kTextSize>, kMujocoWarningsKept> ring{};
  std::uint64_t count = 0;  // also the next slot: ring[count % kept]
};

Log& log() {
  static Log l;  // constructed before the handler is installed (install_… calls log() first)
  return l;
}

// Short and allocation-free: it may run in the physics thread, inside mj_step.
extern "C" void on_mujoco_warning(const char* msg) {
  Log& l = log();
  std::lock_guard<std::mutex> lock(l.mutex);
  auto& slot = l.ring[l.count % kMujocoWarningsKept];
  std::strncpy(slot.data(), msg ? msg : "", kTextSize - 1);
  slot[kTextSize - 1] = '\0';
  ++l.count;
}

}  // namespace

void install_mujoco_warning_handler() {
  static std::once_flag once;
  std::call_once(once, [] {
    (void)log();
    mju_user_warning = on_mujoco_warning;
  });
}

MujocoWarnings mujoco_warnings() {
  Log& l = log();
  std::lock_guard<std::mutex> lock(l.mutex);
  MujocoWarnings w;
  w.count = l.count;
  const std::uint64_t kept = std::min<std::uint64_t>(l.count, kMujocoWarningsKept);
  for (std::uint64_t k = l.count - kept; k < l.count; ++k) w.messages.emplace_back(l.ring[k % kMujocoWarningsKept].data());
  return w;
}

}  // namespace spidar::physics
