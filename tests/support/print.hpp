// GoogleTest printers: a failing assertion shows a Fixed as its decimal value and its raw bits.
#pragma once

#include <cinttypes>
#include <cstdio>
#include <ostream>

#include <detsim/fixed/fixed.hpp>

namespace detsim {

inline void PrintTo(Fixed x, std::ostream* os) {
  char buf[40];
  std::snprintf(buf, sizeof buf, " (raw 0x%016" PRIx64 ")", static_cast<std::uint64_t>(x.raw()));
  *os << to_string(x) << buf;
}

}  // namespace detsim
