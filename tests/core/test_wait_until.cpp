// core::wait_until_ns: a notification that makes the condition true ends the wait; a deadline in
// the past, or one that passes without it, returns false; a condition already true returns at once.
#include <gtest/gtest.h>

#include <thread>

#include "spidar/core/wait_until.hpp"

namespace spidar::core {
namespace {

TEST(WaitUntil, ANotificationThatMakesItTrueEndsTheWait) {
  std::mutex m;
  std::condition_variable cv;
  bool ready = false;
  std::thread producer([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    {
      const std::lock_guard lock(m);
      ready = true;
    }
    cv.notify_all();
  });
  std::unique_lock lock(m);
  // A minute: only a lost notification reaches it.
  EXPECT_TRUE(wait_until_ns(cv, lock, monotonic_ns() + 60'000'000'000, [&] { return ready; }));
  EXPECT_TRUE(lock.owns_lock());
  lock.unlock();
  producer.join();
}

TEST(WaitUntil, ADeadlineThatPassesReturnsFalseAndATrueConditionReturnsAtOnce) {
  std::mutex m;
  std::condition_variable cv;
  std::unique_lock lock(m);
  int asked = 0;
  EXPECT_FALSE(wait_until_ns(cv, lock, monotonic_ns() - 1, [&] { return ++asked, false; }));
  EXPECT_EQ(asked, 1);
  const std::int64_t deadline = monotonic_ns() + 2'000'000;
  EXPECT_FALSE(wait_until_ns(cv, lock, deadline, [] { return false; }));
  EXPECT_GE(monotonic_ns(), deadline);  // it did not give up before its deadline
  EXPECT_TRUE(wait_until_ns(cv, lock, monotonic_ns() - 1, [] { return true; }));
  EXPECT_TRUE(lock.owns_lock());
}

}  // namespace
}  // namespace spidar::core
