#include "spidar/core/thread_name.hpp"

#include <pthread.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <array>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

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

std::vector<ThreadCpu> thread_cpu_by_name() {
  namespace fs = std::filesystem;
  const double tick = static_cast<double>(sysconf(_SC_CLK_TCK));
  std::map<std::string, ThreadCpu> by_name;
  std::error_code ec;
  for (const auto& task : fs::directory_iterator("/proc/self/task", ec)) {
    std::string name, stat;
    std::ifstream comm(task.path() / "comm"), st(task.path() / "stat");
    if (!std::getline(comm, name) || !std::getline(st, stat)) continue;  // it ended meanwhile
    // Fields after the name's closing parenthesis: state is the 3rd of stat(5), utime the 14th and
    // stime the 15th.
    const auto close = stat.rfind(')');
    if (close == std::string::npos) continue;
    std::istringstream rest(stat.substr(close + 2));
    std::string field;
    double utime = 0, stime = 0;
    for (int i = 3; i <= 15 && rest >> field; ++i) {
      if (i == 14) utime = std::atof(field.c_str());
      if (i == 15) stime = std::atof(field.c_str());
    }
    ThreadCpu& t = by_name[name];
    t.name = name;
    t.cpu_s += (utime + stime) / (tick > 0 ? tick : 100.0);
    ++t.threads;
  }
  std::vector<ThreadCpu> out;
  for (auto& [n, t] : by_name) out.push_back(t);
  std::sort(out.begin(), out.end(), [](const ThreadCpu& a, const ThreadCpu& b) { return a.cpu_s > b.cpu_s; });
  return out;
}

}  // namespace spidar::core
