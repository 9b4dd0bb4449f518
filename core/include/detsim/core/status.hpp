// Errors as values: what the simulation returns for bad definitions, unknown IDs and bad bytes.
#pragma once

#include <string>
#include <utility>
#include <variant>

namespace detsim {

/// Success, or a message naming what is wrong ("body 7: box half extent y must be > 0, got 0").
class [[nodiscard]] Status {
 public:
  Status() = default;
  static Status success() { return {}; }
  static Status error(std::string message) { return Status(std::move(message), false); }

  [[nodiscard]] bool ok() const noexcept { return ok_; }
  explicit operator bool() const noexcept { return ok_; }
  /// The error message; empty on success.
  [[nodiscard]] const std::string& message() const noexcept { return message_; }

 private:
  Status(std::string message, bool ok) : message_(std::move(message)), ok_(ok) {}
  std::string message_;
  bool ok_ = true;
};

/// A value or an error message.
template <class T>
class [[nodiscard]] Expected {
 public:
  Expected(T value) : v_(std::move(value)) {}  // NOLINT: implicit by design, like std::expected
  Expected(Status error) : v_(std::move(error)) {}

  [[nodiscard]] bool ok() const noexcept { return v_.index() == 0; }
  explicit operator bool() const noexcept { return ok(); }
  /// The value; only valid when ok().
  [[nodiscard]] const T& value() const& { return std::get<0>(v_); }
  [[nodiscard]] T& value() & { return std::get<0>(v_); }
  /// The value moved out of a temporary (`auto world = World::create(def).value();`).
  [[nodiscard]] T&& value() && { return std::get<0>(std::move(v_)); }
  [[nodiscard]] const T& operator*() const& { return value(); }
  /// The value, for changing it in place (`result->add(x)`); only valid when ok().
  [[nodiscard]] T& operator*() & { return value(); }
  [[nodiscard]] const T* operator->() const { return &value(); }
  [[nodiscard]] T* operator->() { return &value(); }
  /// The error message; empty when ok().
  [[nodiscard]] const std::string& message() const noexcept {
    static const std::string none;
    return ok() ? none : std::get<1>(v_).message();
  }
  [[nodiscard]] Status status() const { return ok() ? Status::success() : std::get<1>(v_); }

 private:
  std::variant<T, Status> v_;
};

}  // namespace detsim
