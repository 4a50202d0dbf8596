#pragma once
/// Hand-off of a large value (e.g. a SceneSnapshot) from one writer to one reader without either
/// ever waiting: the writer fills a back buffer and swaps it in; the reader takes the newest.
/// Buffers are reused, so after warm-up nothing allocates if T reuses its storage.
#include <array>
#include <atomic>
#include <cstdint>

namespace spidar::core {

template <typename T>
class TripleBuffer {
 public:
  /// Writer: the buffer to fill. Call publish() when done.
  T& back() { return buffers_[back_]; }
  /// Writer: makes the back buffer the newest.
  void publish() {
    const std::uint32_t old = middle_.exchange(back_ | kFresh, std::memory_order_acq_rel);
    back_ = old & kIndex;
  }
  /// Reader: true and the newest value in `front()` if something new was published.
  bool update() {
    if (!(middle_.load(std::memory_order_acquire) & kFresh)) return false;
    const std::uint32_t old = middle_.exchange(front_, std::memory_order_acq_rel);
    front_ = old & kIndex;
    return true;
  }
  /// Reader: the value taken by the last successful update().
  const T& front() const { return buffers_[front_]; }

 private:
  static constexpr std::uint32_t kIndex = 3, kFresh = 4;
  std::array<T, 3> buffers_{};
  std::uint32_t back_ = 0, front_ = 1;
  std::atomic<std::uint32_t> middle_{2};
};

}  // namespace spidar::core
