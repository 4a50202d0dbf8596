#pragma once
/// What each latched fault was: one line of text per fault bit, written once by the thread that
/// latches the fault (the servo thread, its monitor, or a caller of `emergency_stop`) and read by
/// any thread. Writing never allocates and never locks (fixed buffers published through a
/// sequence lock), so the servo thread may record a fault in the cycle it latches it.
#include <array>
#include <atomic>
#include <cstdarg>
#include <cstdint>
#include <string>

#include "spidar/core/seqlock.hpp"

namespace spidar::device {

class FaultLog {
 public:
  /// Longest text kept per fault, with its terminating NUL [bytes]; longer texts are cut.
  static constexpr std::size_t kTextSize = 320;

  /// Records `text` for every bit of `bits`: the bits the caller has just latched (each bit is
  /// written by the one thread that flipped it; a concurrent second writer of the same bit is
  /// skipped). No allocation.
  void record(std::uint32_t bits, const char* text) noexcept;
  /// As `record`, formatting with snprintf into a fixed buffer.
  void recordf(std::uint32_t bits, const char* format, ...) noexcept
      __attribute__((format(printf, 3, 4)));
  void vrecordf(std::uint32_t bits, const char* format, std::va_list args) noexcept;

  /// "name: text; name: text" for the bits of `faults`, in the order they were recorded (the
  /// first fault first); a bit without text gets "no details recorded". Empty for no faults.
  /// Any thread; allocates.
  std::string describe(std::uint32_t faults) const;

 private:
  struct Entry {
    std::uint64_t order = 0;  ///< 1, 2, 3, … in recording order
    std::array<char, kTextSize> text{};
  };
  std::array<core::Latest<Entry>, 32> slots_;
  std::atomic<std::uint64_t> order_{0};
  std::atomic<std::uint32_t> writing_{0};  ///< bits whose slot is being written
};

}  // namespace spidar::device
