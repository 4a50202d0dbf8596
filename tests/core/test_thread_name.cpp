// core::set_thread_name: the name the system's tools read (/proc/self/task/TID/comm).
#include <gtest/gtest.h>

#include <sys/syscall.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <ctime>
#include <fstream>
#include <vector>
#include <string>
#include <thread>

#include "spidar/core/thread_name.hpp"

namespace spidar::core {
namespace {

std::string comm_of(long tid) {
  std::ifstream in("/proc/self/task/" + std::to_string(tid) + "/comm");
  std::string name;
  std::getline(in, name);
  return name;
}

TEST(ThreadName, NamesTheCallingThreadAsTheSystemSeesItCutTo15Characters) {
  std::string seen, read_back, other_seen;
  std::thread t([&] {
    set_thread_name("spidar-a-long-thread-name");
    const long tid = syscall(SYS_gettid);
    seen = comm_of(tid);
    read_back = thread_name();
  });
  t.join();
  EXPECT_EQ(seen, "spidar-a-long-t");
  EXPECT_EQ(read_back, "spidar-a-long-t");
  // The caller's own name is left alone.
  EXPECT_NE(thread_name(), "spidar-a-long-t");
}

// A thread that burned 60 ms of its own CPU time shows at least 50 ms under its name (the
// kernel counts in 10 ms ticks), and a sleeping one next to nothing. The measurement waits until
// the sleeper has named itself: on a loaded machine it may not even have started by then.
TEST(ThreadName, TheProcesssThreadsCpuTimeIsSummedByName) {
  std::atomic<bool> named{false}, measured{false};
  std::vector<ThreadCpu> seen;
  std::thread sleeper([&] {
    set_thread_name("spidar-sleeper");
    named = true;
    while (!measured.load()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  });
  std::thread busy([&] {
    set_thread_name("spidar-busytest");
    timespec t{};
    do clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    while (t.tv_sec == 0 && t.tv_nsec < 60'000'000);
    while (!named.load()) std::this_thread::yield();
    seen = thread_cpu_by_name();
    measured = true;
  });
  busy.join();
  sleeper.join();
  auto find = [&](const std::string& n) {
    for (const ThreadCpu& c : seen)
      if (c.name == n) return c;
    return ThreadCpu{};
  };
  EXPECT_GE(find("spidar-busytest").cpu_s, 0.05);
  EXPECT_EQ(find("spidar-busytest").threads, 1);
  EXPECT_EQ(find("spidar-sleeper").threads, 1);
  EXPECT_LT(find("spidar-sleeper").cpu_s, find("spidar-busytest").cpu_s);
  for (std::size_t i = 1; i < seen.size(); ++i) EXPECT_GE(seen[i - 1].cpu_s, seen[i].cpu_s);  // most first
}

}  // namespace
}  // namespace spidar::core
