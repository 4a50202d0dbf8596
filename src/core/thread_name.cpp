#include "spidar/core/thread_name.hpp"

#include <pthread.h>

#include <array>

namespace spidar::core {

void set_thread_name(std::string_view name) {
  constexpr std::size_t kMax = 15;  // the kernel's TASK_COMM_LEN, less its NUL
  const std::string cut(name.substr(0, kMax));
  (void)pthread_setname_np(pthread_self(), cut.c_str());
}

std::string thread_name() {
  std::array<char, 16> buf{};
  if (pthread_getname_np(pthread_self(), buf.data(), buf.size()) != 0) return {};
  return buf.data();
}

}  // namespace spidar::core
