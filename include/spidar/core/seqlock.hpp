#pragma once
/// Lock-free hand-off of plain data between threads: one writer that never waits, any number of
/// readers that retry if they raced a write (a sequence lock). The payload is stored as atomic
/// 64-bit words, so the hand-off is free of data races by the C++ memory model (and TSan-clean).
///
/// `Latest<T>`: the newest value. `SampleRing<T, N>`: the last N values, for interpolation.
/// T must be trivially copyable. Neither allocates after construction.
#include <array>
#include <atomic>
#include <cstdint>
#include <cstring>
#include <optional>
#include <span>
#include <type_traits>

namespace spidar::core {

namespace detail {

template <typename T>
class SeqSlot {
  static_assert(std::is_trivially_copyable_v<T>, "SeqSlot needs a trivially copyable type");
  static constexpr std::size_t kWords = (sizeof(T) + 7) / 8;

 public:
  /// Single writer only.
  void store(const T& value) {
    std::array<std::uint64_t, kWords> buf{};
    std::memcpy(buf.data(), static_cast<const void*>(&value), sizeof(T));
    const std::uint64_t s = seq_.load(std::memory_order_relaxed);
    seq_.store(s + 1, std::memory_order_relaxed);
    // Release stores keep the odd sequence number ahead of the payload (no standalone fences:
    // ThreadSanitizer cannot model those; on x86 these are plain moves).
    for (std::size_t i = 0; i < kWords; ++i) words_[i].store(buf[i], std::memory_order_release);
    seq_.store(s + 2, std::memory_order_release);
  }

  /// Returns false if a write raced the read (the caller retries or skips).
  bool try_load(T& out, std::uint64_t* seq = nullptr) const {
    const std::uint64_t s1 = seq_.load(std::memory_order_acquire);
    if (s1 & 1u) return false;
    std::array<std::uint64_t, kWords> buf;
    // Acquire loads keep the closing sequence check after the payload reads.
    for (std::size_t i = 0; i < kWords; ++i) buf[i] = words_[i].load(std::memory_order_acquire);
    if (seq_.load(std::memory_order_relaxed) != s1) return false;
    std::memcpy(static_cast<void*>(&out), buf.data(), sizeof(T));
    if (seq) *seq = s1;
    return true;
  }

  std::uint64_t version() const { return seq_.load(std::memory_order_acquire); }

 private:
  std::atomic<std::uint64_t> seq_{0};
  std::array<std::atomic<std::uint64_t>, kWords> words_{};
};

}  // namespace detail

/// The newest value of T, written by one thread, read by any.
template <typename T>
class Latest {
 public:
  void publish(const T& value) { slot_.store(value); }
  /// The newest value, or nullopt if none was published yet (or writes kept racing).
  std::optional<T> read() const {
    T out;
    for (int tries = 0; tries < 64; ++tries) {
      std::uint64_t seq = 0;
      if (slot_.try_load(out, &seq)) {
        if (seq == 0) return std::nullopt;
        return out;
      }
    }
    return std::nullopt;
  }
  /// Changes whenever a value is published (even numbers; 0 = never).
  std::uint64_t version() const { return slot_.version(); }

 private:
  detail::SeqSlot<T> slot_;
};

/// Reads newest-first values through `read(out, max)` (SampleRing::newest, or a wrapper of it)
/// into `buf`, only as many as reach back to what the reader already has: first `first`, then
/// four times as many at each try, until the oldest read satisfies `reached` (e.g. it is at or
/// before a time, or a sequence number already handled), the source has no more, or `buf` is
/// full. Returns how many it read (newest first in buf). A ring of a second of samples copied
/// whole to use its newest few costs more than the use.
template <typename T, typename Read, typename Reached>
std::size_t read_newest_until(Read&& read, std::span<T> buf, Reached&& reached, std::size_t first = 32) {
  if (buf.empty()) return 0;
  std::size_t want = first < 1 ? 1 : (first > buf.size() ? buf.size() : first);
  for (;;) {
    const std::size_t n = read(buf.data(), want);
    if (n < want || reached(buf[n - 1]) || want == buf.size()) return n;
    want = want * 4 > buf.size() ? buf.size() : want * 4;
  }
}

/// The last N values of T in publication order, written by one thread, read by any.
template <typename T, std::size_t N>
class SampleRing {
  static_assert(N >= 2 && (N & (N - 1)) == 0, "N must be a power of two");

 public:
  /// Single writer: appends, overwriting the oldest.
  void push(const T& value) {
    const std::uint64_t i = count_.load(std::memory_order_relaxed);
    slots_[i & (N - 1)].store(Entry{i, value});
    count_.store(i + 1, std::memory_order_release);
  }
  /// Values pushed so far.
  std::uint64_t count() const { return count_.load(std::memory_order_acquire); }

  /// Copies up to `max` newest values, newest first, into out; returns how many. Values the
  /// writer overwrote while reading are skipped.
  std::size_t newest(T* out, std::size_t max) const {
    const std::uint64_t end = count();
    std::size_t n = 0;
    for (std::uint64_t k = 0; k < max && k < end && k < N - 1; ++k) {
      const std::uint64_t index = end - 1 - k;
      Entry e;
      if (!slots_[index & (N - 1)].try_load(e) || e.index != index) break;
      out[n++] = e.value;
    }
    return n;
  }

 private:
  struct Entry {
    std::uint64_t index;
    T value;
  };
  std::atomic<std::uint64_t> count_{0};
  std::array<detail::SeqSlot<Entry>, N> slots_{};
};

}  // namespace spidar::core
