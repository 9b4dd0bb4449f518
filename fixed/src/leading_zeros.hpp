// Leading zeros of a nonzero 64-bit value, shared by the normalisations of log and sqrt. Internal
// to the fixed module; not installed.
#pragma once

#include <bit>
#include <cstdint>
#include <type_traits>

namespace detsim::detail {

/// std::countl_zero(v) for v != 0. On x86-64 without LZCNT (the default target) compilers emit
/// BSR, which leaves its output register unchanged for a zero input and therefore waits for
/// whatever wrote that register last: often the end of the previous call (Clang 14 put sqrt's
/// count in the return register, and a loop of sqrt ran 2x slower, one call after the other).
/// Here the output register is zeroed first, which the processor treats as having no input, so
/// the count depends on v alone. The result is the same on every path.
constexpr int leading_zeros(std::uint64_t v) noexcept {
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__)) && !defined(__LZCNT__)
  if (!std::is_constant_evaluated()) {
    std::uint64_t top = 0;
    __asm__("bsr %1, %0" : "+r"(top) : "r"(v) : "cc");
    return 63 - static_cast<int>(top);
  }
#endif
  return std::countl_zero(v);
}

}  // namespace detsim::detail
