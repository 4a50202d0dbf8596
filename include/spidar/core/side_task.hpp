#pragma once
/// A second thread for one task at a time, so that a frame's independent stages run side by side
/// on a two-core machine: start() hands a task to the helper, the caller does its own part, and
/// wait() joins (and re-throws what the task threw).
///
/// The helper thread is made at the first start(), by the thread that calls it, so that it
/// inherits that thread's scheduling (on Linux a thread's nice value and policy are inherited at
/// creation): the frame thread's helper runs at the frame thread's priority. It sleeps on a
/// condition variable between tasks, so waking it costs a futex wake, not a thread creation.
///
/// Not copyable or movable (the helper refers to it). One owner thread calls start() and wait();
/// the task must not call either. The task object must live until wait() returns.
#include <condition_variable>
#include <exception>
#include <mutex>
#include <thread>
#include <utility>

namespace spidar::core {

class SideTask {
 public:
  SideTask() = default;
  ~SideTask();
  SideTask(const SideTask&) = delete;
  SideTask& operator=(const SideTask&) = delete;

  /// Runs `task()` on the helper thread. The previous task must have been waited for; throws
  /// std::logic_error otherwise. `task` is held by reference: keep it alive until wait().
  template <class F>
  void start(F& task) {
    start_erased(&task, [](void* f) { (*static_cast<F*>(f))(); });
  }
  /// Blocks until the started task has finished; re-throws its exception, if any. A no-op when
  /// nothing was started.
  void wait();
  /// True while a task is started and not yet waited for.
  bool busy() const { return started_; }
  /// Tasks run so far (for tests and reports).
  unsigned long long tasks_run() const;

 private:
  void start_erased(void* task, void (*call)(void*));
  void loop();

  mutable std::mutex mutex_;
  std::condition_variable wake_, done_;
  void* task_ = nullptr;
  void (*call_)(void*) = nullptr;
  bool pending_ = false;   // a task handed over, not finished (guarded by mutex_)
  bool quit_ = false;      // guarded by mutex_
  bool started_ = false;   // owner thread only
  unsigned long long run_ = 0;  // guarded by mutex_
  std::exception_ptr error_;    // guarded by mutex_
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
