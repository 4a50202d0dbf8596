// core::DoneFlag: what a writer wrote before set() is what a waiting reader sees after wait().
#include <gtest/gtest.h>

#include <chrono>
#include <thread>
#include <vector>

#include "spidar/core/done_flag.hpp"

namespace spidar::core {
namespace {

TEST(DoneFlag, AWaiterSeesWhatWasWrittenBeforeTheSet) {
  for (int round = 0; round < 50; ++round) {
    std::vector<int> data;
    DoneFlag flag;
    EXPECT_FALSE(flag.done());
    std::thread writer([&] {
      if (round % 2 == 0) std::this_thread::sleep_for(std::chrono::microseconds(200));
      data.assign(1000, round);
      flag.set();
    });
    flag.wait();
    ASSERT_EQ(data.size(), 1000u);
    EXPECT_EQ(data.front(), round);
    EXPECT_EQ(data.back(), round);
    EXPECT_TRUE(flag.done());
    writer.join();
  }
}

TEST(DoneFlag, WaitReturnsAtOnceWhenSetAndCopiesTakeTheState) {
  DoneFlag set_one(true);
  set_one.wait();  // would block forever if not
  DoneFlag copy = set_one;
  EXPECT_TRUE(copy.done());
  DoneFlag unset;
  copy = unset;
  EXPECT_FALSE(copy.done());
  copy.set();
  EXPECT_TRUE(copy.done());
  copy.reset();
  EXPECT_FALSE(copy.done());
}

}  // namespace
}  // namespace spidar::core
