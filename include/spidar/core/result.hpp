#pragma once
/// A small `std::expected`-like result for library functions that can fail on bad input.
/// Errors carry a message that says what was wrong, where, and what was expected.
#include <cassert>
#include <stdexcept>
#include <string>
#include <utility>
#include <variant>

namespace spidar {

struct Error {
  std::string message;
};

/// Thrown by `Result::value()` on an error, and by API boundaries that prefer exceptions.
class SpidarError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

template <typename T>
class [[nodiscard]] Result {
 public:
  Result(T value) : v_(std::move(value)) {}  // NOLINT(google-explicit-constructor)
  Result(Error error) : v_(std::move(error)) {}  // NOLINT(google-explicit-constructor)

  bool ok() const { return v_.index() == 0; }
  explicit operator bool() const { return ok(); }

  /// The value; throws SpidarError with the error message if there is none.
  const T& value() const& {
    if (!ok()) throw SpidarError(error().message);
    return std::get<0>(v_);
  }
  T&& value() && {
    if (!ok()) throw SpidarError(error().message);
    return std::get<0>(std::move(v_));
  }
  const T& operator*() const {
    assert(ok());
    return *std::get_if<0>(&v_);
  }
  const T* operator->() const {
    assert(ok());
    return std::get_if<0>(&v_);
  }
  const Error& error() const {
    assert(!ok());
    return *std::get_if<1>(&v_);
  }

 private:
  std::variant<T, Error> v_;
};

/// Result of a function that returns nothing on success.
struct Ok {};
using Status = Result<Ok>;

}  // namespace spidar
