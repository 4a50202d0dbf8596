#pragma once
/// A bounded history: the newest `capacity` values, oldest first; older ones are overwritten.
/// A live session runs for hours; its plots need the last few hundred frames, not all of them.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "spidar/core/result.hpp"

namespace spidar::session {

template <typename T>
class HistoryRing {
 public:
  /// `capacity` ≥ 1 (SpidarError otherwise).
  explicit HistoryRing(std::size_t capacity) : capacity_(capacity) {
    if (capacity == 0) throw SpidarError("HistoryRing: capacity must be at least 1");
    values_.reserve(capacity);
  }
  void push(const T& v) {
    if (values_.size() < capacity_) {
      values_.push_back(v);
    } else {
      values_[head_] = v;
      head_ = (head_ + 1) % capacity_;
    }
    ++pushed_;
  }
  std::size_t size() const { return values_.size(); }
  std::size_t capacity() const { return capacity_; }
  bool empty() const { return values_.empty(); }
  /// Values pushed so far, kept or not.
  std::uint64_t pushed() const { return pushed_; }
  /// The i-th oldest value kept (0 ≤ i < size()).
  const T& operator[](std::size_t i) const { return values_[(head_ + i) % values_.size()]; }
  const T& back() const { return (*this)[values_.size() - 1]; }

 private:
  std::size_t capacity_;
  std::vector<T> values_;
  std::size_t head_ = 0;  ///< index of the oldest value once full
  std::uint64_t pushed_ = 0;
};

}  // namespace spidar::session
