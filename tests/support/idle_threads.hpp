#pragma once
// This process's SCHED_IDLE threads (core::IdleSpinner's), as /proc lists them, and a bounded wait
// for the last of them to leave: pthread_join returns when the kernel clears the thread's id, on
// its way out, before the task is gone from /proc, and an exiting SCHED_IDLE task may wait behind
// every other task on its CPU (weight 3 against 1024) before it is (seen: 1 in 3 runs of the suite
// listed it just after the join).
#include <dirent.h>
#include <sched.h>
#include <sys/types.h>

#include <chrono>
#include <string>
#include <thread>
#include <vector>

namespace spidar::test {

/// The ids of this process's threads whose policy is SCHED_IDLE.
inline std::vector<pid_t> idle_threads() {
  std::vector<pid_t> out;
  DIR* d = opendir("/proc/self/task");
  if (d == nullptr) return out;
  while (const dirent* e = readdir(d)) {
    if (e->d_name[0] == '.') continue;
    const pid_t tid = static_cast<pid_t>(std::stol(e->d_name));
    if (sched_getscheduler(tid) == SCHED_IDLE) out.push_back(tid);
  }
  closedir(d);
  return out;
}

/// Whether this process has no SCHED_IDLE thread, waiting up to `limit` (generous: a passing test
/// waits only as long as the exiting thread takes) for the ended ones to leave /proc.
inline bool no_idle_thread_within(std::chrono::milliseconds limit = std::chrono::seconds(10)) {
  const auto until = std::chrono::steady_clock::now() + limit;
  while (!idle_threads().empty() && std::chrono::steady_clock::now() < until)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  return idle_threads().empty();
}

}  // namespace spidar::test
