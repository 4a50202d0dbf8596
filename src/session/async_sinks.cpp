#include "spidar/session/async_sinks.hpp"

#include <algorithm>
#include <chrono>
#include <future>
#include <stdexcept>

#include "spidar/core/realtime.hpp"

namespace spidar::session {

AsyncSinks::AsyncSinks(std::vector<FrameSink*> sinks, int slots, int nice)
    : sinks_(std::move(sinks)), slots_(static_cast<std::size_t>(slots < 1 ? 1 : slots)),
      nice_(std::clamp(nice, 0, 19)) {
  for (std::size_t k = slots_.size(); k-- > 0;) free_.push_back(k);
}

AsyncSinks::~AsyncSinks() {
  {
    std::lock_guard lock(mutex_);
    quit_ = true;
  }
  changed_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void AsyncSinks::on_start() {
  if (started_) return;
  started_ = true;
  std::promise<void> ready;
  auto started = ready.get_future();
  thread_ = std::thread([this, &ready] {
    if (nice_ > 0) (void)core::set_nice(nice_);  // best effort: a normal share otherwise
    try {
      for (FrameSink* k : sinks_) k->on_start();
    } catch (...) {
      ready.set_exception(std::current_exception());
      return;
    }
    ready.set_value();
    run();
  });
  try {
    started.get();
  } catch (...) {
    thread_.join();
    throw;
  }
}

void AsyncSinks::rethrow_if_failed() {
  if (!error_) return;
  std::exception_ptr e = error_;
  error_ = nullptr;  // once
  std::rethrow_exception(e);
}

void AsyncSinks::copy_into(const FrameEvent& from, Slot& to) const {
  to.e = from;
  if (from.bgr != nullptr) {
    from.bgr->copyTo(to.bgr);
    to.e.bgr = &to.bgr;
  }
  if (from.measured != nullptr) {
    to.measured = *from.measured;
    to.e.measured = &to.measured;
  }
  if (from.scene != nullptr) {
    to.scene = *from.scene;  // shapes by value; the meshes are shared and not changed per frame
    to.e.scene = &to.scene;
  }
  if (from.result != nullptr) {
    pipeline::copy_frame_result(*from.result, &to.result);
    to.e.result = &to.result;
  }
  if (from.compared != nullptr) {
    pipeline::copy_frame_result(*from.compared, &to.compared);
    to.e.compared = &to.compared;
  }
  if (from.filmed != nullptr) {
    sim::copy_filmed_frame(*from.filmed, &to.filmed);
    to.e.filmed = &to.filmed;
  }
}

void AsyncSinks::on_frame(const FrameEvent& e) {
  if (!started_) on_start();
  std::size_t k = 0;
  {
    std::unique_lock lock(mutex_);
    rethrow_if_failed();
    if (free_.empty()) {
      const auto t0 = std::chrono::steady_clock::now();
      changed_.wait(lock, [this] { return !free_.empty() || error_ || !thread_.joinable(); });
      ++waits_;
      waited_ms_ += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      rethrow_if_failed();
      if (free_.empty()) throw std::logic_error("async sinks: the output thread is gone");
    }
    k = free_.back();
    free_.pop_back();
  }
  copy_into(e, slots_[k]);  // the slot is this thread's until queued
  {
    std::lock_guard lock(mutex_);
    queued_.push_back(k);
  }
  changed_.notify_all();
}

void AsyncSinks::run() {
  for (;;) {
    std::size_t k = 0;
    {
      std::unique_lock lock(mutex_);
      changed_.wait(lock, [this] { return quit_ || !queued_.empty() || summary_.has_value(); });
      if (quit_) return;
      if (queued_.empty()) break;  // ending, everything delivered
      k = queued_.front();
      queued_.pop_front();
    }
    bool failed = false;
    try {
      for (FrameSink* sink : sinks_) sink->on_frame(slots_[k].e);
    } catch (...) {
      std::lock_guard lock(mutex_);
      error_ = std::current_exception();
      failed = true;
    }
    {
      std::lock_guard lock(mutex_);
      free_.push_back(k);
    }
    changed_.notify_all();
    if (failed) return;  // the frame thread re-throws; no more frames, no on_end
  }
  // on_end, on this thread.
  SessionSummary s;
  {
    std::lock_guard lock(mutex_);
    s = *summary_;
  }
  try {
    for (FrameSink* k : sinks_) k->on_end(s);
  } catch (...) {
    std::lock_guard lock(mutex_);
    error_ = std::current_exception();
  }
}

void AsyncSinks::on_end(const SessionSummary& s) {
  if (!thread_.joinable()) {
    std::lock_guard lock(mutex_);
    rethrow_if_failed();
    return;
  }
  {
    std::lock_guard lock(mutex_);
    summary_ = s;
  }
  changed_.notify_all();
  thread_.join();
  std::lock_guard lock(mutex_);
  rethrow_if_failed();
}

std::uint64_t AsyncSinks::waits() const {
  std::lock_guard lock(mutex_);
  return waits_;
}

double AsyncSinks::waited_ms() const {
  std::lock_guard lock(mutex_);
  return waited_ms_;
}

}  // namespace spidar::session
