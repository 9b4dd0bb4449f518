// Checked invariants: DETSIM_ASSERT(condition) in builds with DETSIM_CHECKS (the CMake option of
// that name, on by default in Debug builds), nothing at all in the others.
//
// An assertion only reads: it never changes a result, so a checked build and a release build give
// the same bits (the golden tests run in both). A failed one prints the condition and where it is,
// and aborts: a broken invariant is a bug in detsim, found before it becomes a desync.
#pragma once

#ifndef DETSIM_CHECKS
#define DETSIM_CHECKS 0
#endif

namespace detsim {

/// Whether this build checks invariants (DETSIM_ASSERT, World::validate after every step).
inline constexpr bool checks_enabled = DETSIM_CHECKS != 0;

/// Prints "detsim: invariant failed at FILE:LINE: WHAT" to stderr and aborts.
[[noreturn]] void invariant_failed(const char* what, const char* file, int line) noexcept;

}  // namespace detsim

#if DETSIM_CHECKS
#define DETSIM_ASSERT(condition) \
  ((condition) ? static_cast<void>(0) : ::detsim::invariant_failed(#condition, __FILE__, __LINE__))
#else
#define DETSIM_ASSERT(condition) static_cast<void>(0)
#endif
