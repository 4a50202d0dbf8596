#include "spidar/core/side_task.hpp"
#include "spidar/core/thread_name.hpp"

#include <stdexcept>

namespace spidar::core {

SideTask::~SideTask() {
  if (started_) {
    try {
      wait();
    } catch (...) {  // a task's error nobody waited for
    }
  }
  {
    std::lock_guard lock(mutex_);
    quit_ = true;
  }
  wake_.notify_one();
  if (thread_.joinable()) thread_.join();
}

void SideTask::start_erased(void* task, void (*call)(void*)) {
  if (started_) throw std::logic_error("SideTask::start: the previous task was not waited for");
  if (!thread_.joinable()) thread_ = std::thread([this] { loop(); });
  task_ = task;
  call_ = call;
  owner_scheduling_ = current_scheduling();
  error_ = nullptr;
  started_ = true;
  {
    std::lock_guard lock(mutex_);  // the helper checks state_ under it: no wake-up is lost
    state_.store(kOffered, std::memory_order_release);
  }
  wake_.notify_one();
}

void SideTask::run_task() {
  try {
    call_(task_);
  } catch (...) {
    error_ = std::current_exception();
  }
  run_.fetch_add(1, std::memory_order_acq_rel);
}

void SideTask::wait() {
  if (!started_) return;
  started_ = false;
  int offered = kOffered;
  if (state_.compare_exchange_strong(offered, kRunning, std::memory_order_acq_rel)) {
    // The helper has not begun it: run it here.
    run_task();
    run_by_caller_.fetch_add(1, std::memory_order_acq_rel);
  } else {
    // The helper runs it: a short spin (it is usually nearly done), then sleep until it is.
    for (int i = 0; i < 4000 && state_.load(std::memory_order_acquire) != kDone; ++i) {
#if defined(__x86_64__) || defined(__i386__)
      __builtin_ia32_pause();
#endif
    }
    if (state_.load(std::memory_order_acquire) != kDone) {
      std::unique_lock lock(mutex_);
      done_.wait(lock, [this] { return state_.load(std::memory_order_acquire) == kDone; });
    }
  }
  state_.store(kIdle, std::memory_order_release);
  if (std::exception_ptr error = std::exchange(error_, nullptr)) std::rethrow_exception(error);
}

void SideTask::loop() {
  set_thread_name("spidar-side");
  ThreadScheduling asked = current_scheduling();  // the scheduling last asked for (made: inherited)
  std::unique_lock lock(mutex_);
  for (;;) {
    wake_.wait(lock, [this] { return quit_ || state_.load(std::memory_order_acquire) == kOffered; });
    if (quit_) return;
    int offered = kOffered;
    if (!state_.compare_exchange_strong(offered, kRunning, std::memory_order_acq_rel)) continue;  // the caller took it
    lock.unlock();
    if (owner_scheduling_ != asked) {  // asked once per change, not per task
      asked = owner_scheduling_;
      (void)apply_scheduling(asked);  // best effort: what the owner was granted may be refused here
    }
    run_task();
    lock.lock();
    state_.store(kDone, std::memory_order_release);  // under mutex_: the caller's sleep sees it
    done_.notify_one();
  }
}

}  // namespace spidar::core
