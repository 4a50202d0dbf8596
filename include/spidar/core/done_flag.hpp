#pragma once
/// A one-way "done" signal between threads for a piece of data written after its owner was
/// handed over: the writer sets it once the data are complete (release), a reader waits for it
/// (acquire) before reading them. The simulated camera publishes a frame as soon as its image is
/// ready and writes the frame's ground-truth images after (sim::FilmedFrame::truth_images).
///
/// Copies take the source's state (a copy of finished data is finished): the flag can sit in a
/// plain struct that is copied and kept in pools.
#include <atomic>

namespace spidar::core {

class DoneFlag {
 public:
  DoneFlag() = default;
  explicit DoneFlag(bool done) : done_(done) {}
  DoneFlag(const DoneFlag& other) : done_(other.done()) {}
  DoneFlag& operator=(const DoneFlag& other) {
    if (other.done()) set();
    else reset();
    return *this;
  }

  /// The data are complete: wakes every waiter.
  void set() {
    done_.store(true, std::memory_order_release);
    done_.notify_all();
  }
  /// Not done (again): only while no reader can see the data (before they are handed over).
  void reset() { done_.store(false, std::memory_order_relaxed); }
  bool done() const { return done_.load(std::memory_order_acquire); }
  /// Blocks until set() (returns at once when already set).
  void wait() const { done_.wait(false, std::memory_order_acquire); }

 private:
  std::atomic<bool> done_{false};
};

}  // namespace spidar::core
