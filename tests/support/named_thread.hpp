#pragma once
// This process's thread of a given name (as core::set_thread_name set it), found in /proc, for
// tests that check where the library put one of its own threads (its CPU affinity, its policy).
#include <dirent.h>
#include <sys/types.h>

#include <fstream>
#include <string>

namespace spidar::test {

/// The id of this process's first thread named `name` (/proc/self/task/<tid>/comm), or −1.
inline pid_t thread_named(const std::string& name) {
  pid_t found = -1;
  DIR* d = opendir("/proc/self/task");
  if (d == nullptr) return found;
  while (const dirent* e = readdir(d)) {
    if (e->d_name[0] == '.') continue;
    std::ifstream comm(std::string("/proc/self/task/") + e->d_name + "/comm");
    std::string line;
    if (std::getline(comm, line) && line == name) {
      found = static_cast<pid_t>(std::stol(e->d_name));
      break;
    }
  }
  closedir(d);
  return found;
}

}  // namespace spidar::test
