#include "spidar/core/side_task.hpp"

#include <stdexcept>

namespace spidar::core {

SideTask::~SideTask() {
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
  {
    std::lock_guard lock(mutex_);
    task_ = task;
    call_ = call;
    pending_ = true;
    error_ = nullptr;
  }
  started_ = true;
  wake_.notify_one();
}

void SideTask::wait() {
  if (!started_) return;
  started_ = false;
  std::exception_ptr error;
  {
    std::unique_lock lock(mutex_);
    done_.wait(lock, [this] { return !pending_; });
    error = std::exchange(error_, nullptr);
  }
  if (error) std::rethrow_exception(error);
}

unsigned long long SideTask::tasks_run() const {
  std::lock_guard lock(mutex_);
  return run_;
}

void SideTask::loop() {
  std::unique_lock lock(mutex_);
  for (;;) {
    wake_.wait(lock, [this] { return quit_ || pending_; });
    if (pending_) {
      void* task = task_;
      void (*call)(void*) = call_;
      lock.unlock();
      std::exception_ptr error;
      try {
        call(task);
      } catch (...) {
        error = std::current_exception();
      }
      lock.lock();
      error_ = error;
      pending_ = false;
      ++run_;
      done_.notify_one();
    }
    if (quit_) return;
  }
}

}  // namespace spidar::core
