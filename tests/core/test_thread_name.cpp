// core::set_thread_name: the name the system's tools read (/proc/self/task/TID/comm).
#include <gtest/gtest.h>

#include <sys/syscall.h>
#include <unistd.h>

#include <fstream>
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

}  // namespace
}  // namespace spidar::core
