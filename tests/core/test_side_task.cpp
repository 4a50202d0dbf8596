#include "spidar/core/side_task.hpp"

#include <gtest/gtest.h>

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <future>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace spidar::core {
namespace {

TEST(SideTask, RunsTheTaskOnAnotherThreadWhileTheCallerWorks) {
  SideTask side;
  // The task waits for the caller's part, which first waits for the task to have begun: run one
  // after the other on one thread, the task would wait out its (generous) timeout and see nothing.
  std::mutex m;
  std::condition_variable cv;
  bool task_began = false, caller_done = false, task_saw_caller = false, caller_saw_task = false;
  std::thread::id task_thread;
  auto task = [&] {
    task_thread = std::this_thread::get_id();
    std::unique_lock lock(m);
    task_began = true;
    cv.notify_all();
    task_saw_caller = cv.wait_for(lock, std::chrono::seconds(30), [&] { return caller_done; });
  };
  run_side_by_side(&side, task, [&] {
    std::unique_lock lock(m);
    caller_saw_task = cv.wait_for(lock, std::chrono::seconds(30), [&] { return task_began; });
    caller_done = true;
    cv.notify_all();
  });
  EXPECT_TRUE(caller_saw_task);
  EXPECT_TRUE(task_saw_caller);
  EXPECT_NE(task_thread, std::this_thread::get_id());
  EXPECT_EQ(side.tasks_run(), 1u);
  EXPECT_EQ(side.tasks_run_by_caller(), 0u);
  EXPECT_FALSE(side.busy());
}

// Each task runs exactly once, on the helper or (when the helper had not begun it by the caller's
// wait) on the caller; with no part of its own the caller mostly takes the task back itself.
TEST(SideTask, ManyTasksInARowEachRunOnceOnTheHelperOrTheCaller) {
  SideTask side;
  std::vector<int> side_counts(2000, 0), own_counts(2000, 0);
  std::vector<std::thread::id> ran_on(2000);
  for (int i = 0; i < 2000; ++i) {
    const auto k = static_cast<std::size_t>(i);
    run_side_by_side(
        &side,
        [&] {
          ++side_counts[k];
          ran_on[k] = std::this_thread::get_id();
        },
        [&] { ++own_counts[k]; });
  }
  std::size_t on_caller = 0;
  for (std::size_t k = 0; k < 2000; ++k) {
    ASSERT_EQ(side_counts[k], 1) << "task " << k;
    ASSERT_EQ(own_counts[k], 1) << "task " << k;
    on_caller += ran_on[k] == std::this_thread::get_id() ? 1 : 0;
  }
  EXPECT_EQ(side.tasks_run(), 2000u);
  EXPECT_EQ(side.tasks_run_by_caller(), on_caller);
}

TEST(SideTask, ATasksExceptionComesBackFromWaitAndTheHelperGoesOn) {
  SideTask side;
  auto throws = [] { throw std::runtime_error("bracelets: no red pixels"); };
  side.start(throws);
  try {
    side.wait();
    FAIL() << "wait() did not re-throw";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "bracelets: no red pixels");
  }
  int ran = 0;
  auto fine = [&] { ++ran; };
  side.start(fine);
  EXPECT_NO_THROW(side.wait());
  EXPECT_EQ(ran, 1);
  // Both sides throwing: the caller's exception is the one seen, and the helper is waited for.
  EXPECT_THROW(run_side_by_side(&side, throws, [] { throw std::logic_error("caller"); }), std::logic_error);
  EXPECT_FALSE(side.busy());
  EXPECT_EQ(side.tasks_run(), 3u);
  // Thrown by a task the caller took back (nothing of its own to do first), likewise.
  for (int k = 0; k < 50; ++k) {
    side.start(throws);
    EXPECT_THROW(side.wait(), std::runtime_error);
  }
  EXPECT_EQ(side.tasks_run(), 53u);
}

TEST(SideTask, StartingBeforeWaitingIsRefusedAndWaitWithNothingStartedReturns) {
  SideTask side;
  EXPECT_NO_THROW(side.wait());
  std::promise<void> release;
  std::shared_future<void> gate = release.get_future().share();
  auto blocked = [gate] { gate.wait(); };
  side.start(blocked);
  EXPECT_TRUE(side.busy());
  auto other = [] {};
  EXPECT_THROW(side.start(other), std::logic_error);
  release.set_value();  // before wait(): the caller may run the task itself
  side.wait();
  EXPECT_FALSE(side.busy());
}

TEST(SideTask, WithoutAHelperBothPartsRunInOrderOnTheCaller) {
  std::vector<std::string> order;
  std::thread::id where;
  run_side_by_side(
      static_cast<SideTask*>(nullptr), [&] { order.push_back("a"); where = std::this_thread::get_id(); },
      [&] { order.push_back("b"); });
  EXPECT_EQ(order, (std::vector<std::string>{"a", "b"}));
  EXPECT_EQ(where, std::this_thread::get_id());
}

TEST(SideTask, TheHelperRunsAtTheNiceValueOfTheThreadThatFirstStartedIt) {
  // A thread of its own, made nicer (raising nice needs no privilege), makes the helper.
  const int target = std::min(getpriority(PRIO_PROCESS, 0) + 3, 19);
  int helper_nice = -100, own_nice = -100;
  std::thread owner([&] {
    const auto tid = static_cast<id_t>(gettid());
    ASSERT_EQ(setpriority(PRIO_PROCESS, tid, target), 0);
    own_nice = getpriority(PRIO_PROCESS, tid);
    SideTask side;
    // Read on the helper: the caller waits for it to have run (not taking it back itself).
    std::atomic<bool> read{false};
    auto read_nice = [&] {
      helper_nice = getpriority(PRIO_PROCESS, static_cast<id_t>(gettid()));
      read = true;
    };
    side.start(read_nice);
    while (!read.load()) std::this_thread::yield();
    side.wait();
    EXPECT_EQ(side.tasks_run_by_caller(), 0u);
  });
  owner.join();
  EXPECT_EQ(own_nice, target);
  EXPECT_EQ(helper_nice, target);
}

// The session lowers the frame thread's nice value after its warm-up frame, which made the helper:
// the helper must follow (it had stayed at nice 0, level with any other program on a busy machine).
TEST(SideTask, TheHelperFollowsItsOwnersNiceValueChangedAfterItWasMade) {
  const int before = getpriority(PRIO_PROCESS, 0);
  const int after = std::min(before + 4, 19);
  if (after == before) GTEST_SKIP() << "already at nice 19";
  std::vector<int> helper_nice;
  std::thread owner([&] {
    SideTask side;
    auto on_helper = [&] {
      std::atomic<bool> read{false};
      auto read_nice = [&] {
        helper_nice.push_back(getpriority(PRIO_PROCESS, static_cast<id_t>(gettid())));
        read = true;
      };
      side.start(read_nice);
      while (!read.load()) std::this_thread::yield();  // run by the helper, not taken back
      side.wait();
    };
    on_helper();  // makes the helper at the owner's nice value
    ASSERT_EQ(setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), after), 0);
    on_helper();
    on_helper();
    EXPECT_EQ(side.tasks_run_by_caller(), 0u);
  });
  owner.join();
  ASSERT_EQ(helper_nice.size(), 3u);
  EXPECT_EQ(helper_nice[0], before);
  EXPECT_EQ(helper_nice[1], after);
  EXPECT_EQ(helper_nice[2], after);
}

TEST(SideTask, DestroyingItWithATaskStartedRunsTheTaskFirst) {
  std::atomic<bool> finished{false};
  {
    SideTask side;
    auto slow = [&] {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      finished = true;
    };
    side.start(slow);
  }  // the destructor waits for the task (or runs it), then joins the helper
  EXPECT_TRUE(finished.load());
}

}  // namespace
}  // namespace spidar::core
