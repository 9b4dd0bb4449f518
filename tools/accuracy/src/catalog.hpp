// The catalogue of measured functions: for each, how to call it, its MPFR reference, its
// documented values outside the domain, and its inputs. Internal to detsim_accuracy.
#pragma once

#include <span>
#include <string_view>

#include <detsim_accuracy/accuracy.hpp>
#include "inputs.hpp"

namespace detsim::accuracy::detail {

/// MPFR temporaries a reference may use.
struct Scratch {
  Mp a;
  Mp b;
};

struct Entry {
  FunctionSpec spec;
  /// Results per input: 1, or 2 for sincos (sin, cos).
  int results = 1;
  std::array<std::string_view, 2> result_names{};
  /// Calls the fixed-point function.
  void (*compute)(const Args& args, Fixed* out) = nullptr;
  /// The exact result(s) of the exact inputs `in` (already set from args).
  void (*reference)(const mpfr_ptr* in, mpfr_ptr* out, Scratch& scratch) = nullptr;
  /// For inputs outside the domain (log of 0, x / 0, ...): sets the documented result, names the
  /// rule, and returns true. nullptr when every input is checked against MPFR.
  bool (*documented)(const Args& args, Fixed* value, const char** rule) = nullptr;
  /// One random input: uniform over the domain when !log_half, log-uniform in magnitude otherwise.
  void (*sample)(Rng& rng, bool log_half, Args& args) = nullptr;
  /// Appends the edge inputs.
  void (*edges)(ArgsList& list) = nullptr;
};

[[nodiscard]] std::span<const Entry> entries() noexcept;

}  // namespace detsim::accuracy::detail
