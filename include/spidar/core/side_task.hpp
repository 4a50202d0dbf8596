#pragma once
/// A second thread for one task at a time, so that a frame's independent stages run side by side
/// on a two-core machine: start() hands a task to the helper, the caller does its own part, and
/// wait() joins (and re-throws what the task threw).
///
/// Never slower than doing both in turn, whatever the machine: if the helper has not begun the
/// task by the time the caller waits (a sleeping CPU of a VM can take milliseconds to wake, a
/// busy machine may not schedule the helper at all), the caller takes the task back and runs it
/// itself. A task runs exactly once, on one of the two threads.
///
/// The helper runs each task at its owner's scheduling as it was at that task's start() (policy,
/// priority and nice value; best effort): the frame thread's helper runs at the frame thread's
/// priority even when the owner changed it after the helper was made (the session lowers the
/// frame thread's nice value after its warm-up frame, which made the helper; the helper had
/// stayed at nice 0, level with any other program). The helper is made at the first start() and
/// sleeps on a condition variable between tasks.
///
/// Not copyable or movable (the helper refers to it). One owner thread calls start() and wait();
/// the task must not call either. The task object must live until wait() returns.
#include <atomic>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <thread>
#include <utility>

#include "spidar/core/realtime.hpp"

namespace spidar::core {

class SideTask {
 public:
  SideTask() = default;
  ~SideTask();
  SideTask(const SideTask&) = delete;
  SideTask& operator=(const SideTask&) = delete;

  /// Offers `task()` to the helper thread. The previous task must have been waited for; throws
  /// std::logic_error otherwise. `task` is held by reference: keep it alive until wait().
  template <class F>
  void start(F& task) {
    start_erased(&task, [](void* f) { (*static_cast<F*>(f))(); });
  }
  /// Returns once the started task has run: on the helper (waiting for it to finish), or here if
  /// the helper had not begun it. Re-throws the task's exception, if any. A no-op when nothing
  /// was started.
  void wait();
  /// True while a task is started and not yet waited for.
  bool busy() const { return started_; }
  /// Tasks run so far, and of those the ones the caller ran itself (for tests and reports).
  unsigned long long tasks_run() const { return run_.load(std::memory_order_acquire); }
  unsigned long long tasks_run_by_caller() const { return run_by_caller_.load(std::memory_order_acquire); }

 private:
  enum State : int { kIdle, kOffered, kRunning, kDone };
  void start_erased(void* task, void (*call)(void*));
  void loop();
  /// Runs the offered task on this thread; its exception into error_.
  void run_task();

  std::mutex mutex_;
  std::condition_variable wake_, done_;
  std::atomic<int> state_{kIdle};
  void* task_ = nullptr;               // written before state_ becomes kOffered
  ThreadScheduling owner_scheduling_;  // likewise: the owner's, at start()
  void (*call_)(void*) = nullptr;
  std::exception_ptr error_;           // written by the runner before state_ becomes kDone
  bool quit_ = false;                  // guarded by mutex_
  bool started_ = false;               // owner thread only
  std::atomic<unsigned long long> run_{0}, run_by_caller_{0};
  std::thread thread_;
};

/// Runs `a` on `side`'s helper and `b` on the calling thread, and returns when both are done. If
/// both throw, b's exception is the one re-thrown (a's is dropped). With `side` null, runs a then
/// b on the calling thread (the serial reference the parallel run must equal).
template <class A, class B>
void run_side_by_side(SideTask* side, A&& a, B&& b) {
  if (side == nullptr) {
    a();
    b();
    return;
  }
  side->start(a);
  try {
    b();
  } catch (...) {
    try {
      side->wait();
    } catch (...) {
    }
    throw;
  }
  side->wait();
}

}  // namespace spidar::core
